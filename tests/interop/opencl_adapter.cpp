#include "interop/opencl_adapter.hpp"

#include <variant>

namespace pyrseg::test {
namespace {

std::unique_ptr<Adapter> make_opencl_adapter() {
    return std::make_unique<OpenclAdapter>();
}

INSTANTIATE_TEST_SUITE_P(Opencl, DeviceFrames, ::testing::Values(AdapterMaker{"opencl", &make_opencl_adapter}),
                         adapter_name);

}  // namespace

OpenclAdapter::~OpenclAdapter() {
    if (queue_ != nullptr) clFinish(queue_);
    for (cl_mem m : buffers_) clReleaseMemObject(m);
    for (cl_mem m : foreign_) clReleaseMemObject(m);
    if (other_ != nullptr) clReleaseContext(other_);
    if (queue_ != nullptr) clReleaseCommandQueue(queue_);
    if (context_ != nullptr) clReleaseContext(context_);
}

std::string OpenclAdapter::open() {
    cl_uint platforms = 0;
    if (clGetPlatformIDs(0, nullptr, &platforms) != CL_SUCCESS || platforms == 0) {
        return "no OpenCL platform on this machine (the ICD loader found no driver)";
    }
    std::vector<cl_platform_id> ids(platforms);
    clGetPlatformIDs(platforms, ids.data(), nullptr);
    for (cl_platform_id p : ids) {
        if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, &device_, nullptr) == CL_SUCCESS) break;
    }
    if (device_ == nullptr) return "no OpenCL device on this machine";
    cl_int err = CL_SUCCESS;
    context_ = clCreateContext(nullptr, 1, &device_, nullptr, nullptr, &err);
    EXPECT_EQ(err, CL_SUCCESS);
    queue_ = clCreateCommandQueue(context_, device_, 0, &err);
    EXPECT_EQ(err, CL_SUCCESS);
    return "";
}

Segmenter OpenclAdapter::make_segmenter(int width, int height, const Params& params, const Outputs& outputs) {
    return opencl::make_segmenter(width, height, queue(), params, outputs);
}

int OpenclAdapter::allocate(std::size_t bytes) {
    cl_int err = CL_SUCCESS;
    cl_mem m = clCreateBuffer(context_, CL_MEM_READ_WRITE, bytes, nullptr, &err);
    EXPECT_EQ(err, CL_SUCCESS);
    const unsigned char pattern = 0xAB;
    EXPECT_EQ(clEnqueueFillBuffer(queue_, m, &pattern, 1, 0, bytes, 0, nullptr, nullptr), CL_SUCCESS);
    buffers_.push_back(m);
    sizes_.push_back(bytes);
    return int(buffers_.size()) - 1;
}

std::size_t OpenclAdapter::size(int buffer) const {
    return sizes_.at(std::size_t(buffer));
}

void OpenclAdapter::upload(int buffer, std::size_t offset, const void* data, std::size_t bytes) {
    EXPECT_EQ(clEnqueueWriteBuffer(queue_, mem(buffer), CL_TRUE, offset, bytes, data, 0, nullptr, nullptr), CL_SUCCESS);
}

std::vector<unsigned char> OpenclAdapter::download(int buffer, std::size_t offset, std::size_t bytes) {
    std::vector<unsigned char> out(bytes);
    EXPECT_EQ(clEnqueueReadBuffer(queue_, mem(buffer), CL_TRUE, offset, bytes, out.data(), 0, nullptr, nullptr),
              CL_SUCCESS);
    return out;
}

void OpenclAdapter::run(Segmenter& segmenter, std::span<const Frame> frames, std::size_t /*way*/) {
    std::vector<cl_event> events;
    const auto release = [&] {
        for (cl_event e : events) clReleaseEvent(e);
    };
    try {
        for (const Frame& f : frames) {
            const opencl::LabelBuffers out = labels(f.out);
            events.push_back(std::holds_alternative<CloudFrame>(f.in)
                                 ? opencl::segment(segmenter, cloud(std::get<CloudFrame>(f.in)), out)
                                 : opencl::segment(segmenter, depth(std::get<DepthFrame>(f.in)), out));
            EXPECT_NE(events.back(), nullptr);
        }
    } catch (...) {
        EXPECT_EQ(clFinish(queue_), CL_SUCCESS);
        release();
        throw;
    }
    // The last frame's event: the ones before it completed too, in queue order.
    if (!events.empty()) {
        EXPECT_EQ(clWaitForEvents(1, &events.back()), CL_SUCCESS);
    }
    for (cl_event e : events) {
        cl_int status = 0;
        clGetEventInfo(e, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof(status), &status, nullptr);
        EXPECT_EQ(status, CL_COMPLETE);
    }
    release();
}

cl_mem OpenclAdapter::mem(int buffer) const {
    return buffer == Region::kNone ? nullptr : buffers_.at(std::size_t(buffer));
}

opencl::CloudBuffers OpenclAdapter::cloud(const CloudFrame& frame) const {
    return {mem(frame.points.buffer), frame.points.offset,     mem(frame.normals.buffer), frame.normals.offset,
            frame.row_step_bytes,     mem(frame.color.buffer), frame.color.offset,        frame.color_row_step_bytes};
}

opencl::DepthBuffer OpenclAdapter::depth(const DepthFrame& frame) const {
    return {mem(frame.samples.buffer), frame.samples.offset, frame.view,
            mem(frame.color.buffer),   frame.color.offset,   frame.color_row_step_bytes};
}

opencl::LabelBuffers OpenclAdapter::labels(const LabelFrame& frame) const {
    return {mem(frame.labels.buffer), frame.labels.offset,          frame.row_step_bytes,    mem(frame.count.buffer),
            frame.count.offset,       mem(frame.statistics.buffer), frame.statistics.offset, mem(frame.graph.buffer),
            frame.graph.offset,       mem(frame.tracks.buffer),     frame.tracks.offset};
}

cl_context OpenclAdapter::foreign_context() {
    if (other_ == nullptr) other_ = clCreateContext(nullptr, 1, &device_, nullptr, nullptr, nullptr);
    EXPECT_NE(other_, nullptr);
    return other_;
}

cl_mem OpenclAdapter::foreign_buffer(std::size_t bytes) {
    cl_int err = CL_SUCCESS;
    cl_mem m = clCreateBuffer(foreign_context(), CL_MEM_READ_WRITE, bytes, nullptr, &err);
    EXPECT_EQ(err, CL_SUCCESS);
    foreign_.push_back(m);
    return m;
}

}  // namespace pyrseg::test
