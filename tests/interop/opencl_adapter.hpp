#pragma once
// The OpenCL side of the shared device-frame checks (device_frames.hpp): the first OpenCL device there is (PoCL's CPU
// device in CI), a context and an in-order queue of the test's own, buffers on that context; a frame is
// opencl::segment, waited for through the event it returns.
#include <string>
#include <vector>

#include "interop/device_frames.hpp"
#include "pyrseg/opencl.hpp"

namespace pyrseg::test {

class OpenclAdapter final : public Adapter {
public:
    OpenclAdapter() = default;
    ~OpenclAdapter() override;
    OpenclAdapter(const OpenclAdapter&) = delete;
    OpenclAdapter& operator=(const OpenclAdapter&) = delete;

    [[nodiscard]] std::string open() override;
    [[nodiscard]] std::string backend_name() const override { return "opencl"; }
    [[nodiscard]] std::vector<Way> ways() const override { return {{"opencl::segment"}}; }
    [[nodiscard]] Segmenter make_segmenter(int width, int height, const Params& params,
                                           const Outputs& outputs = {}) override;
    [[nodiscard]] int allocate(std::size_t bytes) override;
    [[nodiscard]] std::size_t size(int buffer) const override;
    void upload(int buffer, std::size_t offset, const void* data, std::size_t bytes) override;
    [[nodiscard]] std::vector<unsigned char> download(int buffer, std::size_t offset, std::size_t bytes) override;
    void run(Segmenter& segmenter, std::span<const Frame> frames, std::size_t way) override;

    // For the OpenCL-only tests: the application's objects, and the shared frames in OpenCL's terms.
    [[nodiscard]] opencl::Queue queue() const { return {context_, device_, queue_}; }
    [[nodiscard]] cl_mem mem(int buffer) const;
    [[nodiscard]] opencl::CloudBuffers cloud(const CloudFrame& frame) const;
    [[nodiscard]] opencl::DepthBuffer depth(const DepthFrame& frame) const;
    [[nodiscard]] opencl::LabelBuffers labels(const LabelFrame& frame) const;
    // A buffer on another context of the same device (released with the adapter).
    [[nodiscard]] cl_mem foreign_buffer(std::size_t bytes);
    [[nodiscard]] cl_context foreign_context();

    cl_device_id device_ = nullptr;
    cl_context context_ = nullptr;
    cl_command_queue queue_ = nullptr;

private:
    cl_context other_ = nullptr;
    std::vector<cl_mem> buffers_;
    std::vector<std::size_t> sizes_;
    std::vector<cl_mem> foreign_;
};

}  // namespace pyrseg::test
