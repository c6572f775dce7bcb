#pragma once
// The CUDA side of the shared device-frame checks (device_frames.hpp): device 0, a non-blocking stream of the
// test's own, memory it allocates; a frame is cuda::segment on that stream, waited for by synchronizing it. Without a
// CUDA device every test is skipped, with pyrseg's reason (`pyrseg backends`), else CUDA's.
#include <cuda_runtime_api.h>

#include <string>
#include <vector>

#include "interop/device_frames.hpp"
#include "pyrseg/cuda.hpp"

namespace pyrseg::test {

class CudaAdapter final : public Adapter {
public:
    CudaAdapter() = default;
    ~CudaAdapter() override;
    CudaAdapter(const CudaAdapter&) = delete;
    CudaAdapter& operator=(const CudaAdapter&) = delete;

    [[nodiscard]] std::string open() override;
    [[nodiscard]] std::string backend_name() const override { return "cuda"; }
    [[nodiscard]] std::vector<Way> ways() const override { return {{"cuda::segment"}}; }
    [[nodiscard]] Segmenter make_segmenter(int width, int height, const Params& params,
                                           const Outputs& outputs = {}) override;
    [[nodiscard]] int allocate(std::size_t bytes) override;
    [[nodiscard]] std::size_t size(int buffer) const override;
    void upload(int buffer, std::size_t offset, const void* data, std::size_t bytes) override;
    [[nodiscard]] std::vector<unsigned char> download(int buffer, std::size_t offset, std::size_t bytes) override;
    void run(Segmenter& segmenter, std::span<const Frame> frames, std::size_t way) override;

    // For the CUDA-only tests: the application's stream and memory, and the shared frames in CUDA's terms.
    [[nodiscard]] cudaStream_t stream() const { return stream_; }
    [[nodiscard]] unsigned char* pointer(int buffer) const;
    [[nodiscard]] cuda::CloudPointers cloud(const CloudFrame& frame) const;
    [[nodiscard]] cuda::DepthPointers depth(const DepthFrame& frame) const;
    [[nodiscard]] cuda::LabelPointers labels(const LabelFrame& frame) const;
    // Pinned host memory holding `bytes` of `data` (freed with the adapter).
    [[nodiscard]] void* pinned(std::size_t bytes, const void* data);
    // `count` items at `src`, once the stream has done everything queued on it.
    template <class T>
    [[nodiscard]] std::vector<T> read(const void* src, std::size_t count) {
        std::vector<T> out(count);
        copy_out(out.data(), src, count * sizeof(T));
        return out;
    }

private:
    void copy_out(void* dst, const void* src, std::size_t bytes);

    cudaStream_t stream_ = nullptr;
    std::vector<unsigned char*> memory_;
    std::vector<std::size_t> sizes_;
    std::vector<void*> pinned_;
};

}  // namespace pyrseg::test
