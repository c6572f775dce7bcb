// pyrseg/cuda.hpp on streams and device memory this test creates itself, as an application would: device-resident
// frames give the host path's labels and segment count byte for byte (clouds with and without normals, both
// metrics, padded rows, depth images u16 and f32 with odd row steps and changing intrinsics), frames follow the
// stream's order (back to back, after an event of another stream), a frame captured into a CUDA graph replays with
// new input, and bad input is a pyrseg::Error that leaves the caller's memory and stream untouched.
#include <cuda_runtime_api.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/cuda.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

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

// A host function the stream runs: blocks it until the test opens the gate (at most 10 s, so that a test that went
// wrong does not hang).
struct Gate {
    std::atomic<bool> open{false};
    static void CUDART_CB wait(void* self) {
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (!static_cast<Gate*>(self)->open.load() && std::chrono::steady_clock::now() < until)
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
};

// The application's side: device 0, a non-blocking stream of its own, memory it allocates.
class CudaApp : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string why = why_no_cuda_device();
        if (!why.empty()) GTEST_SKIP() << why;
        ASSERT_EQ(cudaSetDevice(0), cudaSuccess);
        ASSERT_EQ(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), cudaSuccess);
    }

    void TearDown() override {
        if (stream_ != nullptr) {
            EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
        }
        for (void* p : device_memory_) cudaFree(p);
        for (void* p : pinned_memory_) cudaFreeHost(p);
        if (stream_ != nullptr) cudaStreamDestroy(stream_);
    }

    // `bytes` of device memory, with `data` copied in when given.
    template <class T = unsigned char>
    T* device(std::size_t bytes, const void* data = nullptr) {
        void* p = nullptr;
        EXPECT_EQ(cudaMalloc(&p, bytes), cudaSuccess);
        device_memory_.push_back(p);
        if (data != nullptr) upload(p, data, bytes);
        return static_cast<T*>(p);
    }

    // Pinned host memory, with `data` copied in when given.
    template <class T = unsigned char>
    T* pinned(std::size_t bytes, const void* data = nullptr) {
        void* p = nullptr;
        EXPECT_EQ(cudaMallocHost(&p, bytes), cudaSuccess);
        pinned_memory_.push_back(p);
        if (data != nullptr) std::memcpy(p, data, bytes);
        return static_cast<T*>(p);
    }

    // Host to device on the test's stream, waited for (the source may go at once).
    void upload(void* dst, const void* src, std::size_t bytes) {
        EXPECT_EQ(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyHostToDevice, stream_), cudaSuccess);
        EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
    }

    // `count` items from device memory, once the stream has done everything queued on it.
    template <class T>
    std::vector<T> read(const void* src, std::size_t count) {
        std::vector<T> out(count);
        EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
        EXPECT_EQ(cudaMemcpyAsync(out.data(), src, count * sizeof(T), cudaMemcpyDeviceToHost, stream_), cudaSuccess);
        EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
        return out;
    }

    cudaStream_t stream_ = nullptr;
    std::vector<void*> device_memory_;
    std::vector<void*> pinned_memory_;
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

CloudView view_of(const synthetic::Scene& scene, bool normals) {
    CloudView view;
    view.points = scene.points.data();
    view.normals = normals ? scene.normals.data() : nullptr;
    view.width = scene.width;
    view.height = scene.height;
    return view;
}

synthetic::Scene scene_of(int width, int height, std::uint64_t seed = 1,
                          synthetic::Sensor sensor = synthetic::Sensor::structured_light) {
    synthetic::SceneOptions o;
    o.width = width;
    o.height = height;
    o.seed = seed;
    o.sensor = sensor;
    return synthetic::generate(o);
}

