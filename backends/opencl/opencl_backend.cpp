// The OpenCL backend in the registry: pyrseg's own queue on the chosen device (opencl_device.cpp is the device,
// opencl_interop.cpp the caller's-context functions of pyrseg/opencl.hpp).
#include "backends/opencl/opencl_backend.hpp"

#include <string>
#include <vector>

#include "backends/opencl/opencl_device.hpp"
#include "backends/opencl/opencl_runtime.hpp"
#include "core/gpu/device.hpp"
#include "core/gpu/gpu_executor.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::opencl {

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    return gpu::make_gpu_executor(plan, std::make_unique<OpenclDevice>(runtime_for(choose_device())));
}

std::vector<std::string> describe_devices(std::string* why_none) {
    std::vector<std::string> out;
    for (const DeviceRef& d : enumerate_devices(why_none)) out.push_back(d.description);
    return out;
}

const core::BackendEntry kBackend = {[](std::string* why_none, bool* available) {
                                         std::vector<std::string> devices = describe_devices(why_none);
                                         *available = !devices.empty();
                                         return devices;
                                     },
                                     make_executor,
                                     [](std::string* device) {
                                         try {
                                             const DeviceRef d = choose_device();
                                             cl_device_type type = 0;
                                             clGetDeviceInfo(d.device, CL_DEVICE_TYPE, sizeof(type), &type, nullptr);
                                             if ((type & CL_DEVICE_TYPE_CPU) == 0) return false;
                                             *device = d.description;
                                             return true;
                                         } catch (const Error&) {
                                             return false;
                                         }
                                     }};

}  // namespace pyrseg::opencl
