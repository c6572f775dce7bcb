// Device-resident frames (pyrseg/opencl.hpp, ...): the input already in the application's GPU buffer, the labels
// and K left in another, beside the host rows of bench_segment.cpp on the same scenes. Each frame is waited for
// (one wait per frame, the application's), so the time is a frame's latency with no host transfer:
//   pipeline_device/<api>/<size>/estimated_normals    a float cloud (12 bytes a pixel, on the device)
//   pipeline_depth_device/<api>/<size>/u16            a uint16 depth image (2 bytes a pixel, on the device)
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_scenes.hpp"
#include "pyrseg/error.hpp"

#ifdef PYRSEG_BENCH_OPENCL
#include "pyrseg/opencl.hpp"
#endif
#ifdef PYRSEG_BENCH_VULKAN
#include "pyrseg/vulkan.hpp"
#include "tests/support/vulkan_device.hpp"
#endif
#ifdef PYRSEG_BENCH_CUDA
#include <cuda_runtime_api.h>

#include "pyrseg/cuda.hpp"
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

#ifdef PYRSEG_BENCH_VULKAN
// The application's Vulkan objects (tests/support/vulkan_device.hpp: the first device with a compute queue, as the
// interop tests make it), device-local buffers, and a fence for the frames.
struct VulkanApp {
    test::VulkanDevice vk;
    VkFence fence = VK_NULL_HANDLE;
    std::vector<test::VulkanDevice::Buffer> buffers;

    VulkanApp() {
        if (!vk.why_unavailable().empty()) return;
        VkFenceCreateInfo fence_info{};
        fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
        vkCreateFence(vk.device(), &fence_info, nullptr, &fence);
    }
    ~VulkanApp() {
        for (const test::VulkanDevice::Buffer& b : buffers) vk.destroy(b);
        if (fence != VK_NULL_HANDLE) vkDestroyFence(vk.device(), fence, nullptr);
    }
    VulkanApp(const VulkanApp&) = delete;
    VulkanApp& operator=(const VulkanApp&) = delete;

    // A buffer with the transfer usages, in memory with `flags` (host-visible ones are filled from `data`).
    VkBuffer buffer(VkDeviceSize bytes, VkMemoryPropertyFlags flags, const void* data = nullptr) {
        const test::VulkanDevice::Buffer b = vk.make_buffer(bytes, flags);
        if (b.buffer == VK_NULL_HANDLE) return VK_NULL_HANDLE;
        if (data != nullptr && b.mapped != nullptr) std::memcpy(b.mapped, data, bytes);
        buffers.push_back(b);
        return b.buffer;
    }
};

VulkanApp& vulkan_app() {
    static VulkanApp app;
    return app;
}

