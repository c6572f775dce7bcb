// pyrseg/cuda.hpp: Segmenters on the caller's stream, and frames on the caller's device pointers. The checks here are
// the CUDA ones (which device a stream or pointer belongs to, whether memory is the device's, how large an allocation
// is); the frame itself is core/device_frame.cpp's, as for every API, and the stream's commands are
// cuda_backend.cu's.
#include "pyrseg/cuda.hpp"

#include <cudaTypedefs.h>
#include <cuda_runtime_api.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "backends/cuda/cuda_backend.hpp"
#include "backends/cuda/cuda_device.hpp"
#include "core/device_frame.hpp"
#include "core/executor.hpp"
#include "core/gpu/gpu_executor.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::cuda {
namespace {

[[noreturn]] void bad(const std::string& what) {
    throw Error(ErrorCode::invalid_argument, what);
}

// CUDA's words for an error, which is then cleared from the runtime's last error: the application's next
// cudaGetLastError must not report what pyrseg has already reported.
std::string cuda_says(cudaError_t err) {
    (void)cudaGetLastError();
    return std::string(cudaGetErrorName(err)) + ": " + cudaGetErrorString(err);
}

int device_of_stream(cudaStream_t stream) {
    int device = -1;
#if CUDART_VERSION >= 12080
    const cudaError_t err = cudaStreamGetDevice(stream, &device);
    if (err != cudaSuccess) bad("the stream is not a usable CUDA stream (cudaStreamGetDevice: " + cuda_says(err) + ")");
#else
    (void)stream;
    const cudaError_t err = cudaGetDevice(&device);
    if (err != cudaSuccess) bad("no current CUDA device (cudaGetDevice: " + cuda_says(err) + ")");
#endif
    return device;
}

// The driver's cuMemGetAddressRange, or null where the driver does not give it (pyrseg then trusts the caller's
// sizes). Looked up once.
PFN_cuMemGetAddressRange_v3020 address_range_function() {
#if CUDART_VERSION >= 12050
    static const PFN_cuMemGetAddressRange_v3020 function = [] {
        void* f = nullptr;
        cudaDriverEntryPointQueryResult found = cudaDriverEntryPointSymbolNotFound;
        if (cudaGetDriverEntryPointByVersion("cuMemGetAddressRange", &f, 3020, cudaEnableDefault, &found) !=
                cudaSuccess ||
            found != cudaDriverEntryPointSuccess) {
            (void)cudaGetLastError();
            return PFN_cuMemGetAddressRange_v3020{nullptr};
        }
        return reinterpret_cast<PFN_cuMemGetAddressRange_v3020>(f);
    }();
    return function;
#else
    return nullptr;
#endif
}

// How many bytes the allocation holding `pointer` has from there on; `claimed` where the driver cannot tell.
std::size_t bytes_from(const void* pointer, std::size_t claimed) {
    const PFN_cuMemGetAddressRange_v3020 range = address_range_function();
    if (range == nullptr) return claimed;
    CUdeviceptr base = 0;
    std::size_t size = 0;
    const auto at = static_cast<CUdeviceptr>(reinterpret_cast<std::uintptr_t>(pointer));
    if (range(&base, &size, at) != CUDA_SUCCESS || at < base || at - base > size) return claimed;
    return std::min<std::size_t>(claimed, size - std::size_t(at - base));
}

// One of the caller's pointers, checked: device memory of the Segmenter's device, or managed memory.
core::ExternalBuffer external(const CudaDevice& device, const void* pointer, std::size_t bytes, const char* what) {
    core::ExternalBuffer b;
    if (pointer == nullptr) return b;  // the frame's checks say whether it is needed
    const std::string name = std::string("the ") + what + " pointer";
    cudaPointerAttributes a{};
    const cudaError_t err = cudaPointerGetAttributes(&a, pointer);
    if (err != cudaSuccess) bad(name + " is not one CUDA can tell (cudaPointerGetAttributes: " + cuda_says(err) + ")");
    const std::string device_memory =
        "pyrseg::cuda::segment reads and writes device memory (cudaMalloc, cudaMallocAsync, cudaMallocManaged); give "
        "host memory to Segmenter::segment";
    switch (a.type) {
        case cudaMemoryTypeDevice:
            if (a.device != device.ordinal()) {
                bad(name + " is memory of CUDA device " + std::to_string(a.device) +
                    ", but the Segmenter's stream is on " + "device " + std::to_string(device.ordinal()));
            }
            break;
        case cudaMemoryTypeManaged:
            break;
        case cudaMemoryTypeHost:
            bad(name + " is pinned host memory (cudaMallocHost, cudaHostAlloc, cudaHostRegister): " + device_memory);
        default:
            bad(name + " is host memory that CUDA did not allocate: " + device_memory);
    }
    b.handle = static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(pointer));
    b.offset = 0;
    b.bytes = bytes_from(pointer, bytes);
    return b;
}

