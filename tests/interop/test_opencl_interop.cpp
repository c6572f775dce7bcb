// pyrseg/opencl.hpp on a context, device, queue and buffers this test creates itself, as an application would:
// device-resident frames give the host path's labels and segment count byte for byte (clouds with and without
// normals, both metrics, depth images u16 and f32 with odd row steps), order through events, and bad input is a
// pyrseg::Error that leaves the caller's buffers and queue untouched.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/opencl.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

// The application's side: the first OpenCL device there is (PoCL's CPU device in CI).
class OpenclApp : public ::testing::Test {
protected:
    void SetUp() override {
        cl_uint platforms = 0;
        if (clGetPlatformIDs(0, nullptr, &platforms) != CL_SUCCESS || platforms == 0) {
            GTEST_SKIP() << "no OpenCL platform on this machine (the ICD loader found no driver)";
        }
        std::vector<cl_platform_id> ids(platforms);
        clGetPlatformIDs(platforms, ids.data(), nullptr);
        for (cl_platform_id p : ids) {
            if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, &device_, nullptr) == CL_SUCCESS) break;
        }
        if (device_ == nullptr) GTEST_SKIP() << "no OpenCL device on this machine";
        cl_int err = CL_SUCCESS;
        context_ = clCreateContext(nullptr, 1, &device_, nullptr, nullptr, &err);
        ASSERT_EQ(err, CL_SUCCESS);
        queue_ = clCreateCommandQueue(context_, device_, 0, &err);
        ASSERT_EQ(err, CL_SUCCESS);
    }

    void TearDown() override {
        for (cl_mem m : buffers_) clReleaseMemObject(m);
        if (queue_ != nullptr) clReleaseCommandQueue(queue_);
        if (context_ != nullptr) clReleaseContext(context_);
    }

    [[nodiscard]] opencl::Queue queue() const { return {context_, device_, queue_}; }

    cl_mem buffer(std::size_t bytes, const void* data = nullptr, cl_context context = nullptr) {
        cl_int err = CL_SUCCESS;
        cl_mem m = clCreateBuffer(context != nullptr ? context : context_, CL_MEM_READ_WRITE, bytes, nullptr, &err);
        EXPECT_EQ(err, CL_SUCCESS);
        if (data != nullptr) {
            EXPECT_EQ(clEnqueueWriteBuffer(queue_, m, CL_TRUE, 0, bytes, data, 0, nullptr, nullptr), CL_SUCCESS);
        }
        buffers_.push_back(m);
        return m;
    }

    template <class T>
    std::vector<T> read(cl_mem m, std::size_t count, std::size_t offset = 0) {
        std::vector<T> out(count);
        EXPECT_EQ(clEnqueueReadBuffer(queue_, m, CL_TRUE, offset, count * sizeof(T), out.data(), 0, nullptr, nullptr),
                  CL_SUCCESS);
        return out;
    }

    cl_device_id device_ = nullptr;
    cl_context context_ = nullptr;
    cl_command_queue queue_ = nullptr;
    std::vector<cl_mem> buffers_;
};

// Rows of `width` items of `item` bytes copied `pitch` bytes apart (the rest 0xCD), as an SDK pads them.
std::vector<unsigned char> pitched(const void* packed, int width, int height, std::size_t item, std::size_t pitch) {
    std::vector<unsigned char> out(pitch * std::size_t(height), 0xCD);
    for (int y = 0; y < height; ++y) {
        std::memcpy(out.data() + std::size_t(y) * pitch,
                    static_cast<const unsigned char*>(packed) + std::size_t(y) * std::size_t(width) * item,
                    std::size_t(width) * item);
    }
    return out;
}

// The labels of a device frame's buffer, rows `pitch` bytes apart, packed again.
std::vector<std::uint32_t> unpitch(const std::vector<unsigned char>& bytes, int width, int height, std::size_t pitch) {
    std::vector<std::uint32_t> out(std::size_t(width) * std::size_t(height));
    for (int y = 0; y < height; ++y) {
        std::memcpy(out.data() + std::size_t(y) * std::size_t(width), bytes.data() + std::size_t(y) * pitch,
                    4 * std::size_t(width));
    }
    return out;
}

struct Scene {
    const char* what;
    int width, height;
    synthetic::Sensor sensor;
    bool normals;
    Params params;
    std::size_t cloud_pad;   // extra bytes per row of points
    std::size_t labels_pad;  // extra bytes per row of labels
};

