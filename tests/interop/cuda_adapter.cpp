#include "interop/cuda_adapter.hpp"

#include <cstring>
#include <variant>

#include "pyrseg/backend.hpp"

namespace pyrseg::test {
namespace {

std::unique_ptr<Adapter> make_cuda_adapter() {
    return std::make_unique<CudaAdapter>();
}

INSTANTIATE_TEST_SUITE_P(Cuda, DeviceFrames, ::testing::Values(AdapterMaker{"cuda", &make_cuda_adapter}), adapter_name);

// Why there is no CUDA device here, in pyrseg's words (`pyrseg backends`), else CUDA's; empty when there is one.
std::string why_no_cuda_device() {
    int count = 0;
    const cudaError_t err = cudaGetDeviceCount(&count);
    if (err == cudaSuccess && count > 0) return "";
    std::string why = "no CUDA device (cudaGetDeviceCount: " +
                      (err == cudaSuccess ? std::string("0 devices")
                                          : std::string(cudaGetErrorName(err)) + ": " + cudaGetErrorString(err)) +
                      ")";
    (void)cudaGetLastError();
    for (const BackendInfo& b : list_backends()) {
        if (b.name == "cuda" && !b.available && !b.reason.empty()) why = b.reason;
    }
    return why;
}

}  // namespace

CudaAdapter::~CudaAdapter() {
    if (stream_ != nullptr) {
        EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
    }
    for (unsigned char* p : memory_) cudaFree(p);
    for (void* p : pinned_) cudaFreeHost(p);
    if (stream_ != nullptr) cudaStreamDestroy(stream_);
}

std::string CudaAdapter::open() {
    std::string why = why_no_cuda_device();
    if (!why.empty()) return why;
    EXPECT_EQ(cudaSetDevice(0), cudaSuccess);
    EXPECT_EQ(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), cudaSuccess);
    return "";
}

Segmenter CudaAdapter::make_segmenter(int width, int height, const Params& params, const Outputs& outputs) {
    return cuda::make_segmenter(width, height, stream_, params, outputs);
}

int CudaAdapter::allocate(std::size_t bytes) {
    void* p = nullptr;
    EXPECT_EQ(cudaMalloc(&p, bytes), cudaSuccess);
    EXPECT_EQ(cudaMemsetAsync(p, 0xAB, bytes, stream_), cudaSuccess);
    memory_.push_back(static_cast<unsigned char*>(p));
    sizes_.push_back(bytes);
    return int(memory_.size()) - 1;
}

std::size_t CudaAdapter::size(int buffer) const {
    return sizes_.at(std::size_t(buffer));
}

void CudaAdapter::upload(int buffer, std::size_t offset, const void* data, std::size_t bytes) {
    // Waited for: the source may go at once.
    EXPECT_EQ(cudaMemcpyAsync(pointer(buffer) + offset, data, bytes, cudaMemcpyHostToDevice, stream_), cudaSuccess);
    EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
}

std::vector<unsigned char> CudaAdapter::download(int buffer, std::size_t offset, std::size_t bytes) {
    return read<unsigned char>(pointer(buffer) + offset, bytes);
}

void CudaAdapter::copy_out(void* dst, const void* src, std::size_t bytes) {
    EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
    EXPECT_EQ(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyDeviceToHost, stream_), cudaSuccess);
    EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
}

void CudaAdapter::run(Segmenter& segmenter, std::span<const Frame> frames, std::size_t /*way*/) {
    try {
        for (const Frame& f : frames) {
            const cuda::LabelPointers out = labels(f.out);
            if (std::holds_alternative<CloudFrame>(f.in)) {
                cuda::segment(segmenter, cloud(std::get<CloudFrame>(f.in)), out);
            } else {
                cuda::segment(segmenter, depth(std::get<DepthFrame>(f.in)), out);
            }
        }
    } catch (...) {
        EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
        throw;
    }
    EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
}

unsigned char* CudaAdapter::pointer(int buffer) const {
    return buffer == Region::kNone ? nullptr : memory_.at(std::size_t(buffer));
}

// A region as CUDA takes it: a pointer into the allocation and the bytes from there on.
cuda::CloudPointers CudaAdapter::cloud(const CloudFrame& frame) const {
    cuda::CloudPointers c;
    if (frame.points.buffer != Region::kNone) {
        c.points = reinterpret_cast<const float*>(pointer(frame.points.buffer) + frame.points.offset);
        c.points_bytes = size(frame.points.buffer) - frame.points.offset;
    }
    if (frame.normals.buffer != Region::kNone) {
        c.normals = reinterpret_cast<const float*>(pointer(frame.normals.buffer) + frame.normals.offset);
        c.normals_bytes = size(frame.normals.buffer) - frame.normals.offset;
    }
    c.row_step_bytes = frame.row_step_bytes;
    if (frame.color.buffer != Region::kNone) {
        c.color = reinterpret_cast<const std::uint8_t*>(pointer(frame.color.buffer) + frame.color.offset);
        c.color_bytes = size(frame.color.buffer) - frame.color.offset;
    }
    c.color_row_step_bytes = frame.color_row_step_bytes;
    return c;
}

cuda::DepthPointers CudaAdapter::depth(const DepthFrame& frame) const {
    cuda::DepthPointers d;
    if (frame.samples.buffer != Region::kNone) {
        d.samples = pointer(frame.samples.buffer) + frame.samples.offset;
        d.bytes = size(frame.samples.buffer) - frame.samples.offset;
    }
    d.view = frame.view;
    if (frame.color.buffer != Region::kNone) {
        d.color = reinterpret_cast<const std::uint8_t*>(pointer(frame.color.buffer) + frame.color.offset);
        d.color_bytes = size(frame.color.buffer) - frame.color.offset;
    }
    d.color_row_step_bytes = frame.color_row_step_bytes;
    return d;
}

cuda::LabelPointers CudaAdapter::labels(const LabelFrame& frame) const {
    cuda::LabelPointers l;
    if (frame.labels.buffer != Region::kNone) {
        l.labels = reinterpret_cast<std::uint32_t*>(pointer(frame.labels.buffer) + frame.labels.offset);
        l.labels_bytes = size(frame.labels.buffer) - frame.labels.offset;
    }
    l.row_step_bytes = frame.row_step_bytes;
    if (frame.count.buffer != Region::kNone) {
        l.count = reinterpret_cast<std::uint32_t*>(pointer(frame.count.buffer) + frame.count.offset);
    }
    if (frame.statistics.buffer != Region::kNone) {
        l.statistics = reinterpret_cast<std::uint32_t*>(pointer(frame.statistics.buffer) + frame.statistics.offset);
        l.statistics_bytes = size(frame.statistics.buffer) - frame.statistics.offset;
    }
    if (frame.graph.buffer != Region::kNone) {
        l.graph = reinterpret_cast<std::uint32_t*>(pointer(frame.graph.buffer) + frame.graph.offset);
        l.graph_bytes = size(frame.graph.buffer) - frame.graph.offset;
    }
    if (frame.tracks.buffer != Region::kNone) {
        l.tracks = reinterpret_cast<std::uint32_t*>(pointer(frame.tracks.buffer) + frame.tracks.offset);
        l.tracks_bytes = size(frame.tracks.buffer) - frame.tracks.offset;
    }
    return l;
}

void* CudaAdapter::pinned(std::size_t bytes, const void* data) {
    void* p = nullptr;
    EXPECT_EQ(cudaMallocHost(&p, bytes), cudaSuccess);
    pinned_.push_back(p);
    if (p != nullptr) std::memcpy(p, data, bytes);
    return p;
}

}  // namespace pyrseg::test