// A synthetic scene's depth as whole millimetres (0: no data).
std::vector<std::uint16_t> millimetres(const synthetic::Scene& scene) {
    std::vector<std::uint16_t> mm(std::size_t(scene.width) * std::size_t(scene.height));
    for (std::size_t i = 0; i < mm.size(); ++i) {
        const float z = scene.points[3 * i + 2];
        mm[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
    }
    return mm;
}

struct Scene {
    const char* what = "";
    int width = 0, height = 0;
    synthetic::Sensor sensor = synthetic::Sensor::structured_light;
    bool normals = false;
    Params params;
    std::size_t cloud_pad = 0;   // extra bytes per row of points
    std::size_t labels_pad = 0;  // extra bytes per row of labels
};

TEST_F(CudaApp, CloudFramesMatchTheHostPath) {
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
        const synthetic::Scene scene = scene_of(s.width, s.height, 1, s.sensor);
        const CloudView view = view_of(scene, s.normals);
        Segmenter cpu(s.width, s.height, s.params, "cpu");
        const Result expected = cpu.segment(view);
        ASSERT_GT(expected.segment_count, 0u);

        const std::size_t cloud_pitch = 12 * std::size_t(s.width) + s.cloud_pad;
        const std::size_t labels_pitch = 4 * std::size_t(s.width) + s.labels_pad;
        const std::size_t labels_bytes = labels_pitch * std::size_t(s.height);
        const auto points = pitched(scene.points.data(), s.width, s.height, 12, cloud_pitch);
        const auto normals = pitched(scene.normals.data(), s.width, s.height, 12, cloud_pitch);
        Segmenter segmenter = cuda::make_segmenter(s.width, s.height, stream_, s.params);
        EXPECT_EQ(segmenter.backend_name(), "cuda");
        cuda::CloudPointers in;
        auto* block = device(points.size() + 12);
        upload(block + 12, points.data(), points.size());
        in.points = reinterpret_cast<const float*>(block + 12);  // data need not start at the allocation's start
        in.points_bytes = points.size();
        if (s.normals) {
            in.normals = device<float>(normals.size(), normals.data());
            in.normals_bytes = normals.size();
        }
        in.row_step_bytes = s.cloud_pad == 0 ? 0 : cloud_pitch;
        cuda::LabelPointers out;
        out.labels = device<std::uint32_t>(labels_bytes);
        out.labels_bytes = labels_bytes;
        out.row_step_bytes = s.labels_pad == 0 ? 0 : labels_pitch;
        auto* counts = device<std::uint32_t>(16);
        out.count = counts + 2;
        // Two frames queued back to back before anything is read: the second reuses pyrseg's buffers after the
        // first, in stream order.
        cuda::segment(segmenter, in, out);
        cuda::LabelPointers out2 = out;
        out2.labels = device<std::uint32_t>(labels_bytes);
        out2.count = nullptr;
        cuda::segment(segmenter, in, out2);
        ASSERT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
        EXPECT_TRUE(segmenter.last_timings().empty());

        for (const std::uint32_t* labels : {out.labels, out2.labels}) {
            const auto bytes = read<unsigned char>(labels, labels_bytes);
            EXPECT_TRUE(
                same_bytes("labels", unpitch(bytes, s.width, s.height, labels_pitch), expected.labels, s.width));
        }
        EXPECT_EQ(read<std::uint32_t>(out.count, 1)[0], expected.segment_count);
        // The same Segmenter's host path, on the application's stream, then a device frame again.
        const Result host = segmenter.segment(view);
        EXPECT_TRUE(same_bytes("host path labels", host.labels, expected.labels, s.width));
        EXPECT_EQ(host.segment_count, expected.segment_count);
        cuda::segment(segmenter, in, out2);
        const auto bytes = read<unsigned char>(out2.labels, labels_bytes);
        EXPECT_TRUE(same_bytes("labels after a host frame", unpitch(bytes, s.width, s.height, labels_pitch),
                               expected.labels, s.width));
    }
}

