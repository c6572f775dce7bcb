// What only OpenCL's interop has, on the adapter's context and queue (opencl_adapter.hpp; the checks every API shares
// are device_frames.cpp): a frame waits for the events it is given, and buffers, queues and contexts that do not
// belong together are refused.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "interop/opencl_adapter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

using OpenclInterop = ApiTest<OpenclAdapter>;

TEST_F(OpenclInterop, AFrameWaitsForTheEventsItIsGiven) {
    // The points arrive through another queue, after a gate the test opens late: a frame that did not wait for
    // that write's event would segment the zeros the buffer held before.
    OpenclAdapter& cl = api();
    synthetic::SceneOptions o;
    o.width = 48;
    o.height = 40;
    const synthetic::Scene scene = synthetic::generate(o);
    Segmenter segmenter = opencl::make_segmenter(o.width, o.height, cl.queue());
    const std::vector<float> zeros(scene.points.size(), 0.0f);
    const int points = cl.allocate(4 * scene.points.size());
    cl.upload(points, 0, zeros.data(), 4 * zeros.size());
    opencl::CloudBuffers in;
    in.points = cl.mem(points);
    const int labels = cl.allocate(4 * std::size_t(o.width) * std::size_t(o.height));
    opencl::LabelBuffers out;
    out.labels = cl.mem(labels);
    cl_int err = CL_SUCCESS;
    cl_event gate = clCreateUserEvent(cl.context_, &err);
    ASSERT_EQ(err, CL_SUCCESS);
    cl_command_queue uploads = clCreateCommandQueue(cl.context_, cl.device_, 0, &err);
    ASSERT_EQ(err, CL_SUCCESS);
    cl_event written = nullptr;
    ASSERT_EQ(clEnqueueWriteBuffer(uploads, in.points, CL_FALSE, 0, 4 * scene.points.size(), scene.points.data(), 1,
                                   &gate, &written),
              CL_SUCCESS);
    clFlush(uploads);
    const cl_event wait[] = {written};
    cl_event done = opencl::segment(segmenter, in, out, wait);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    cl_int status = 0;
    clGetEventInfo(done, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof(status), &status, nullptr);
    EXPECT_NE(status, CL_COMPLETE) << "the frame ran before the event it waits for";
    ASSERT_EQ(clSetUserEventStatus(gate, CL_COMPLETE), CL_SUCCESS);
    ASSERT_EQ(clWaitForEvents(1, &done), CL_SUCCESS);
    clReleaseEvent(done);
    clReleaseEvent(written);
    clReleaseEvent(gate);
    clReleaseCommandQueue(uploads);
    Segmenter cpu(o.width, o.height, {}, "cpu");
    CloudView view;
    view.points = scene.points.data();
    view.width = o.width;
    view.height = o.height;
    const Result expected = cpu.segment(view);
    ASSERT_GT(expected.segment_count, 1u);
    const auto bytes = cl.download(labels, 0, 4 * expected.labels.size());
    std::vector<std::uint32_t> got(expected.labels.size());
    std::memcpy(got.data(), bytes.data(), bytes.size());
    EXPECT_TRUE(same_bytes("labels", got, expected.labels, o.width));
}

TEST_F(OpenclInterop, BuffersAndQueuesOfAnotherContextAreRefused) {
    OpenclAdapter& cl = api();
    const Wall wall;
    constexpr int kW = Wall::kWidth;
    constexpr int kH = Wall::kHeight;
    Segmenter segmenter = opencl::make_segmenter(kW, kH, cl.queue());
    opencl::CloudBuffers good_cloud;
    good_cloud.points = cl.mem(cl.allocate(4 * wall.points.size()));
    clEnqueueWriteBuffer(cl.queue_, good_cloud.points, CL_TRUE, 0, 4 * wall.points.size(), wall.points.data(), 0,
                         nullptr, nullptr);
    const int labels = cl.allocate(4 * Wall::kPixels);
    const int count = cl.allocate(4);
    cl.upload(labels, 0, wall.sentinel.data(), 4 * Wall::kPixels);
    cl.upload(count, 0, wall.sentinel.data(), 4);
    opencl::LabelBuffers good_out;
    good_out.labels = cl.mem(labels);
    good_out.count = cl.mem(count);
    const auto untouched = [&] {
        const auto l = cl.download(labels, 0, 4 * Wall::kPixels);
        EXPECT_EQ(std::memcmp(l.data(), wall.sentinel.data(), l.size()), 0) << "the labels buffer was written";
        const auto k = cl.download(count, 0, 4);
        EXPECT_EQ(std::memcmp(k.data(), wall.sentinel.data(), 4), 0) << "the count was written";
    };
    const auto refused = [&](const opencl::CloudBuffers& c, const opencl::LabelBuffers& o) {
        expect_error(
            [&] {
                cl_event e = opencl::segment(segmenter, c, o);
                clReleaseEvent(e);
            },
            "another context");
        untouched();
    };
    opencl::CloudBuffers c = good_cloud;
    c.points = cl.foreign_buffer(4 * wall.points.size());
    refused(c, good_out);
    opencl::LabelBuffers o = good_out;
    o.count = cl.foreign_buffer(4);
    refused(good_cloud, o);

    // Queues that do not fit.
    cl_command_queue other_queue = clCreateCommandQueue(cl.foreign_context(), cl.device_, 0, nullptr);
    EXPECT_THROW((void)opencl::make_segmenter(kW, kH, {cl.context_, cl.device_, other_queue}), Error);
    clReleaseCommandQueue(other_queue);
    cl_int err = CL_SUCCESS;
    cl_command_queue out_of_order =
        clCreateCommandQueue(cl.context_, cl.device_, CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE, &err);
    if (err == CL_SUCCESS) {
        expect_error(
            [&] {
                (void)opencl::make_segmenter(kW, kH, {cl.context_, cl.device_, out_of_order});
            },
            "out of order");
        clReleaseCommandQueue(out_of_order);
    }
    EXPECT_THROW((void)opencl::make_segmenter(kW, kH, {cl.context_, cl.device_, nullptr}), Error);

    // After every refusal the Segmenter still segments.
    cl_event e = opencl::segment(segmenter, good_cloud, good_out);
    ASSERT_EQ(clWaitForEvents(1, &e), CL_SUCCESS);
    clReleaseEvent(e);
    const auto k = cl.download(count, 0, 4);
    std::uint32_t segments = 0;
    std::memcpy(&segments, k.data(), 4);
    EXPECT_EQ(segments, 1u) << "a flat wall at 1 m: one segment";
}

}  // namespace
}  // namespace pyrseg::test
