#pragma once
// OpenCL platforms and devices, the device choice, and the context + program per device that every Segmenter of
// the process shares (the program is compiled once per context).
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace pyrseg::opencl {

struct DeviceRef {
    cl_platform_id platform = nullptr;
    cl_device_id device = nullptr;
    unsigned platform_index = 0;
    unsigned device_index = 0;
    std::string description;  // "0:0 Portable Computing Language: pthread-... (OpenCL 3.0 PoCL ..., CPU)"
};

// Every device of every platform; when there is none, *why_none says why.
[[nodiscard]] std::vector<DeviceRef> enumerate_devices(std::string* why_none);

// $PYRSEG_OPENCL_DEVICE ("P:D" indices, or text found in the description), else the first GPU, else the first
// device. Throws pyrseg::Error(backend_unavailable) naming the reason.
[[nodiscard]] DeviceRef choose_device();

struct Runtime {
    cl_context context = nullptr;
    cl_program program = nullptr;
    cl_device_id device = nullptr;
    std::string description;
    cl_ulong max_alloc = 0;   // CL_DEVICE_MAX_MEM_ALLOC_SIZE
    cl_ulong global_mem = 0;  // CL_DEVICE_GLOBAL_MEM_SIZE
    // CL_OUT_OF_RESOURCES was seen on it: the Segmenters on it keep failing, the next ones get a new context.
    mutable std::atomic<bool> faulted{false};
    ~Runtime();
};

// The shared runtime of a device, created and compiled on first use. A failed build throws pyrseg::Error with the
// device's build log.
[[nodiscard]] std::shared_ptr<const Runtime> runtime_for(const DeviceRef& device);
// The runtime on a caller's context and device (pyrseg/opencl.hpp), shared by the Segmenters on it while any lives;
// the context is retained as long.
[[nodiscard]] std::shared_ptr<const Runtime> runtime_for(cl_context context, cl_device_id device);

[[nodiscard]] const char* error_name(cl_int code);
[[noreturn]] void fail(cl_int code, const char* what);
inline void check(cl_int code, const char* what) {
    if (code != CL_SUCCESS) fail(code, what);
}

}  // namespace pyrseg::opencl
