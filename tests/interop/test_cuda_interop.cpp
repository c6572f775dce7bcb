// What only CUDA's interop has, on the adapter's stream and memory (cuda_adapter.hpp; the checks every API shares
// are device_frames.cpp): frames follow the stream's order after an event of another stream, a frame captured into a
// CUDA graph replays with new input (and, with tracks, as the stream's next frame each time), the legacy default stream
// works, and host memory, memory the caller claims more of than it has, Segmenters on pyrseg's own stream and what a
// capture cannot hold are refused, leaving the caller's memory and stream untouched.
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

#include "interop/cuda_adapter.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

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

// The adapter's stream and memory, in the shapes these tests take them.
class CudaInterop : public ApiTest<CudaAdapter> {
protected:
    void SetUp() override {
        ApiTest::SetUp();
        if (!IsSkipped()) stream_ = api().stream();
    }

    // `bytes` of device memory, with `data` copied in when given.
    template <class T = unsigned char>
    T* device(std::size_t bytes, const void* data = nullptr) {
        const int buffer = api().allocate(bytes);
        if (data != nullptr) api().upload(buffer, 0, data, bytes);
        return reinterpret_cast<T*>(api().pointer(buffer));
    }

    // Pinned host memory holding `data`.
    template <class T = unsigned char>
    T* pinned(std::size_t bytes, const void* data) {
        return static_cast<T*>(api().pinned(bytes, data));
    }

    // Host to device on the test's stream, waited for (the source may go at once).
    void upload(void* dst, const void* src, std::size_t bytes) {
        EXPECT_EQ(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyHostToDevice, stream_), cudaSuccess);
        EXPECT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
    }

    template <class T>
    std::vector<T> read(const void* src, std::size_t count) {
        return api().read<T>(src, count);
    }

    // What `segment` queues (a call of cuda::segment), captured on the test's stream into a graph; nullptr, the
    // failure said, when pyrseg refused to be captured or the frame invalidated the capture.
    template <class Segment>
    cudaGraph_t capture(const Segment& segment) {
        if (cudaStreamBeginCapture(stream_, cudaStreamCaptureModeGlobal) != cudaSuccess) {
            ADD_FAILURE() << "cudaStreamBeginCapture failed";
            return nullptr;
        }
        bool refused = false;
        try {
            segment();
        } catch (const Error& e) {
            refused = true;
            ADD_FAILURE() << "cuda::segment refused to be captured: " << e.what();
        }
        cudaGraph_t graph = nullptr;
        const cudaError_t ended = cudaStreamEndCapture(stream_, &graph);
        if (ended != cudaSuccess) ADD_FAILURE() << "the frame invalidated the capture: " << cudaGetErrorString(ended);
        if (refused || ended != cudaSuccess) {
            if (graph != nullptr) cudaGraphDestroy(graph);
            return nullptr;
        }
        return graph;
    }

    cudaStream_t stream_ = nullptr;
};

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