TEST_F(CudaApp, DepthFramesMatchTheHostPath) {
    const synthetic::Scene scene = scene_of(93, 61, 1, synthetic::Sensor::kinect_v1);
    const int w = scene.width;
    const int h = scene.height;
    const std::vector<std::uint16_t> u16 = millimetres(scene);
    std::vector<float> f32(u16.size());
    for (std::size_t i = 0; i < u16.size(); ++i) {
        const float z = scene.points[3 * i + 2];
        f32[i] = i % 53 == 1 ? -z : z * 0.001f;  // metres; NaN and negative samples are missing data
    }
    const Params params = sensor_preset(SensorKind::kinect_v1);
    Segmenter cpu(w, h, params, "cpu");
    Segmenter segmenter = cuda::make_segmenter(w, h, stream_, params);
    struct Case {
        const char* what;
        const void* samples;
        DepthFormat format;
        std::size_t sample;
        std::size_t pad;
        double metres_per_unit;
        double fx_scale;
        double cx_shift;
    };
    const Case cases[] = {
        {"u16 mm, packed", u16.data(), DepthFormat::u16, 2, 0, 0.001, 1.0, 0.3},
        {"u16 mm, rows of 2W+6 bytes", u16.data(), DepthFormat::u16, 2, 6, 0.001, 1.0, 0.3},
        {"f32 m, rows of 4W+12 bytes, other intrinsics", f32.data(), DepthFormat::f32, 4, 12, 1.0, 1.2, 0.3},
        {"u16 mm again, first intrinsics", u16.data(), DepthFormat::u16, 2, 2, 0.001, 1.0, 0.3},
        {"u16 mm, rows of 2W+2 bytes, another cx", u16.data(), DepthFormat::u16, 2, 2, 0.001, 1.0, -1.7},
    };
    // Every frame's memory first, then every frame queued before any is read: each new ray table goes with its own
    // frame, in stream order, while the frames before may still run.
    struct Frame {
        Result expected;
        cuda::DepthPointers in;
        cuda::LabelPointers out;
    };
    std::vector<Frame> frames;
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        const std::size_t pitch = c.sample * std::size_t(w) + c.pad;
        const auto bytes = pitched(c.samples, w, h, c.sample, pitch);
        const DepthView view{
            bytes.data(),          c.format,      w, h, pitch, c.metres_per_unit, scene.fx * c.fx_scale, scene.fy,
            scene.cx + c.cx_shift, scene.cy - 0.2};
        Frame f;
        f.expected = cpu.segment(view);
        ASSERT_GT(f.expected.segment_count, 1u);
        auto* block = device(bytes.size() + c.sample);
        upload(block + c.sample, bytes.data(), bytes.size());
        f.in.samples = block + c.sample;  // one sample into the allocation
        f.in.bytes = bytes.size();
        f.in.view = view;
        f.in.view.depth = nullptr;
        f.out.labels = device<std::uint32_t>(4 * std::size_t(w) * std::size_t(h));
        f.out.labels_bytes = 4 * std::size_t(w) * std::size_t(h);
        f.out.count = device<std::uint32_t>(4);
        frames.push_back(std::move(f));
    }
    for (const Frame& f : frames) cuda::segment(segmenter, f.in, f.out);
    ASSERT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
    for (std::size_t k = 0; k < frames.size(); ++k) {
        SCOPED_TRACE(cases[k].what);
        const Frame& f = frames[k];
        EXPECT_TRUE(
            same_bytes("labels", read<std::uint32_t>(f.out.labels, f.expected.labels.size()), f.expected.labels, w));
        EXPECT_EQ(read<std::uint32_t>(f.out.count, 1)[0], f.expected.segment_count);
    }
}

TEST_F(CudaApp, AFrameWaitsForAnEventOfAnotherStream) {
    // The points arrive through another stream, after a gate the test opens late: a frame that did not wait for
    // that copy's event would segment the zeros the memory held before, and a segment() that waited for its
    // stream would not return before the gate opens.
    const synthetic::Scene scene = scene_of(48, 40);
    const std::size_t bytes = 4 * scene.points.size();
    Segmenter segmenter = cuda::make_segmenter(scene.width, scene.height, stream_);
    const std::vector<float> zeros(scene.points.size(), 0.0f);
    cuda::CloudPointers in;
    in.points = device<float>(bytes, zeros.data());
    in.points_bytes = bytes;
    cuda::LabelPointers out;
    out.labels = device<std::uint32_t>(4 * std::size_t(scene.width) * std::size_t(scene.height));
    out.labels_bytes = 4 * std::size_t(scene.width) * std::size_t(scene.height);
    const float* source = pinned<float>(bytes, scene.points.data());  // pinned: the copy is queued, not staged

    cudaStream_t uploads = nullptr;
    ASSERT_EQ(cudaStreamCreateWithFlags(&uploads, cudaStreamNonBlocking), cudaSuccess);
    cudaEvent_t written = nullptr;
    ASSERT_EQ(cudaEventCreateWithFlags(&written, cudaEventDisableTiming), cudaSuccess);
    Gate gate;
    ASSERT_EQ(cudaLaunchHostFunc(uploads, &Gate::wait, &gate), cudaSuccess);
    ASSERT_EQ(cudaMemcpyAsync(const_cast<float*>(in.points), source, bytes, cudaMemcpyHostToDevice, uploads),
              cudaSuccess);
    ASSERT_EQ(cudaEventRecord(written, uploads), cudaSuccess);
    ASSERT_EQ(cudaStreamWaitEvent(stream_, written, 0), cudaSuccess);
    const auto start = std::chrono::steady_clock::now();
    cuda::segment(segmenter, in, out);
    const auto returned = std::chrono::steady_clock::now() - start;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(cudaStreamQuery(stream_), cudaErrorNotReady) << "the frame ran before the event it waits for";
    EXPECT_LT(returned, std::chrono::seconds(5)) << "cuda::segment waited for its stream";
    gate.open = true;
    ASSERT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
    ASSERT_EQ(cudaStreamSynchronize(uploads), cudaSuccess);
    cudaEventDestroy(written);
    cudaStreamDestroy(uploads);

    Segmenter cpu(scene.width, scene.height, {}, "cpu");
    const Result expected = cpu.segment(view_of(scene, false));
    ASSERT_GT(expected.segment_count, 1u);
    EXPECT_TRUE(
        same_bytes("labels", read<std::uint32_t>(out.labels, expected.labels.size()), expected.labels, scene.width));
}

