// Device-resident frames (pyrseg/opencl.hpp, ...): the input already in the application's GPU buffer, the labels
// and K left in another, beside the host rows of bench_segment.cpp on the same scenes. Each frame is waited for
// (one wait per frame, the application's), so the time is a frame's latency with no host transfer:
//   pipeline_device/<api>/<size>/estimated_normals    a float cloud (12 bytes a pixel, on the device)
//   pipeline_depth_device/<api>/<size>/u16            a uint16 depth image (2 bytes a pixel, on the device)
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bench/bench_scenes.hpp"
#include "pyrseg/error.hpp"

#ifdef PYRSEG_BENCH_OPENCL
#include "pyrseg/opencl.hpp"
#endif

namespace pyrseg::bench {
namespace {

// What one device frame costs the loop: queue it, wait for it (the application's wait).
void time_device_frames(benchmark::State& state, int width, int height, const std::function<void()>& frame) {
    try {
        frame();  // warm: kernels built, ray slopes on the device
    } catch (const Error& e) {
        state.SkipWithError(e.what());
        return;
    }
    for (auto _ : state) frame();
    state.counters["host_transfer_bytes"] = 0;
    state.counters["Mpix/s"] =
        benchmark::Counter(double(width) * height * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

std::vector<std::uint16_t> depth_samples(const synthetic::Scene& s) {
    std::vector<std::uint16_t> out(std::size_t(s.width) * std::size_t(s.height));
    for (std::size_t i = 0; i < out.size(); ++i) {
        const float z = s.points[3 * i + 2];
        out[i] = std::isfinite(z) && z > 0 && z < 65535 ? std::uint16_t(std::lround(z)) : 0;
    }
    return out;
}

#ifdef PYRSEG_BENCH_OPENCL
// The application's OpenCL objects: $PYRSEG_OPENCL_DEVICE is pyrseg's own choice, so take the first GPU, else the
// first device, as a simple application would.
struct OpenclApp {
    cl_device_id device = nullptr;
    cl_context context = nullptr;
    cl_command_queue queue = nullptr;
    OpenclApp() {
        cl_uint count = 0;
        if (clGetPlatformIDs(0, nullptr, &count) != CL_SUCCESS || count == 0) return;
        std::vector<cl_platform_id> platforms(count);
        clGetPlatformIDs(count, platforms.data(), nullptr);
        for (cl_platform_id p : platforms) {
            if (clGetDeviceIDs(p, CL_DEVICE_TYPE_GPU, 1, &device, nullptr) == CL_SUCCESS) break;
        }
        for (cl_platform_id p : platforms) {
            if (device == nullptr && clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, &device, nullptr) != CL_SUCCESS)
                device = nullptr;
        }
        if (device == nullptr) return;
        context = clCreateContext(nullptr, 1, &device, nullptr, nullptr, nullptr);
        if (context != nullptr) queue = clCreateCommandQueue(context, device, 0, nullptr);
    }
    ~OpenclApp() {
        if (queue != nullptr) clReleaseCommandQueue(queue);
        if (context != nullptr) clReleaseContext(context);
    }
    OpenclApp(const OpenclApp&) = delete;
    OpenclApp& operator=(const OpenclApp&) = delete;
    cl_mem buffer(std::size_t bytes, const void* data) const {
        cl_mem m = clCreateBuffer(context, CL_MEM_READ_WRITE, bytes, nullptr, nullptr);
        if (m != nullptr && data != nullptr)
            clEnqueueWriteBuffer(queue, m, CL_TRUE, 0, bytes, data, 0, nullptr, nullptr);
        return m;
    }
};

OpenclApp& opencl_app() {
    static OpenclApp app;
    return app;
}

void opencl_frames(benchmark::State& state, int width, int height, bool depth) {
    OpenclApp& app = opencl_app();
    if (app.queue == nullptr) {
        state.SkipWithError("no OpenCL device");
        return;
    }
    const synthetic::Scene& s = scene(width, height);
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    const std::vector<std::uint16_t> samples = depth ? depth_samples(s) : std::vector<std::uint16_t>();
    cl_mem input = depth ? app.buffer(2 * pixels, samples.data()) : app.buffer(12 * pixels, s.points.data());
    cl_mem labels = app.buffer(4 * pixels, nullptr);
    cl_mem count = app.buffer(4, nullptr);
    {
        Segmenter segmenter = opencl::make_segmenter(width, height, {app.context, app.device, app.queue});
        opencl::LabelBuffers out{labels, 0, 0, count, 0};
        opencl::CloudBuffers cloud{input, 0, nullptr, 0, 0};
        opencl::DepthBuffer image{
            input, 0, DepthView{nullptr, DepthFormat::u16, width, height, 0, 0.001, s.fx, s.fy, s.cx, s.cy}};
        time_device_frames(state, width, height, [&] {
            cl_event done = depth ? opencl::segment(segmenter, image, out) : opencl::segment(segmenter, cloud, out);
            clWaitForEvents(1, &done);
            clReleaseEvent(done);
        });
        state.counters["dispatches"] = segmenter.last_dispatches();
    }
    clReleaseMemObject(count);
    clReleaseMemObject(labels);
    clReleaseMemObject(input);
}
#endif

int register_all() {
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        const std::string px = size_name(w, h);
#ifdef PYRSEG_BENCH_OPENCL
        benchmark::RegisterBenchmark(("pipeline_device/opencl/" + px + "/estimated_normals").c_str(),
                                     [=](benchmark::State& st) { opencl_frames(st, w, h, false); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
        benchmark::RegisterBenchmark(("pipeline_depth_device/opencl/" + px + "/u16").c_str(),
                                     [=](benchmark::State& st) { opencl_frames(st, w, h, true); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
#endif
    }
    return 0;
}

const int registered = register_all();

}  // namespace
}  // namespace pyrseg::bench