TEST_F(CudaInterop, AFrameWaitsForAnEventOfAnotherStream) {
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

TEST_F(CudaInterop, ACapturedFrameReplaysWithNewInput) {
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

    cudaGraph_t graph = capture([&] { cuda::segment(segmenter, in, out); });
    ASSERT_NE(graph, nullptr);
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

TEST_F(CudaInterop, ACapturedFrameWithTracksRunsAsTheStreamsNextFrameEachTime) {
    // A frame with tracks captured into a CUDA graph after the stream's first frame, then launched three times with
    // new points: each launch is the stream's next frame (K' and the frame's number live on the device), and
    // decode_device_tracks gives the tracks the CPU's host stream of the same frames gets.
    const PanningStream stream = panning_stream({0, 3, 7, 8});
    const std::vector<Window>& windows = stream.windows;
    Segmenter cpu(PanningStream::kWidth, PanningStream::kHeight, stream.params, "cpu", stream.outputs);
    Segmenter segmenter =
        cuda::make_segmenter(PanningStream::kWidth, PanningStream::kHeight, stream_, stream.params, stream.outputs);
    EXPECT_EQ(segmenter.segment(stream.cloud(0)).tracks, cpu.segment(stream.cloud(0)).tracks);

    const std::size_t bytes = 4 * windows[0].points.size();
    cuda::CloudPointers in;
    in.points = device<float>(bytes);
    in.points_bytes = bytes;
    cuda::LabelPointers out;
    out.labels_bytes = 4 * windows[0].depth.size();
    out.labels = device<std::uint32_t>(out.labels_bytes);
    out.count = device<std::uint32_t>(4);
    out.statistics_bytes = segmenter.device_statistics_bytes();
    out.statistics = device<std::uint32_t>(out.statistics_bytes);
    out.tracks_bytes = segmenter.device_tracks_bytes();
    out.tracks = device<std::uint32_t>(out.tracks_bytes);
    cudaGraph_t graph = capture([&] { cuda::segment(segmenter, in, out); });
    ASSERT_NE(graph, nullptr);
    cudaGraphExec_t exec = nullptr;
    ASSERT_EQ(cudaGraphInstantiate(&exec, graph, 0), cudaSuccess);
    cudaGraphDestroy(graph);
    std::size_t matched = 0;
    for (std::size_t f = 1; f < windows.size(); ++f) {
        SCOPED_TRACE("launch " + std::to_string(f));
        const Result expected = cpu.segment(stream.cloud(f));
        upload(const_cast<float*>(in.points), windows[f].points.data(), bytes);
        ASSERT_EQ(cudaGraphLaunch(exec, stream_), cudaSuccess);
        ASSERT_EQ(cudaStreamSynchronize(stream_), cudaSuccess);
        const std::uint32_t count = read<std::uint32_t>(out.count, 1)[0];
        ASSERT_EQ(count, expected.segment_count);
        std::vector<SegmentStats> segments;
        const std::vector<std::uint32_t> stats = read<std::uint32_t>(out.statistics, out.statistics_bytes / 4);
        segmenter.decode_device_statistics(stats.data(), count, segments);
        const std::vector<std::uint32_t> track_words = read<std::uint32_t>(out.tracks, out.tracks_bytes / 4);
        std::vector<SegmentTrack> tracks;
        segmenter.decode_device_tracks(track_words.data(), segments, tracks);
        EXPECT_EQ(tracks, expected.tracks);
        for (const SegmentTrack& t : tracks) matched += t.how != TrackMatch::new_track ? 1 : 0;
    }
    cudaGraphExecDestroy(exec);
    EXPECT_GT(matched, 5u) << "a stream whose tracks carry over";
}

TEST_F(CudaInterop, ACapturedDepthFrameCarriesItsOwnRayTable) {
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

    // The Segmenter's first frame: its ray table goes into the graph.
    cudaGraph_t graph = capture([&] { cuda::segment(segmenter, in, out); });
    ASSERT_NE(graph, nullptr);
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

TEST_F(CudaInterop, TheLegacyDefaultStreamWorks) {
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

// CUDA takes pointers: they must be device memory of the Segmenter's device, and the driver's size of the
// allocation wins over a larger one the caller claims.
TEST_F(CudaInterop, PointersThatAreNotTheDevicesMemoryAreRefused) {
    Refusals r(api());
    const cuda::CloudPointers good_cloud = api().cloud(r.cloud);
    const cuda::DepthPointers good_depth = api().depth(r.depth);
    const cuda::LabelPointers good_out = api().labels(r.out);
    const auto refused = [&](const auto& frame, const cuda::LabelPointers& out, const std::string& words) {
        expect_error([&] { cuda::segment(r.segmenter, frame, out); }, words);
        r.expect_untouched();
    };
    const std::size_t cloud_bytes = 4 * r.wall.points.size();
    const float* host_points = r.wall.points.data();
    auto* pinned_points = pinned<float>(cloud_bytes, host_points);
    cuda::CloudPointers c = good_cloud;
    c.points = host_points;
    refused(c, good_out, "host memory");
    c = good_cloud;
    c.points = pinned_points;
    refused(c, good_out, "pinned host memory");
    c = good_cloud;
    c.points = device<float>(cloud_bytes / 2);  // the caller's size is more than the allocation: the driver's wins
    refused(c, good_out, "needs");
    c = good_cloud;
    c.normals = host_points;
    c.normals_bytes = cloud_bytes;
    refused(c, good_out, "normals");
    cuda::LabelPointers o = good_out;
    o.count = const_cast<std::uint32_t*>(r.wall.sentinel.data());
    refused(good_cloud, o, "host memory");
    o = good_out;
    o.labels_bytes -= 4;
    refused(good_cloud, o, "needs");
    cuda::DepthPointers d = good_depth;
    d.bytes -= 2;
    refused(d, good_out, "needs");
    d = good_depth;
    d.samples = r.wall.depth.data();
    refused(d, good_out, "host memory");

    int devices = 0;
    ASSERT_EQ(cudaGetDeviceCount(&devices), cudaSuccess);
    if (devices > 1) {
        void* other = nullptr;
        ASSERT_EQ(cudaSetDevice(1), cudaSuccess);
        ASSERT_EQ(cudaMalloc(&other, cloud_bytes), cudaSuccess);
        ASSERT_EQ(cudaSetDevice(0), cudaSuccess);
        c = good_cloud;
        c.points = static_cast<const float*>(other);
        refused(c, good_out, "memory of CUDA device 1");
        cudaFree(other);
    }
    r.expect_still_segments();
}

TEST_F(CudaInterop, SegmentersNotOnTheCallersStreamAndCapturesAreRefused) {
    Refusals r(api());
    constexpr int w = Wall::kWidth;
    constexpr int h = Wall::kHeight;
    const cuda::CloudPointers good_cloud = api().cloud(r.cloud);
    const cuda::LabelPointers good_out = api().labels(r.out);
    Segmenter own(w, h, {}, "cuda");
    expect_error([&] { cuda::segment(own, good_cloud, good_out); }, "pyrseg's own");
    r.expect_untouched();

    // What a capture cannot hold is refused before anything is captured, and the capture goes on.
    ASSERT_EQ(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeGlobal), cudaSuccess);
    expect_error([&] { (void)cuda::make_segmenter(w, h, stream_); }, "being captured");
    CloudView host_view;
    host_view.points = r.wall.points.data();
    host_view.width = w;
    host_view.height = h;
    expect_error([&] { (void)r.segmenter.segment(host_view); }, "being captured");
    cudaGraph_t graph = nullptr;
    ASSERT_EQ(cudaStreamEndCapture(stream_, &graph), cudaSuccess) << "a refusal invalidated the capture";
    std::size_t nodes = 0;
    ASSERT_EQ(cudaGraphGetNodes(graph, nullptr, &nodes), cudaSuccess);
    EXPECT_EQ(nodes, 0u);
    cudaGraphDestroy(graph);
    r.expect_untouched();
    r.expect_still_segments();
}

}  // namespace
}  // namespace pyrseg::test