TEST_F(CudaApp, ACapturedFrameReplaysWithNewInput) {
    // One frame captured into a CUDA graph, then launched three times, the input changed by a copy on the stream
    // before each launch: every launch gives that input's labels and K.
    const int w = 80;
    const int h = 60;
    const synthetic::Scene scenes[] = {scene_of(w, h, 1), scene_of(w, h, 2)};
    Segmenter cpu(w, h, {}, "cpu");
    const Result expected[] = {cpu.segment(view_of(scenes[0], false)), cpu.segment(view_of(scenes[1], false))};
    ASSERT_NE(expected[0].labels, expected[1].labels);
    const std::size_t bytes = 4 * scenes[0].points.size();
    const float* sources[] = {pinned<float>(bytes, scenes[0].points.data()),
                              pinned<float>(bytes, scenes[1].points.data())};
    const std::size_t labels_bytes = 4 * std::size_t(w) * std::size_t(h);
    const std::vector<std::uint32_t> sentinel(std::size_t(w) * std::size_t(h), 0xDEADBEEFu);

    Segmenter segmenter = cuda::make_segmenter(w, h, stream_);
    cuda::CloudPointers in;
    in.points = device<float>(bytes, scenes[1].points.data());
    in.points_bytes = bytes;
    cuda::LabelPointers out;
    out.labels = device<std::uint32_t>(labels_bytes, sentinel.data());
    out.labels_bytes = labels_bytes;
    out.count = device<std::uint32_t>(4, sentinel.data());

    ASSERT_EQ(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeGlobal), cudaSuccess);
    try {
        cuda::segment(segmenter, in, out);
    } catch (const Error& e) {
        cudaGraph_t abandoned = nullptr;
        cudaStreamEndCapture(stream_, &abandoned);
        if (abandoned != nullptr) cudaGraphDestroy(abandoned);
        FAIL() << "cuda::segment refused to be captured: " << e.what();
    }
    cudaGraph_t graph = nullptr;
    ASSERT_EQ(cudaStreamEndCapture(stream_, &graph), cudaSuccess) << "the frame invalidated the capture";
    std::size_t nodes = 0;
    ASSERT_EQ(cudaGraphGetNodes(graph, nullptr, &nodes), cudaSuccess);
    EXPECT_GT(nodes, 10u) << "the graph should hold the frame's copies and kernels";
    cudaGraphExec_t exec = nullptr;
    ASSERT_EQ(cudaGraphInstantiate(&exec, graph, 0), cudaSuccess);
    cudaGraphDestroy(graph);
    // A capture runs nothing.
    EXPECT_EQ(read<std::uint32_t>(out.labels, sentinel.size()), sentinel) << "the capture wrote the labels";

    for (const int k : {0, 1, 0}) {
        SCOPED_TRACE("launch on scene " + std::to_string(k + 1));
        ASSERT_EQ(cudaMemcpyAsync(const_cast<float*>(in.points), sources[k], bytes, cudaMemcpyHostToDevice, stream_),
                  cudaSuccess);
        ASSERT_EQ(cudaGraphLaunch(exec, stream_), cudaSuccess);
        ASSERT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
        EXPECT_TRUE(same_bytes("labels", read<std::uint32_t>(out.labels, sentinel.size()), expected[k].labels, w));
        EXPECT_EQ(read<std::uint32_t>(out.count, 1)[0], expected[k].segment_count);
    }
    cudaGraphExecDestroy(exec);
    // The Segmenter still takes frames outside the graph.
    upload(const_cast<float*>(in.points), scenes[1].points.data(), bytes);
    cuda::segment(segmenter, in, out);
    EXPECT_TRUE(
        same_bytes("labels after the graph", read<std::uint32_t>(out.labels, sentinel.size()), expected[1].labels, w));
}