TEST_F(OpenclApp, CloudFramesMatchTheHostPath) {
    const Scene scenes[] = {
        {"paper metric, estimated normals, packed", 131, 97, synthetic::Sensor::structured_light, false, Params{}, 0,
         0},
        {"given normals, padded rows", 67, 45, synthetic::Sensor::structured_light, true, Params{}, 20, 12},
        {"kinect-v1 preset (robust metric), padded", 101, 77, synthetic::Sensor::kinect_v1, false,
         sensor_preset(SensorKind::kinect_v1), 4, 4},
        {"a thin strip", 57, 9, synthetic::Sensor::structured_light, false, Params{}, 8, 0},
    };
    for (const Scene& s : scenes) {
        SCOPED_TRACE(s.what);
        synthetic::SceneOptions o;
        o.width = s.width;
        o.height = s.height;
        o.sensor = s.sensor;
        const synthetic::Scene scene = synthetic::generate(o);
        CloudView view;
        view.points = scene.points.data();
        view.normals = s.normals ? scene.normals.data() : nullptr;
        view.width = s.width;
        view.height = s.height;
        Segmenter cpu(s.width, s.height, s.params, "cpu");
        const Result expected = cpu.segment(view);
        ASSERT_GT(expected.segment_count, 0u);

        const std::size_t cloud_pitch = 12 * std::size_t(s.width) + s.cloud_pad;
        const std::size_t labels_pitch = 4 * std::size_t(s.width) + s.labels_pad;
        const auto points = pitched(scene.points.data(), s.width, s.height, 12, cloud_pitch);
        const auto normals = pitched(scene.normals.data(), s.width, s.height, 12, cloud_pitch);
        Segmenter segmenter = opencl::make_segmenter(s.width, s.height, queue(), s.params);
        EXPECT_EQ(segmenter.backend_name(), "opencl");
        opencl::CloudBuffers in;
        in.points = buffer(points.size() + 16, nullptr);
        ASSERT_EQ(
            clEnqueueWriteBuffer(queue_, in.points, CL_TRUE, 16, points.size(), points.data(), 0, nullptr, nullptr),
            CL_SUCCESS);
        in.points_offset = 16;  // data need not start at the buffer's start
        if (s.normals) in.normals = buffer(normals.size(), normals.data());
        in.row_step_bytes = s.cloud_pad == 0 ? 0 : cloud_pitch;
        opencl::LabelBuffers out;
        out.labels = buffer(labels_pitch * std::size_t(s.height));
        out.row_step_bytes = s.labels_pad == 0 ? 0 : labels_pitch;
        out.count = buffer(16);
        out.count_offset = 8;
        // Two frames queued back to back before anything is read: the second reuses pyrseg's buffers after the
        // first, in queue order.
        cl_event first = opencl::segment(segmenter, in, out);
        opencl::LabelBuffers out2 = out;
        out2.labels = buffer(labels_pitch * std::size_t(s.height));
        out2.count = nullptr;
        cl_event second = opencl::segment(segmenter, in, out2);
        ASSERT_NE(first, nullptr);
        ASSERT_NE(second, nullptr);
        ASSERT_EQ(clWaitForEvents(1, &second), CL_SUCCESS);
        cl_int status = 0;
        clGetEventInfo(first, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof(status), &status, nullptr);
        EXPECT_EQ(status, CL_COMPLETE);
        clReleaseEvent(first);
        clReleaseEvent(second);
        EXPECT_TRUE(segmenter.last_timings().empty());

        for (cl_mem labels : {out.labels, out2.labels}) {
            const auto bytes = read<unsigned char>(labels, labels_pitch * std::size_t(s.height));
            EXPECT_TRUE(
                same_bytes("labels", unpitch(bytes, s.width, s.height, labels_pitch), expected.labels, s.width));
        }
        EXPECT_EQ(read<std::uint32_t>(out.count, 1, 8)[0], expected.segment_count);
        // The same Segmenter's host path, on the caller's queue.
        const Result host = segmenter.segment(view);
        EXPECT_TRUE(same_bytes("host path labels", host.labels, expected.labels, s.width));
    }
}