// Lets the calling thread query pointers while a capture is under way, whatever its mode and thread: the queries
// queue nothing, but a strict capture may count any call outside its list as potentially unsafe. The frame's own
// commands are issued after, in the thread's own mode.
class RelaxedCapture {
public:
    RelaxedCapture() : exchanged_(cudaThreadExchangeStreamCaptureMode(&mode_) == cudaSuccess) {}
    ~RelaxedCapture() {
        if (exchanged_) cudaThreadExchangeStreamCaptureMode(&mode_);
    }
    RelaxedCapture(const RelaxedCapture&) = delete;
    RelaxedCapture& operator=(const RelaxedCapture&) = delete;

private:
    cudaStreamCaptureMode mode_ = cudaStreamCaptureModeRelaxed;
    bool exchanged_;
};

CudaDevice& device_of(Segmenter& segmenter) {
    auto* device = dynamic_cast<CudaDevice*>(core::executor_of(segmenter).gpu_device());
    if (device == nullptr) {
        bad("this Segmenter does not run on CUDA; make it with pyrseg::cuda::make_segmenter on your stream");
    }
    if (!device->callers_stream()) {
        bad("this Segmenter runs on a CUDA stream of pyrseg's own (Segmenter(..., \"cuda\")); make it with "
            "pyrseg::cuda::make_segmenter on your stream to give it device pointers");
    }
    return *device;
}

core::DeviceLabels labels_of(const CudaDevice& device, const LabelPointers& out) {
    core::DeviceLabels l;
    l.labels = external(device, out.labels, out.labels_bytes, "labels");
    l.row_step_bytes = out.row_step_bytes;
    l.count = external(device, out.count, 4, "segment count");
    l.statistics = external(device, out.statistics, out.statistics_bytes, "statistics");
    l.graph = external(device, out.graph, out.graph_bytes, "segment graph");
    l.tracks = external(device, out.tracks, out.tracks_bytes, "tracks");
    return l;
}

}  // namespace

Segmenter make_segmenter(int width, int height, cudaStream_t stream, const Params& params, const Outputs& outputs) {
    // The capture first: what follows (device queries, allocation) is not for a stream being captured.
    cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
    const cudaError_t err = cudaStreamIsCapturing(stream, &status);
    if (err != cudaSuccess) {
        std::string why;
        if (describe_devices(&why).empty()) {
            (void)cudaGetLastError();
            throw Error(ErrorCode::backend_unavailable, "pyrseg::cuda::make_segmenter: " + why);
        }
        bad("the stream is not a usable CUDA stream (cudaStreamIsCapturing: " + cuda_says(err) + ")");
    }
    if (status != cudaStreamCaptureStatusNone) {
        bad("the stream is being captured into a CUDA graph: make the Segmenter before capturing (it allocates its "
            "buffers)");
    }
    const int device = device_of_stream(stream);
    const CurrentDevice current(device);
    (void)address_range_function();  // looked up now rather than in a frame, which may be captured
    return core::make_segmenter(width, height, params, outputs, "cuda", [&](const core::Plan& plan) {
        return gpu::make_gpu_executor(plan, make_device(device, stream));
    });
}

void segment(Segmenter& segmenter, const CloudPointers& cloud, const LabelPointers& out) {
    CudaDevice& device = device_of(segmenter);
    const CurrentDevice current(device.ordinal());
    core::DeviceCloud c;
    core::DeviceLabels l;
    {
        const RelaxedCapture relaxed;
        c.points = external(device, cloud.points, cloud.points_bytes, "points");
        c.normals = external(device, cloud.normals, cloud.normals_bytes, "normals");
        c.color.rgb = external(device, cloud.color, cloud.color_bytes, "colour image");
        l = labels_of(device, out);
    }
    c.row_step_bytes = cloud.row_step_bytes;
    c.color.row_step_bytes = cloud.color_row_step_bytes;
    core::run_device_frame(segmenter, c, l);
}

void segment(Segmenter& segmenter, const DepthPointers& depth, const LabelPointers& out) {
    CudaDevice& device = device_of(segmenter);
    const CurrentDevice current(device.ordinal());
    core::DeviceDepth d;
    core::DeviceLabels l;
    {
        const RelaxedCapture relaxed;
        d.samples = external(device, depth.samples, depth.bytes, "depth samples");
        d.color.rgb = external(device, depth.color, depth.color_bytes, "colour image");
        l = labels_of(device, out);
    }
    d.view = depth.view;
    d.color.row_step_bytes = depth.color_row_step_bytes;
    core::run_device_frame(segmenter, d, l);
}

}  // namespace pyrseg::cuda