TEST_F(CudaApp, ACapturedDepthFrameCarriesItsOwnRayTable) {
    // A device depth frame sends its ray table with its own commands: captured as the Segmenter's very first frame,
    // the graph replays with new samples, and still gives its calibration's labels after a frame with other
    // intrinsics ran on the same Segmenter in between.
    const synthetic::Scene scenes[] = {scene_of(72, 54, 3, synthetic::Sensor::kinect_v1),
                                       scene_of(72, 54, 4, synthetic::Sensor::kinect_v1)};
    const int w = scenes[0].width;
    const int h = scenes[0].height;
    const std::vector<std::uint16_t> mm[] = {millimetres(scenes[0]), millimetres(scenes[1])};
    const std::size_t bytes = 2 * mm[0].size();
    const Params params = sensor_preset(SensorKind::kinect_v1);
    DepthView view{nullptr, DepthFormat::u16, w, h, 0, 0.001, scenes[0].fx, scenes[0].fy, scenes[0].cx, scenes[0].cy};
    DepthView other = view;
    other.fx *= 1.3;
    other.cy += 2.5;
    Segmenter cpu(w, h, params, "cpu");
    Result expected[2];
    for (int k = 0; k < 2; ++k) {
        DepthView v = view;
        v.depth = mm[k].data();
        expected[k] = cpu.segment(v);
    }
    DepthView other_host = other;
    other_host.depth = mm[0].data();
    const Result expected_other = cpu.segment(other_host);
    const std::uint16_t* sources[] = {pinned<std::uint16_t>(bytes, mm[0].data()),
                                      pinned<std::uint16_t>(bytes, mm[1].data())};

    Segmenter segmenter = cuda::make_segmenter(w, h, stream_, params);
    cuda::DepthPointers in;
    in.samples = device(bytes, mm[0].data());
    in.bytes = bytes;
    in.view = view;
    cuda::LabelPointers out;
    out.labels = device<std::uint32_t>(4 * mm[0].size());
    out.labels_bytes = 4 * mm[0].size();
    out.count = device<std::uint32_t>(4);

    cudaGraph_t graph = nullptr;
    ASSERT_EQ(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeGlobal), cudaSuccess);
    try {
        cuda::segment(segmenter, in, out);  // the Segmenter's first frame: its ray table goes into the graph
    } catch (const Error& e) {
        ADD_FAILURE() << e.what();
    }
    ASSERT_EQ(cudaStreamEndCapture(stream_, &graph), cudaSuccess);
    cudaGraphExec_t exec = nullptr;
    ASSERT_EQ(cudaGraphInstantiate(&exec, graph, 0), cudaSuccess);
    cudaGraphDestroy(graph);
    for (const int k : {1, 0, 1}) {
        SCOPED_TRACE("launch on scene " + std::to_string(k + 1));
        if (k == 0) {
            // Another calibration's frame on the same Segmenter between two launches.
            cuda::DepthPointers in_other = in;
            in_other.view = other;
            ASSERT_EQ(
                cudaMemcpyAsync(const_cast<void*>(in.samples), sources[0], bytes, cudaMemcpyHostToDevice, stream_),
                cudaSuccess);
            cuda::segment(segmenter, in_other, out);
            EXPECT_TRUE(same_bytes("labels, other intrinsics", read<std::uint32_t>(out.labels, mm[0].size()),
                                   expected_other.labels, w));
        }
        ASSERT_EQ(cudaMemcpyAsync(const_cast<void*>(in.samples), sources[k], bytes, cudaMemcpyHostToDevice, stream_),
                  cudaSuccess);
        ASSERT_EQ(cudaGraphLaunch(exec, stream_), cudaSuccess);
        EXPECT_TRUE(same_bytes("labels", read<std::uint32_t>(out.labels, mm[0].size()), expected[k].labels, w));
        EXPECT_EQ(read<std::uint32_t>(out.count, 1)[0], expected[k].segment_count);
    }
    cudaGraphExecDestroy(exec);
}