void vulkan_frames(benchmark::State& state, int width, int height, bool depth) {
    VulkanApp& app = vulkan_app();
    if (app.fence == VK_NULL_HANDLE) {
        state.SkipWithError("no Vulkan device");
        return;
    }
    const synthetic::Scene& s = scene(width, height);
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    const std::vector<std::uint16_t> samples = depth ? depth_samples(s) : std::vector<std::uint16_t>();
    const VkDeviceSize input_bytes = depth ? 2 * pixels : 12 * pixels;
    // Host-visible input (written once); device-local labels, as an application keeps them for its next pass.
    constexpr VkMemoryPropertyFlags kHost = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const VkBuffer input =
        app.buffer(input_bytes, kHost, depth ? static_cast<const void*>(samples.data()) : s.points.data());
    const VkBuffer labels = app.buffer(4 * pixels, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    const VkBuffer count = app.buffer(4, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (input == VK_NULL_HANDLE || labels == VK_NULL_HANDLE || count == VK_NULL_HANDLE) {
        state.SkipWithError("could not allocate the buffers");
        return;
    }
    Segmenter segmenter = vulkan::make_segmenter(width, height, app.vk.handles());
    vulkan::LabelBuffers out;
    out.labels = labels;
    out.labels_bytes = 4 * pixels;
    out.count = count;
    out.count_bytes = 4;
    vulkan::CloudBuffers cloud;
    cloud.points = input;
    cloud.points_bytes = input_bytes;
    vulkan::DepthBuffer image;
    image.samples = input;
    image.bytes = input_bytes;
    image.view = DepthView{nullptr, DepthFormat::u16, width, height, 0, 0.001, s.fx, s.fy, s.cx, s.cy};
    time_device_frames(state, width, height, [&] {
        if (depth) {
            vulkan::submit(segmenter, image, out, {}, {}, {}, app.fence);
        } else {
            vulkan::submit(segmenter, cloud, out, {}, {}, {}, app.fence);
        }
        vkWaitForFences(app.vk.device(), 1, &app.fence, VK_TRUE, UINT64_MAX);
        vkResetFences(app.vk.device(), 1, &app.fence);
    });
    state.counters["dispatches"] = segmenter.last_dispatches();
}
#endif

#ifdef PYRSEG_BENCH_CUDA
// The application's stream and device memory; each frame is timed by the wall clock around segment() and a
// cudaStreamSynchronize (the application's one wait), and by CUDA events around the frame on the stream
// (device_ms: the frame on the GPU alone).
void cuda_frames(benchmark::State& state, int width, int height, bool depth) {
    int devices = 0;
    if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
        cudaGetLastError();
        state.SkipWithError("no CUDA device");
        return;
    }
    const synthetic::Scene& s = scene(width, height);
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    const std::vector<std::uint16_t> samples = depth ? depth_samples(s) : std::vector<std::uint16_t>();
    const std::size_t input_bytes = depth ? 2 * pixels : 12 * pixels;
    cudaStream_t stream = nullptr;
    void* input = nullptr;
    void* labels = nullptr;
    void* count = nullptr;
    cudaEvent_t start = nullptr;
    cudaEvent_t stop = nullptr;
    if (cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking) != cudaSuccess ||
        cudaMalloc(&input, input_bytes) != cudaSuccess || cudaMalloc(&labels, 4 * pixels) != cudaSuccess ||
        cudaMalloc(&count, 4) != cudaSuccess || cudaEventCreate(&start) != cudaSuccess ||
        cudaEventCreate(&stop) != cudaSuccess ||
        cudaMemcpy(input, depth ? static_cast<const void*>(samples.data()) : s.points.data(), input_bytes,
                   cudaMemcpyHostToDevice) != cudaSuccess) {
        state.SkipWithError("CUDA setup failed");
    } else {
        Segmenter segmenter = cuda::make_segmenter(width, height, stream);
        cuda::LabelPointers out;
        out.labels = static_cast<std::uint32_t*>(labels);
        out.labels_bytes = 4 * pixels;
        out.count = static_cast<std::uint32_t*>(count);
        cuda::CloudPointers cloud;
        cloud.points = static_cast<const float*>(input);
        cloud.points_bytes = input_bytes;
        cuda::DepthPointers image;
        image.samples = input;
        image.bytes = input_bytes;
        image.view = DepthView{nullptr, DepthFormat::u16, width, height, 0, 0.001, s.fx, s.fy, s.cx, s.cy};
        double device_ms = 0;
        time_device_frames(state, width, height, [&] {
            cudaEventRecord(start, stream);
            if (depth) {
                cuda::segment(segmenter, image, out);
            } else {
                cuda::segment(segmenter, cloud, out);
            }
            cudaEventRecord(stop, stream);
            cudaStreamSynchronize(stream);
            float ms = 0;
            cudaEventElapsedTime(&ms, start, stop);
            device_ms += double(ms);
        });
        state.counters["device_ms"] = benchmark::Counter(device_ms / double(state.iterations() + 1));
        state.counters["dispatches"] = segmenter.last_dispatches();
    }
    if (stop != nullptr) cudaEventDestroy(stop);
    if (start != nullptr) cudaEventDestroy(start);
    cudaFree(count);
    cudaFree(labels);
    cudaFree(input);
    if (stream != nullptr) cudaStreamDestroy(stream);
}
#endif

int register_all() {
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        const std::string px = size_name(w, h);
#ifdef PYRSEG_BENCH_OPENCL
        register_timed(("pipeline_device/opencl/" + px + "/estimated_normals").c_str(),
                       [=](benchmark::State& st) { opencl_frames(st, w, h, false); });
        register_timed(("pipeline_depth_device/opencl/" + px + "/u16").c_str(),
                       [=](benchmark::State& st) { opencl_frames(st, w, h, true); });
#endif
#ifdef PYRSEG_BENCH_VULKAN
        register_timed(("pipeline_device/vulkan/" + px + "/estimated_normals").c_str(),
                       [=](benchmark::State& st) { vulkan_frames(st, w, h, false); });
        register_timed(("pipeline_depth_device/vulkan/" + px + "/u16").c_str(),
                       [=](benchmark::State& st) { vulkan_frames(st, w, h, true); });
#endif
#ifdef PYRSEG_BENCH_CUDA
        register_timed(("pipeline_device/cuda/" + px + "/estimated_normals").c_str(),
                       [=](benchmark::State& st) { cuda_frames(st, w, h, false); });
        register_timed(("pipeline_depth_device/cuda/" + px + "/u16").c_str(),
                       [=](benchmark::State& st) { cuda_frames(st, w, h, true); });
#endif
    }
    return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace pyrseg::bench
