#include "device.hpp"

#include <array>
#include <optional>
#include <string>

#include "pyrseg/error.hpp"

#ifndef PYRSEG_PYTHON_CUDA
#define PYRSEG_PYTHON_CUDA 0
#endif
#if PYRSEG_PYTHON_CUDA
#include <cuda_runtime_api.h>

#include "pyrseg/cuda.hpp"
#endif

namespace pyrseg::python {

bool is_device_array(const py::handle& obj) {
    return py::hasattr(obj, "__cuda_array_interface__");
}

bool DeviceFrames::built() {
    return PYRSEG_PYTHON_CUDA != 0;
}

#if PYRSEG_PYTHON_CUDA

namespace {

[[noreturn]] void bad(const std::string& what) {
    raise(ErrorCode::invalid_argument, what);
}

// One array's __cuda_array_interface__ (versions 0 to 3), as far as pyrseg needs it.
struct DeviceArray {
    std::uintptr_t data = 0;
    bool readonly = false;
    int ndim = 0;
    std::array<std::int64_t, 3> shape{};
    std::array<std::int64_t, 3> strides{};  // bytes; C order when the interface gives none
    char kind = 0;
    int itemsize = 0;
    std::optional<std::uintptr_t> stream;  // where the producer's work on it is queued; nullopt: none pending