TEST_F(CudaApp, TheLegacyDefaultStreamWorks) {
    const synthetic::Scene scene = scene_of(64, 48);
    const std::size_t bytes = 4 * scene.points.size();
    Segmenter segmenter = cuda::make_segmenter(scene.width, scene.height, nullptr);
    cuda::CloudPointers in;
    in.points = device<float>(bytes, scene.points.data());
    in.points_bytes = bytes;
    cuda::LabelPointers out;
    out.labels = device<std::uint32_t>(4 * std::size_t(scene.width) * std::size_t(scene.height));
    out.labels_bytes = 4 * std::size_t(scene.width) * std::size_t(scene.height);
    cuda::segment(segmenter, in, out);
    ASSERT_EQ(cudaStreamSynchronize(nullptr), cudaSuccess);
    Segmenter cpu(scene.width, scene.height, {}, "cpu");
    const Result expected = cpu.segment(view_of(scene, false));
    EXPECT_TRUE(
        same_bytes("labels", read<std::uint32_t>(out.labels, expected.labels.size()), expected.labels, scene.width));
    EXPECT_TRUE(
        same_bytes("host path labels", segmenter.segment(view_of(scene, false)).labels, expected.labels, scene.width));
}

TEST_F(CudaApp, BadInputIsAnErrorAndWritesNothing) {
    const int w = 32;
    const int h = 24;
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    std::vector<float> points(3 * pixels);
    for (std::size_t i = 0; i < pixels; ++i) {  // a wall 1 m away, 2 mm between pixels
        points[3 * i] = float(2 * int(i % std::size_t(w)) - w);
        points[3 * i + 1] = float(2 * int(i / std::size_t(w)) - h);
        points[3 * i + 2] = 1000.0f;
    }
    const std::size_t cloud_bytes = 4 * points.size();
    std::vector<std::uint16_t> depth(pixels, 1000);
    Segmenter segmenter = cuda::make_segmenter(w, h, stream_);
    const std::vector<std::uint32_t> sentinel(pixels, 0xDEADBEEFu);
    cuda::CloudPointers good_cloud;
    good_cloud.points = device<float>(cloud_bytes, points.data());
    good_cloud.points_bytes = cloud_bytes;
    cuda::DepthPointers good_depth;
    good_depth.samples = device(2 * depth.size(), depth.data());
    good_depth.bytes = 2 * depth.size();
    good_depth.view = DepthView{nullptr, DepthFormat::u16, w, h, 0, 0.001, 500, 500, 16, 12};
    cuda::LabelPointers good_out;
    good_out.labels = device<std::uint32_t>(4 * sentinel.size(), sentinel.data());
    good_out.labels_bytes = 4 * sentinel.size();
    good_out.count = device<std::uint32_t>(4, sentinel.data());
    const auto untouched = [&] {
        EXPECT_EQ(read<std::uint32_t>(good_out.labels, sentinel.size()), sentinel) << "the labels were written";
        EXPECT_EQ(read<std::uint32_t>(good_out.count, 1)[0], 0xDEADBEEFu) << "the count was written";
    };
    const auto expect_error = [&](const auto& frame, const cuda::LabelPointers& out, const std::string& words) {
        SCOPED_TRACE(words);
        try {
            cuda::segment(segmenter, frame, out);
            ADD_FAILURE() << "no error; expected one naming " << words;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
        untouched();
    };

    const auto* host_points = points.data();
    auto* pinned_points = pinned<float>(cloud_bytes, points.data());
    cuda::CloudPointers c = good_cloud;
    c.points = nullptr;
    expect_error(c, good_out, "missing");
    c = good_cloud;
    c.points = host_points;
    expect_error(c, good_out, "host memory");
    c = good_cloud;
    c.points = pinned_points;
    expect_error(c, good_out, "pinned host memory");
    c = good_cloud;
    c.points_bytes = cloud_bytes - 4;  // one float short
    expect_error(c, good_out, "needs");
    c = good_cloud;
    c.points = device<float>(cloud_bytes / 2);  // the caller's size is more than the allocation: the driver's wins
    expect_error(c, good_out, "needs");
    c = good_cloud;
    c.row_step_bytes = 12 * w - 4;
    expect_error(c, good_out, "smaller than a row");
    c = good_cloud;
    c.row_step_bytes = 12 * w + 2;
    expect_error(c, good_out, "multiples of 4");
    c = good_cloud;
    c.normals = host_points;
    c.normals_bytes = cloud_bytes;
    expect_error(c, good_out, "normals");
    cuda::LabelPointers o = good_out;
    o.count = const_cast<std::uint32_t*>(sentinel.data());
    expect_error(good_cloud, o, "host memory");
    o = good_out;
    o.labels = nullptr;
    expect_error(good_cloud, o, "missing");
    o = good_out;
    o.row_step_bytes = 4 * w + 4;  // rows that no longer fit the memory
    expect_error(good_cloud, o, "needs");
    o = good_out;
    o.row_step_bytes = 4 * w + 2;
    expect_error(good_cloud, o, "multiples of 4");
    o = good_out;
    o.labels_bytes = 4 * sentinel.size() - 4;
    expect_error(good_cloud, o, "needs");

    int devices = 0;
    ASSERT_EQ(cudaGetDeviceCount(&devices), cudaSuccess);
    if (devices > 1) {
        void* other = nullptr;
        ASSERT_EQ(cudaSetDevice(1), cudaSuccess);
        ASSERT_EQ(cudaMalloc(&other, cloud_bytes), cudaSuccess);
        ASSERT_EQ(cudaSetDevice(0), cudaSuccess);
        c = good_cloud;
        c.points = static_cast<const float*>(other);
        expect_error(c, good_out, "memory of CUDA device 1");
        cudaFree(other);
    }

    cuda::DepthPointers d = good_depth;
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
    d = good_depth;
    d.bytes = 2 * depth.size() - 2;
    expect_error(d, good_out, "needs");
    d = good_depth;
    d.samples = depth.data();
    expect_error(d, good_out, "host memory");

    // Segmenters not made on the application's stream.
    Segmenter cpu(w, h, {}, "cpu");
    try {
        cuda::segment(cpu, good_cloud, good_out);
        ADD_FAILURE() << "a CPU Segmenter took device pointers";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("does not run on CUDA"), std::string::npos) << e.what();
    }
    Segmenter own(w, h, {}, "cuda");
    try {
        cuda::segment(own, good_cloud, good_out);
        ADD_FAILURE() << "a Segmenter on pyrseg's own stream took device pointers";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("pyrseg's own"), std::string::npos) << e.what();
    }
    untouched();

    // What a capture cannot hold is refused before anything is captured, and the capture goes on.
    ASSERT_EQ(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeGlobal), cudaSuccess);
    try {
        (void)cuda::make_segmenter(w, h, stream_);
        ADD_FAILURE() << "a Segmenter was made on a stream being captured";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("being captured"), std::string::npos) << e.what();
    }
    CloudView host_view;
    host_view.points = points.data();
    host_view.width = w;
    host_view.height = h;
    try {
        (void)segmenter.segment(host_view);
        ADD_FAILURE() << "a host frame ran on a stream being captured";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("being captured"), std::string::npos) << e.what();
    }
    cudaGraph_t graph = nullptr;
    ASSERT_EQ(cudaStreamEndCapture(stream_, &graph), cudaSuccess) << "a refusal invalidated the capture";
    std::size_t nodes = 0;
    ASSERT_EQ(cudaGraphGetNodes(graph, nullptr, &nodes), cudaSuccess);
    EXPECT_EQ(nodes, 0u);
    cudaGraphDestroy(graph);
    untouched();

    // After every refusal the Segmenter still segments.
    cuda::segment(segmenter, good_cloud, good_out);
    EXPECT_EQ(read<std::uint32_t>(good_out.count, 1)[0], 1u) << "a flat wall at 1 m: one segment";
    cuda::segment(segmenter, good_depth, good_out);
    EXPECT_GE(read<std::uint32_t>(good_out.count, 1)[0], 1u);
}

}  // namespace
}  // namespace pyrseg::test