TEST_F(OpenclApp, DepthFramesMatchTheHostPath) {
    synthetic::SceneOptions o;
    o.width = 93;
    o.height = 61;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene scene = synthetic::generate(o);
    const int w = o.width;
    const int h = o.height;
    std::vector<std::uint16_t> u16(std::size_t(w) * std::size_t(h));
    std::vector<float> f32(u16.size());
    for (std::size_t i = 0; i < u16.size(); ++i) {
        const float z = scene.points[3 * i + 2];
        u16[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
        f32[i] = i % 53 == 1 ? -z : z * 0.001f;  // metres; NaN and negative samples are missing data
    }
    Params params = sensor_preset(SensorKind::kinect_v1);
    Segmenter cpu(w, h, params, "cpu");
    Segmenter segmenter = opencl::make_segmenter(w, h, queue(), params);
    struct Case {
        const char* what;
        const void* samples;
        DepthFormat format;
        std::size_t sample;
        std::size_t pad;
        double metres_per_unit;
        double fx_scale;
    };
    const Case cases[] = {
        {"u16 mm, packed", u16.data(), DepthFormat::u16, 2, 0, 0.001, 1.0},
        {"u16 mm, rows of 2W+6 bytes", u16.data(), DepthFormat::u16, 2, 6, 0.001, 1.0},
        {"f32 m, rows of 4W+12 bytes, other intrinsics", f32.data(), DepthFormat::f32, 4, 12, 1.0, 1.2},
        {"u16 mm again, first intrinsics", u16.data(), DepthFormat::u16, 2, 2, 0.001, 1.0},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        const std::size_t pitch = c.sample * std::size_t(w) + c.pad;
        const auto bytes = pitched(c.samples, w, h, c.sample, pitch);
        DepthView view{bytes.data(),   c.format,      w, h, pitch, c.metres_per_unit, scene.fx * c.fx_scale, scene.fy,
                       scene.cx + 0.3, scene.cy - 0.2};
        const Result expected = cpu.segment(view);
        ASSERT_GT(expected.segment_count, 1u);
        opencl::DepthBuffer in;
        in.samples = buffer(bytes.size(), bytes.data());
        in.view = view;
        in.view.depth = nullptr;
        opencl::LabelBuffers out;
        out.labels = buffer(4 * std::size_t(w) * std::size_t(h));
        out.count = buffer(4);
        cl_event done = opencl::segment(segmenter, in, out);
        ASSERT_EQ(clWaitForEvents(1, &done), CL_SUCCESS);
        clReleaseEvent(done);
        EXPECT_TRUE(same_bytes("labels", read<std::uint32_t>(out.labels, expected.labels.size()), expected.labels, w));
        EXPECT_EQ(read<std::uint32_t>(out.count, 1)[0], expected.segment_count);
    }
}

TEST_F(OpenclApp, AFrameWaitsForTheEventsItIsGiven) {
    // The points arrive through another queue, after a gate the test opens late: a frame that did not wait for
    // that write's event would segment the zeros the buffer held before.
    synthetic::SceneOptions o;
    o.width = 48;
    o.height = 40;
    const synthetic::Scene scene = synthetic::generate(o);
    Segmenter segmenter = opencl::make_segmenter(o.width, o.height, queue());
    const std::vector<float> zeros(scene.points.size(), 0.0f);
    opencl::CloudBuffers in;
    in.points = buffer(4 * scene.points.size(), zeros.data());
    opencl::LabelBuffers out;
    out.labels = buffer(4 * std::size_t(o.width) * std::size_t(o.height));
    cl_int err = CL_SUCCESS;
    cl_event gate = clCreateUserEvent(context_, &err);
    ASSERT_EQ(err, CL_SUCCESS);
    cl_command_queue uploads = clCreateCommandQueue(context_, device_, 0, &err);
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
    EXPECT_TRUE(same_bytes("labels", read<std::uint32_t>(out.labels, std::size_t(o.width) * std::size_t(o.height)),
                           expected.labels, o.width));
}

TEST_F(OpenclApp, BadInputIsAnErrorAndWritesNothing) {
    constexpr int w = 32;
    constexpr int h = 24;
    std::vector<float> points(3 * w * h);
    for (int i = 0; i < w * h; ++i) {  // a wall 1 m away, 2 mm between pixels
        points[3 * i] = float(2 * (i % w - w / 2));
        points[3 * i + 1] = float(2 * (i / w - h / 2));
        points[3 * i + 2] = 1000.0f;
    }
    std::vector<std::uint16_t> depth(w * h, 1000);
    Segmenter segmenter = opencl::make_segmenter(w, h, queue());
    const std::vector<std::uint32_t> sentinel(w * h, 0xDEADBEEFu);
    opencl::CloudBuffers good_cloud;
    good_cloud.points = buffer(4 * points.size(), points.data());
    opencl::DepthBuffer good_depth;
    good_depth.samples = buffer(2 * depth.size(), depth.data());
    good_depth.view = DepthView{nullptr, DepthFormat::u16, w, h, 0, 0.001, 500, 500, 16, 12};
    opencl::LabelBuffers good_out;
    good_out.labels = buffer(4 * sentinel.size(), sentinel.data());
    good_out.count = buffer(4, sentinel.data());
    const auto untouched = [&] {
        clFinish(queue_);
        EXPECT_EQ(read<std::uint32_t>(good_out.labels, sentinel.size()), sentinel) << "the labels buffer was written";
        EXPECT_EQ(read<std::uint32_t>(good_out.count, 1)[0], 0xDEADBEEFu) << "the count was written";
    };
    const auto expect_error = [&](const auto& frame, const opencl::LabelBuffers& out, const std::string& words) {
        SCOPED_TRACE(words);
        try {
            cl_event e = opencl::segment(segmenter, frame, out);
            clReleaseEvent(e);
            ADD_FAILURE() << "no error; expected one naming " << words;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
        untouched();
    };

    cl_context other = clCreateContext(nullptr, 1, &device_, nullptr, nullptr, nullptr);
    ASSERT_NE(other, nullptr);
    opencl::CloudBuffers c = good_cloud;
    c.points = buffer(4 * points.size() - 4);
    expect_error(c, good_out, "needs");  // one float short
    c = good_cloud;
    c.points_offset = 8;
    expect_error(c, good_out, "needs");  // the offset leaves too little
    c = good_cloud;
    c.points = buffer(4 * points.size(), nullptr, other);
    expect_error(c, good_out, "another context");
    c = good_cloud;
    c.row_step_bytes = 12 * w - 4;
    expect_error(c, good_out, "smaller than a row");
    c = good_cloud;
    c.row_step_bytes = 12 * w + 2;
    expect_error(c, good_out, "multiples of 4");
    c = good_cloud;
    c.points = nullptr;
    expect_error(c, good_out, "missing");
    opencl::LabelBuffers o = good_out;
    o.count = buffer(4, nullptr, other);
    expect_error(good_cloud, o, "another context");
    o = good_out;
    o.row_step_bytes = 4 * w + 4;  // rows that no longer fit the buffer
    expect_error(good_cloud, o, "needs");

    opencl::DepthBuffer d = good_depth;
    for (const double m : {0.0, -0.001, std::nan(""), double(INFINITY)}) {
        d = good_depth;
        d.view.metres_per_unit = m;
        expect_error(d, good_out, "metres_per_unit");
    }
    d = good_depth;
    d.view.fx = 0;
    expect_error(d, good_out, "fx");
    d = good_depth;
    d.view.fy = std::nan("");
    expect_error(d, good_out, "fy");
    d = good_depth;
    d.view.cx = INFINITY;
    expect_error(d, good_out, "cx");
    d = good_depth;
    d.view.depth = depth.data();
    expect_error(d, good_out, "must be null");
    d = good_depth;
    d.view.row_step_bytes = 2 * w + 1;
    expect_error(d, good_out, "multiples of 2");
    d = good_depth;
    d.view.width = w - 1;
    expect_error(d, good_out, "31 x 24");

    // A Segmenter on another API, and queues that do not fit.
    Segmenter cpu(w, h, {}, "cpu");
    EXPECT_THROW((void)opencl::segment(cpu, good_cloud, good_out), Error);
    cl_command_queue other_queue = clCreateCommandQueue(other, device_, 0, nullptr);
    EXPECT_THROW((void)opencl::make_segmenter(w, h, {context_, device_, other_queue}), Error);
    clReleaseCommandQueue(other_queue);
    cl_int err = CL_SUCCESS;
    cl_command_queue out_of_order =
        clCreateCommandQueue(context_, device_, CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE, &err);
    if (err == CL_SUCCESS) {
        try {
            (void)opencl::make_segmenter(w, h, {context_, device_, out_of_order});
            ADD_FAILURE() << "an out-of-order queue was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("out of order"), std::string::npos) << e.what();
        }
        clReleaseCommandQueue(out_of_order);
    }
    EXPECT_THROW((void)opencl::make_segmenter(w, h, {context_, device_, nullptr}), Error);
    clReleaseContext(other);

    // After every refusal the Segmenter still segments.
    cl_event e = opencl::segment(segmenter, good_cloud, good_out);
    ASSERT_EQ(clWaitForEvents(1, &e), CL_SUCCESS);
    clReleaseEvent(e);
    EXPECT_EQ(read<std::uint32_t>(good_out.count, 1)[0], 1u) << "a flat wall at 1 m: one segment";
}

}  // namespace
}  // namespace pyrseg::test
