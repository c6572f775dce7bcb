#include "backends/opencl/opencl_runtime.hpp"

#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "core/device_choice.hpp"
#include "core/gpu/api_error.hpp"
#include "core/gpu/device_fault.hpp"
#include "pyrseg/error.hpp"

extern const char kOpenclKernelSource[];  // shaders/pyr_opencl.cl with its includes, embedded at build time

namespace pyrseg::opencl {
namespace {

// A string property through one of the clGet*Info functions: query the size, then the text.
template <class Object, class Info>
std::string info_string(cl_int (*get)(Object, Info, size_t, void*, size_t*), Object object, Info what) {
    size_t size = 0;
    if (get(object, what, 0, nullptr, &size) != CL_SUCCESS || size == 0) return "?";
    std::string s(size, '\0');
    get(object, what, size, s.data(), nullptr);
    while (!s.empty() && s.back() == '\0') s.pop_back();
    return s;
}

std::string device_string(cl_device_id device, cl_device_info what) {
    return info_string(clGetDeviceInfo, device, what);
}

std::string platform_name(cl_platform_id platform) {
    return info_string(clGetPlatformInfo, platform, cl_platform_info{CL_PLATFORM_NAME});
}

const char* type_name(cl_device_id device) {
    cl_device_type type = 0;
    clGetDeviceInfo(device, CL_DEVICE_TYPE, sizeof(type), &type, nullptr);
    if ((type & CL_DEVICE_TYPE_GPU) != 0) return "GPU";
    if ((type & CL_DEVICE_TYPE_CPU) != 0) return "CPU";
    if ((type & CL_DEVICE_TYPE_ACCELERATOR) != 0) return "accelerator";
    return "other";
}

}  // namespace

const char* error_name(cl_int code) {
    switch (code) {
        case CL_DEVICE_NOT_FOUND:
            return "CL_DEVICE_NOT_FOUND";
        case CL_DEVICE_NOT_AVAILABLE:
            return "CL_DEVICE_NOT_AVAILABLE";
        case CL_COMPILER_NOT_AVAILABLE:
            return "CL_COMPILER_NOT_AVAILABLE";
        case CL_MEM_OBJECT_ALLOCATION_FAILURE:
            return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
        case CL_OUT_OF_RESOURCES:
            return "CL_OUT_OF_RESOURCES";
        case CL_OUT_OF_HOST_MEMORY:
            return "CL_OUT_OF_HOST_MEMORY";
        case CL_BUILD_PROGRAM_FAILURE:
            return "CL_BUILD_PROGRAM_FAILURE";
        case CL_INVALID_VALUE:
            return "CL_INVALID_VALUE";
        case CL_INVALID_DEVICE:
            return "CL_INVALID_DEVICE";
        case CL_INVALID_CONTEXT:
            return "CL_INVALID_CONTEXT";
        case CL_INVALID_COMMAND_QUEUE:
            return "CL_INVALID_COMMAND_QUEUE";
        case CL_INVALID_MEM_OBJECT:
            return "CL_INVALID_MEM_OBJECT";
        case CL_INVALID_PROGRAM:
            return "CL_INVALID_PROGRAM";
        case CL_INVALID_PROGRAM_EXECUTABLE:
            return "CL_INVALID_PROGRAM_EXECUTABLE";
        case CL_INVALID_KERNEL_NAME:
            return "CL_INVALID_KERNEL_NAME";
        case CL_INVALID_KERNEL:
            return "CL_INVALID_KERNEL";
        case CL_INVALID_ARG_INDEX:
            return "CL_INVALID_ARG_INDEX";
        case CL_INVALID_ARG_VALUE:
            return "CL_INVALID_ARG_VALUE";
        case CL_INVALID_ARG_SIZE:
            return "CL_INVALID_ARG_SIZE";
        case CL_INVALID_KERNEL_ARGS:
            return "CL_INVALID_KERNEL_ARGS";
        case CL_INVALID_WORK_DIMENSION:
            return "CL_INVALID_WORK_DIMENSION";
        case CL_INVALID_WORK_GROUP_SIZE:
            return "CL_INVALID_WORK_GROUP_SIZE";
        case CL_INVALID_GLOBAL_WORK_SIZE:
            return "CL_INVALID_GLOBAL_WORK_SIZE";
        case CL_INVALID_BUFFER_SIZE:
            return "CL_INVALID_BUFFER_SIZE";
        case -1001:
            return "CL_PLATFORM_NOT_FOUND_KHR (no OpenCL platform is installed)";
        default:
            return "an OpenCL error";
    }
}

// OpenCL's codes for the kinds of failure core/gpu/api_error.hpp gives their meaning. CL_OUT_OF_RESOURCES is what
// drivers report once a context has faulted (NVIDIA after a kernel error): a device that cannot go on.
void fail(cl_int code, const char* what) {
    std::optional<gpu::Fault> fault;
    if (code == CL_MEM_OBJECT_ALLOCATION_FAILURE || code == CL_OUT_OF_HOST_MEMORY) {
        fault = gpu::Fault::out_of_memory;
    } else if (code == CL_OUT_OF_RESOURCES) {
        fault = gpu::Fault::device_lost;
    }
    gpu::throw_api_failure(
        {"OpenCL", what, std::string(error_name(code)) + " (" + std::to_string(code) + ")", fault,
         "; the device failed: this Segmenter cannot run it any more (make a new one, or use another backend)"});
}

std::vector<DeviceRef> enumerate_devices(std::string* why_none) {
    std::vector<DeviceRef> all;
    cl_uint platform_count = 0;
    const cl_int err = clGetPlatformIDs(0, nullptr, &platform_count);
    if (err != CL_SUCCESS || platform_count == 0) {
        if (why_none != nullptr) {
            *why_none =
                "no OpenCL platform found (the ICD loader found no driver; on Debian, install an ICD such as "
                "pocl-opencl-icd, or your GPU vendor's)";
        }
        return all;
    }
    std::vector<cl_platform_id> platforms(platform_count);
    clGetPlatformIDs(platform_count, platforms.data(), nullptr);
    for (cl_uint p = 0; p < platform_count; ++p) {
        cl_uint device_count = 0;
        if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, 0, nullptr, &device_count) != CL_SUCCESS) continue;
        std::vector<cl_device_id> devices(device_count);
        clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, device_count, devices.data(), nullptr);
        for (cl_uint d = 0; d < device_count; ++d) {
            DeviceRef ref;
            ref.platform = platforms[p];
            ref.device = devices[d];
            ref.platform_index = p;
            ref.device_index = d;
            ref.description = std::to_string(p) + ":" + std::to_string(d) + " " + platform_name(platforms[p]) + ": " +
                              device_string(devices[d], CL_DEVICE_NAME) + " (" +
                              device_string(devices[d], CL_DEVICE_VERSION) + ", " + type_name(devices[d]) + ")";
            all.push_back(ref);
        }
    }
    if (all.empty() && why_none != nullptr) {
        *why_none = std::to_string(platform_count) + " OpenCL platform(s) found, but no device";
    }
    return all;
}