    [[nodiscard]] std::size_t extent() const {  // bytes from data to the end of the last element
        std::int64_t end = itemsize;
        for (int i = 0; i < ndim; ++i) end += (shape[std::size_t(i)] - 1) * strides[std::size_t(i)];
        return std::size_t(end);
    }
};

DeviceArray device_array(const py::handle& obj, const char* what) {
    const py::dict cai = obj.attr("__cuda_array_interface__");
    DeviceArray a;
    const py::tuple data = cai["data"];
    a.data = data[0].cast<std::uintptr_t>();
    a.readonly = data[1].cast<bool>();
    if (cai.contains("mask") && !cai["mask"].is_none()) bad(std::string(what) + " has a mask; pyrseg takes none");
    const std::string typestr = cai["typestr"].cast<std::string>();
    if (typestr.size() < 3 || typestr[0] == '>') {
        bad(std::string(what) + " has dtype " + typestr + "; pyrseg takes little-endian arrays");
    }
    a.kind = typestr[1];
    a.itemsize = std::stoi(typestr.substr(2));
    const py::tuple shape = cai["shape"];
    if (shape.size() > 3) bad(std::string(what) + " has " + std::to_string(shape.size()) + " dimensions");
    a.ndim = int(shape.size());
    for (int i = 0; i < a.ndim; ++i) a.shape[std::size_t(i)] = shape[std::size_t(i)].cast<std::int64_t>();
    if (cai.contains("strides") && !cai["strides"].is_none()) {
        const py::tuple strides = cai["strides"];
        for (int i = 0; i < a.ndim; ++i) a.strides[std::size_t(i)] = strides[std::size_t(i)].cast<std::int64_t>();
    } else {
        std::int64_t step = a.itemsize;
        for (int i = a.ndim - 1; i >= 0; --i) {
            a.strides[std::size_t(i)] = step;
            step *= a.shape[std::size_t(i)];
        }
    }
    for (int i = 0; i < a.ndim; ++i) {
        if (a.shape[std::size_t(i)] == 0) bad(std::string(what) + " is empty");
    }
    if (cai.contains("stream") && !cai["stream"].is_none()) a.stream = cai["stream"].cast<std::uintptr_t>();
    return a;
}

std::string dims(const DeviceArray& a) {
    std::string s = "(";
    for (int i = 0; i < a.ndim; ++i) s += (i > 0 ? ", " : "") + std::to_string(a.shape[std::size_t(i)]);
    return s + ")";
}

// Rows of `row_bytes` packed elements, rows apart by a step of at least a row: what pyrseg/cuda.hpp reads.
std::size_t row_step(const DeviceArray& a, std::size_t row_bytes, const char* what) {
    const std::int64_t step = a.shape[0] > 1 ? a.strides[0] : std::int64_t(row_bytes);
    if (step < std::int64_t(row_bytes) || step % 4 != 0) {
        bad(std::string(what) + "'s rows are " + std::to_string(step) +
            " bytes apart: pyrseg reads rows of packed elements at least a row apart, a multiple of 4; make it "
            "contiguous on the device first (cupy.ascontiguousarray, tensor.contiguous())");
    }
    return std::size_t(step);
}

void check_shape(const DeviceArray& a, int width, int height, int channels, const char* what) {
    const bool ok = a.shape[0] == height && a.shape[1] == width &&
                    (channels == 0 ? a.ndim == 2 : a.ndim == 3 && a.shape[2] == channels);
    if (!ok) {
        const std::string want = std::to_string(height) + ", " + std::to_string(width) +
                                 (channels == 0 ? "" : ", " + std::to_string(channels));
        raise(ErrorCode::size_mismatch,
              std::string(what) + " has shape " + dims(a) + "; the Segmenter's frames are (" + want + ")");
    }
}

}  // namespace

namespace {

cudaStream_t as_stream(std::uintptr_t value) {
    return reinterpret_cast<cudaStream_t>(value);  // NOLINT(performance-no-int-to-ptr): the API's own handle
}

void check_cuda(cudaError_t status, const char* call) {
    if (status != cudaSuccess) {
        raise(ErrorCode::internal, std::string(call) + " failed: " + cudaGetErrorString(status));
    }
}

std::uintptr_t stream_value(const py::object& stream) {
    if (stream.is_none()) return 0;
    if (py::hasattr(stream, "ptr")) return stream.attr("ptr").cast<std::uintptr_t>();
    if (py::hasattr(stream, "cuda_stream")) return stream.attr("cuda_stream").cast<std::uintptr_t>();
    return stream.cast<std::uintptr_t>();
}

}  // namespace

DeviceFrames::DeviceFrames(const py::object& stream) : stream_(stream_value(stream)) {}

DeviceFrames::~DeviceFrames() {
    if (event_ != nullptr) cudaEventDestroy(static_cast<cudaEvent_t>(event_));
}

Segmenter DeviceFrames::make_segmenter(int width, int height, const Params& params, const Outputs& outputs) const {
    return cuda::make_segmenter(width, height, as_stream(stream_), params, outputs);
}

namespace {

// __cuda_array_interface__ v3: the consumer orders its work after the producer's stream. 1 and 2 name the legacy
// and per-thread default streams there.
void wait_for(const DeviceArray& a, std::uintptr_t ours, void*& event) {
    if (!a.stream) return;
    std::uintptr_t producer = *a.stream;
    if (producer == 1) producer = reinterpret_cast<std::uintptr_t>(cudaStreamLegacy);
    if (producer == 2) producer = reinterpret_cast<std::uintptr_t>(cudaStreamPerThread);
    if (producer == ours) return;
    if (event == nullptr) {
        cudaEvent_t e = nullptr;
        check_cuda(cudaEventCreateWithFlags(&e, cudaEventDisableTiming), "cudaEventCreateWithFlags");
        event = e;
    }
    auto* e = static_cast<cudaEvent_t>(event);
    check_cuda(cudaEventRecord(e, as_stream(producer)), "cudaEventRecord");
    check_cuda(cudaStreamWaitEvent(as_stream(ours), e, 0), "cudaStreamWaitEvent");
}

cuda::LabelPointers label_pointers(const py::object& out, const py::object& count, int width, int height,
                                   DeviceArray& out_array, std::optional<DeviceArray>& count_array) {
    if (out.is_none() || !is_device_array(out)) {
        bad("a device frame needs out=, an H x W uint32 device array for the labels (cupy.empty((H, W), "
            "cupy.uint32)): its results stay on the device");
    }
    out_array = device_array(out, "out");
    if (out_array.kind != 'u' || out_array.itemsize != 4) bad("out must be uint32");
    if (out_array.readonly) bad("out is read-only");
    check_shape(out_array, width, height, 0, "out");
    if (width > 1 && out_array.strides[1] != 4) bad("out's labels must be packed within each row");
    cuda::LabelPointers l;
    // NOLINTNEXTLINE(performance-no-int-to-ptr): the array interface hands device pointers over as integers
    l.labels = reinterpret_cast<std::uint32_t*>(out_array.data);
    l.row_step_bytes = row_step(out_array, std::size_t(width) * 4, "out");
    l.labels_bytes = out_array.extent();
    if (!count.is_none()) {
        if (!is_device_array(count)) bad("count= must be a device array (cupy.zeros(1, cupy.uint32))");
        count_array = device_array(count, "count");
        if (count_array->kind != 'u' || count_array->itemsize != 4 || count_array->readonly) {
            bad("count must be a writable uint32 device array");
        }
        l.count = reinterpret_cast<std::uint32_t*>(count_array->data);  // NOLINT(performance-no-int-to-ptr)
    }
    return l;
}

}  // namespace

void DeviceFrames::segment_cloud(Segmenter& segmenter, const py::object& points, const py::object& normals,
                                 const py::object& out, const py::object& count) {
    const int w = segmenter.width(), h = segmenter.height();
    const DeviceArray p = device_array(points, "points");
    if (p.kind != 'f' || p.itemsize != 4) bad("device points must be float32");
    check_shape(p, w, h, 3, "points");
    if (p.strides[2] != 4 || (w > 1 && p.strides[1] != 12)) {
        bad("device points must be packed xyz within each row (12 bytes a point): pyrseg/cuda.hpp reads them in "
            "place; make them contiguous on the device first");
    }
    cuda::CloudPointers c;
    c.points = reinterpret_cast<const float*>(p.data);  // NOLINT(performance-no-int-to-ptr)
    c.points_bytes = p.extent();
    c.row_step_bytes = row_step(p, std::size_t(w) * 12, "points");
    std::optional<DeviceArray> n;
    if (!normals.is_none()) {
        if (!is_device_array(normals)) bad("normals must be a device array like the points");
        n = device_array(normals, "normals");
        if (n->kind != 'f' || n->itemsize != 4) bad("device normals must be float32");
        check_shape(*n, w, h, 3, "normals");
        if (n->strides[2] != 4 || (w > 1 && n->strides[1] != 12) || (h > 1 && n->strides[0] != p.strides[0])) {
            bad("device normals must have the points' layout: packed xyz, the same row step");
        }
        c.normals = reinterpret_cast<const float*>(n->data);  // NOLINT(performance-no-int-to-ptr)
        c.normals_bytes = n->extent();
    }
    DeviceArray o;
    std::optional<DeviceArray> k;
    const cuda::LabelPointers l = label_pointers(out, count, w, h, o, k);
    wait_for(p, stream_, event_);
    if (n) wait_for(*n, stream_, event_);
    wait_for(o, stream_, event_);
    if (k) wait_for(*k, stream_, event_);
    py::gil_scoped_release nogil;
    cuda::segment(segmenter, c, l);
}

void DeviceFrames::segment_depth(Segmenter& segmenter, const py::object& depth, const DepthView& camera,
                                 const py::object& out, const py::object& count) {
    const int w = segmenter.width(), h = segmenter.height();
    const DeviceArray d = device_array(depth, "depth");
    const bool u16 = d.kind == 'u' && d.itemsize == 2;
    if (!u16 && !(d.kind == 'f' && d.itemsize == 4)) bad("device depth must be uint16 or float32");
    check_shape(d, w, h, 0, "depth");
    if (w > 1 && d.strides[1] != d.itemsize) bad("device depth samples must be packed within each row");
    cuda::DepthPointers dp;
    dp.samples = reinterpret_cast<const void*>(d.data);  // NOLINT(performance-no-int-to-ptr)
    dp.bytes = d.extent();
    dp.view = camera;
    dp.view.depth = nullptr;
    dp.view.format = u16 ? DepthFormat::u16 : DepthFormat::f32;
    dp.view.width = w;
    dp.view.height = h;
    const std::int64_t step = h > 1 ? d.strides[0] : std::int64_t(w) * d.itemsize;
    if (step < std::int64_t(w) * d.itemsize || step % d.itemsize != 0) {
        bad("device depth rows must be at least a row apart, a multiple of the sample size");
    }
    dp.view.row_step_bytes = std::size_t(step);
    DeviceArray o;
    std::optional<DeviceArray> k;
    const cuda::LabelPointers l = label_pointers(out, count, w, h, o, k);
    wait_for(d, stream_, event_);
    wait_for(o, stream_, event_);
    if (k) wait_for(*k, stream_, event_);
    py::gil_scoped_release nogil;
    cuda::segment(segmenter, dp, l);
}

#else  // without the CUDA backend

namespace {
[[noreturn]] void not_built() {
    raise(ErrorCode::backend_unavailable,
          "this pyrseg was built without its CUDA backend (no CUDA compiler at build time): device arrays "
          "(__cuda_array_interface__) cannot be segmented in place; copy them to the host (cupy: .get(), torch: "
          ".cpu().numpy())");
}
}  // namespace

DeviceFrames::DeviceFrames(const py::object& stream) {
    if (!stream.is_none()) not_built();
}
DeviceFrames::~DeviceFrames() = default;
Segmenter DeviceFrames::make_segmenter(int, int, const Params&, const Outputs&) const {
    not_built();
}
void DeviceFrames::segment_cloud(Segmenter&, const py::object&, const py::object&, const py::object&,
                                 const py::object&) {
    not_built();
}
void DeviceFrames::segment_depth(Segmenter&, const py::object&, const DepthView&, const py::object&,
                                 const py::object&) {
    not_built();
}

#endif

}  // namespace pyrseg::python
