// A CUDA application's depth loop with pyrseg/cuda.hpp: each depth frame is already in the application's device
// memory (here copied there from the synthetic Kinect v1 model, as a camera driver or a CUDA filter would leave it),
// pyrseg segments it on the application's own stream into the application's label memory, and nothing waits until
// the application itself reads the labels back. Then one frame is captured into a CUDA graph, and the graph is
// launched on new frames. Every frame is checked against the host path (a CPU Segmenter). Exits 77 where there is no
// CUDA device.
#include <cuda_runtime_api.h>
#include <pyrseg/cuda.hpp>
#include <pyrseg/pyrseg.hpp>
#include <pyrseg/synthetic.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr std::size_t kPixels = std::size_t(kWidth) * std::size_t(kHeight);

// Stops the example with CUDA's words when a CUDA call fails.
void check(cudaError_t err, const char* what) {
    if (err != cudaSuccess) {
        std::fprintf(stderr, "%s failed: %s (%s)\n", what, cudaGetErrorName(err), cudaGetErrorString(err));
        std::exit(1);
    }
}

// Stands in for the camera: frame `frame`'s whole millimetres (0: no data) into `mm`, and its intrinsics.
pyrseg::DepthView camera_frame(std::uint64_t frame, std::uint16_t* mm) {
    pyrseg::synthetic::SceneOptions camera;
    camera.sensor = pyrseg::synthetic::Sensor::kinect_v1;
    camera.width = kWidth;
    camera.height = kHeight;
    camera.seed = frame;
    const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(camera);
    for (std::size_t i = 0; i < kPixels; ++i) {
        const float z = scene.points[3 * i + 2];
        mm[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
    }
    pyrseg::DepthView view;
    view.depth = mm;
    view.format = pyrseg::DepthFormat::u16;
    view.width = kWidth;
    view.height = kHeight;
    view.metres_per_unit = 0.001;
    view.fx = scene.fx;
    view.fy = scene.fy;
    view.cx = scene.cx;
    view.cy = scene.cy;
    return view;
}

// The labels and K the device frame left (already copied back), against the host path's on the same samples.
bool matches(pyrseg::Segmenter& host, const pyrseg::DepthView& view, const std::uint32_t* labels, std::uint32_t count) {
    const pyrseg::Result expected = host.segment(view);
    return expected.segment_count == count && std::memcmp(expected.labels.data(), labels, 4 * kPixels) == 0;
}

int run() {
    const pyrseg::Params params = pyrseg::sensor_preset(pyrseg::SensorKind::kinect_v1);
    cudaStream_t stream = nullptr;
    check(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking), "cudaStreamCreateWithFlags");
    // The application's memory: the depth frame and the labels on the device, pinned host memory for its own copies.
    void* depth = nullptr;
    void* labels = nullptr;
    void* count = nullptr;
    void* host_depth = nullptr;
    void* host_labels = nullptr;
    void* host_count = nullptr;
    check(cudaMalloc(&depth, 2 * kPixels), "cudaMalloc(depth)");
    check(cudaMalloc(&labels, 4 * kPixels), "cudaMalloc(labels)");
    check(cudaMalloc(&count, 4), "cudaMalloc(count)");
    check(cudaMallocHost(&host_depth, 2 * kPixels), "cudaMallocHost(depth)");
    check(cudaMallocHost(&host_labels, 4 * kPixels), "cudaMallocHost(labels)");
    check(cudaMallocHost(&host_count, 4), "cudaMallocHost(count)");
    auto* mm = static_cast<std::uint16_t*>(host_depth);
    const auto* label_words = static_cast<const std::uint32_t*>(host_labels);
    const auto* k = static_cast<const std::uint32_t*>(host_count);

    int failures = 0;
    {
        // Made once: its buffers are on the stream's device, and all its work goes on the stream.
        pyrseg::Segmenter segmenter = pyrseg::cuda::make_segmenter(kWidth, kHeight, stream, params);
        pyrseg::Segmenter host(kWidth, kHeight, params, "cpu");  // the check
        pyrseg::cuda::DepthPointers in;
        in.samples = depth;
        in.bytes = 2 * kPixels;
        pyrseg::cuda::LabelPointers out;
        out.labels = static_cast<std::uint32_t*>(labels);
        out.labels_bytes = 4 * kPixels;
        out.count = static_cast<std::uint32_t*>(count);
        const auto read_back = [&] {
            check(cudaMemcpyAsync(host_labels, labels, 4 * kPixels, cudaMemcpyDeviceToHost, stream), "cudaMemcpyAsync");
            check(cudaMemcpyAsync(host_count, count, 4, cudaMemcpyDeviceToHost, stream), "cudaMemcpyAsync");
            check(cudaStreamSynchronize(stream), "cudaStreamSynchronize");  // the application's only wait
        };

        pyrseg::DepthView view;
        for (std::uint64_t frame = 1; frame <= 3; ++frame) {
            view = camera_frame(frame, mm);
            check(cudaMemcpyAsync(depth, host_depth, 2 * kPixels, cudaMemcpyHostToDevice, stream), "cudaMemcpyAsync");
            in.view = view;
            in.view.depth = nullptr;                    // the samples are on the device
            pyrseg::cuda::segment(segmenter, in, out);  // queued after the copy; returns at once
            read_back();
            const bool same = matches(host, view, label_words, *k);
            failures += same ? 0 : 1;
            std::printf("frame %llu: %u segments (%s)\n", static_cast<unsigned long long>(frame), *k,
                        same ? "matches the host path" : "DIFFERS from the host path");
        }

        // The same frame as a CUDA graph: captured once (the intrinsics are those of the frames before, so the ray
        // table is already on the device), then launched on each new frame after the copy that brings it.
        check(cudaStreamBeginCapture(stream, cudaStreamCaptureModeGlobal), "cudaStreamBeginCapture");
        pyrseg::cuda::segment(segmenter, in, out);
        cudaGraph_t graph = nullptr;
        check(cudaStreamEndCapture(stream, &graph), "cudaStreamEndCapture");
        cudaGraphExec_t exec = nullptr;
        check(cudaGraphInstantiate(&exec, graph, 0), "cudaGraphInstantiate");
        for (std::uint64_t frame = 4; frame <= 5; ++frame) {
            view = camera_frame(frame, mm);
            check(cudaMemcpyAsync(depth, host_depth, 2 * kPixels, cudaMemcpyHostToDevice, stream), "cudaMemcpyAsync");
            check(cudaGraphLaunch(exec, stream), "cudaGraphLaunch");
            read_back();
            const bool same = matches(host, view, label_words, *k);
            failures += same ? 0 : 1;
            std::printf("frame %llu: %u segments, from the CUDA graph (%s)\n", static_cast<unsigned long long>(frame),
                        *k, same ? "matches the host path" : "DIFFERS from the host path");
        }
        cudaGraphExecDestroy(exec);
        cudaGraphDestroy(graph);
    }  // the Segmenter goes (it waits for its stream) before the stream and the memory its frames used
    cudaFreeHost(host_count);
    cudaFreeHost(host_labels);
    cudaFreeHost(host_depth);
    cudaFree(count);
    cudaFree(labels);
    cudaFree(depth);
    cudaStreamDestroy(stream);
    return failures == 0 ? 0 : 1;
}

}  // namespace

int main() {
    int devices = 0;
    const cudaError_t err = cudaGetDeviceCount(&devices);
    if (err != cudaSuccess || devices == 0) {
        // pyrseg's words for why (`pyrseg backends`): they tell a missing driver from an old one.
        std::string why = err != cudaSuccess ? cudaGetErrorString(err) : "0 devices";
        for (const pyrseg::BackendInfo& b : pyrseg::list_backends()) {
            if (b.name == "cuda" && !b.reason.empty()) why = b.reason;
        }
        std::printf("skipped: %s\n", why.c_str());
        return 77;
    }
    try {
        return run();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