DeviceRef choose_device() {
    std::string why;
    const std::vector<DeviceRef> all = enumerate_devices(&why);
    if (all.empty()) throw Error(ErrorCode::backend_unavailable, "backend 'opencl' is unavailable: " + why);
    std::vector<std::string> ids;
    std::vector<std::string> descriptions;
    for (const DeviceRef& d : all) {
        ids.push_back(std::to_string(d.platform_index) + ":" + std::to_string(d.device_index));
        descriptions.push_back(d.description);
    }
    if (const auto chosen = core::device_from_environment("PYRSEG_OPENCL_DEVICE", "OpenCL", ids, descriptions)) {
        return all[*chosen];
    }
    for (const DeviceRef& d : all) {
        cl_device_type type = 0;
        clGetDeviceInfo(d.device, CL_DEVICE_TYPE, sizeof(type), &type, nullptr);
        if ((type & CL_DEVICE_TYPE_GPU) != 0) return d;
    }
    return all.front();
}

Runtime::~Runtime() {
    if (program != nullptr) clReleaseProgram(program);
    if (context != nullptr) clReleaseContext(context);
}

namespace {

// The program for `device` in rt.context; a failed build throws with the device's build log.
void build_program(Runtime& rt, const char* source = kOpenclKernelSource) {
    cl_int err = CL_SUCCESS;
    rt.program = clCreateProgramWithSource(rt.context, 1, &source, nullptr, &err);
    check(err, "clCreateProgramWithSource");
    // No fast-math options: the kernels' float operations must be IEEE (contraction is off in the source).
    err = clBuildProgram(rt.program, 1, &rt.device, "-cl-std=CL1.2", nullptr, nullptr);
    if (err != CL_SUCCESS) {
        size_t size = 0;
        clGetProgramBuildInfo(rt.program, rt.device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
        std::string log(size, '\0');
        clGetProgramBuildInfo(rt.program, rt.device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
        throw Error(ErrorCode::internal, "OpenCL: building the pyrseg kernels for " + rt.description + " failed (" +
                                             error_name(err) + "); build log:\n" + log);
    }
}

void read_limits(Runtime& rt) {
    clGetDeviceInfo(rt.device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof(rt.max_alloc), &rt.max_alloc, nullptr);
    clGetDeviceInfo(rt.device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof(rt.global_mem), &rt.global_mem, nullptr);
}

}  // namespace

std::shared_ptr<const Runtime> runtime_for(const DeviceRef& device) {
    static std::mutex mutex;
    static std::map<cl_device_id, std::shared_ptr<const Runtime>> cache;
    const std::lock_guard lock(mutex);
    // A test's program (core/gpu/device_fault.hpp) is built on a context of its own, never cached.
    const std::optional<std::string> test_source = gpu::test_kernel_source();
    if (auto it = cache.find(device.device); it != cache.end() && !test_source) {
        if (!it->second->faulted) return it->second;
        cache.erase(it);  // released with the last Segmenter on it
    }

    auto rt = std::make_shared<Runtime>();
    rt->device = device.device;
    rt->description = device.description;
    read_limits(*rt);
    const cl_context_properties properties[] = {CL_CONTEXT_PLATFORM,
                                                reinterpret_cast<cl_context_properties>(device.platform), 0};
    cl_int err = CL_SUCCESS;
    rt->context = clCreateContext(properties, 1, &device.device, nullptr, nullptr, &err);
    check(err, "clCreateContext");
    if (test_source) {
        build_program(*rt, test_source->c_str());
        return rt;
    }
    build_program(*rt);
    cache.emplace(device.device, rt);
    return rt;
}

std::shared_ptr<const Runtime> runtime_for(cl_context context, cl_device_id device) {
    // Shared while a Segmenter uses it, and released with the last one: the caller's context is retained only
    // that long.
    static std::mutex mutex;
    static std::map<std::pair<cl_context, cl_device_id>, std::weak_ptr<const Runtime>> cache;
    const std::lock_guard lock(mutex);
    const auto key = std::make_pair(context, device);
    if (auto it = cache.find(key); it != cache.end()) {
        if (auto rt = it->second.lock()) return rt;
    }
    auto rt = std::make_shared<Runtime>();
    check(clRetainContext(context), "clRetainContext");
    rt->context = context;
    rt->device = device;
    cl_platform_id platform = nullptr;
    clGetDeviceInfo(device, CL_DEVICE_PLATFORM, sizeof(void*), &platform, nullptr);  // the handle itself
    rt->description = "the caller's context: " + platform_name(platform) + ": " +
                      device_string(device, CL_DEVICE_NAME) + " (" + device_string(device, CL_DEVICE_VERSION) + ", " +
                      type_name(device) + ")";
    read_limits(*rt);
    build_program(*rt);
    cache[key] = rt;
    return rt;
}

}  // namespace pyrseg::opencl
