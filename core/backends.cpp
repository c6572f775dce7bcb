#include <algorithm>
#include <cstdlib>
#include <string>
#include <thread>

#include "backends/cpu/cpu_backend.hpp"
#include "core/backends_config.hpp"
#if PYRSEG_HAVE_CUDA
#include "backends/cuda/cuda_backend.hpp"
#endif
#if PYRSEG_HAVE_OPENCL
#include "backends/opencl/opencl_backend.hpp"
#endif
#if PYRSEG_HAVE_VULKAN
#include "backends/vulkan/vulkan_backend.hpp"
#endif
#include "core/backend_registry.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg {

std::vector<BackendInfo> list_backends() {
    std::vector<BackendInfo> all;
    // Preference order for "auto": GPUs first, the CPU always last and always there.
#if PYRSEG_HAVE_CUDA
    {
        BackendInfo cuda{"cuda", false, "", {}};
        cuda.devices = cuda::describe_devices(&cuda.reason);
        cuda.available = !cuda.devices.empty();
        all.push_back(cuda);
    }
#else
    all.push_back({"cuda", false, kWhyCuda, {}});
#endif
#if PYRSEG_HAVE_VULKAN
    {
        BackendInfo vulkan{"vulkan", false, "", {}};
        vulkan.devices = vulkan::describe_devices(&vulkan.reason, &vulkan.available);
        all.push_back(vulkan);
    }
#else
    all.push_back({"vulkan", false, kWhyVulkan, {}});
#endif
#if PYRSEG_HAVE_OPENCL
    {
        BackendInfo opencl{"opencl", false, "", {}};
        opencl.devices = opencl::describe_devices(&opencl.reason);
        opencl.available = !opencl.devices.empty();
        all.push_back(opencl);
    }
#else
    all.push_back({"opencl", false, kWhyOpencl, {}});
#endif
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    all.push_back({"cpu", true, "", {"host CPU, " + std::to_string(threads) + " hardware threads"}});
    return all;
}

std::string resolve_backend_name(std::string_view requested) {
    std::string name(requested);
    std::string origin = "requested";
    if (name.empty()) {
        if (const char* env = std::getenv("PYRSEG_BACKEND"); env != nullptr && *env != '\0') {
            name = env;
            origin = "PYRSEG_BACKEND";
        } else {
            name = "auto";
        }
    }
    const std::vector<BackendInfo> all = list_backends();
    if (name == "auto") {
        for (const BackendInfo& b : all) {
            if (b.available) return b.name;
        }
        throw Error(ErrorCode::internal, "no backend is available, not even the CPU");
    }
    std::string known;
    for (const BackendInfo& b : all) {
        if (b.name == name) {
            if (!b.available) {
                std::string message = "backend '" + name;
                message += "' (" + origin + ") is unavailable: ";
                message += b.reason;
                throw Error(ErrorCode::backend_unavailable, message);
            }
            return b.name;
        }
        known += (known.empty() ? "" : ", ") + b.name;
    }
    throw Error(ErrorCode::backend_unavailable,
                "unknown backend '" + name + "' (" + origin + "); known backends: " + known + ", auto");
}

namespace core {

std::unique_ptr<PassExecutor> make_executor(std::string_view backend, const Plan& plan) {
    if (backend == "cpu") return cpu::make_executor(plan);
#if PYRSEG_HAVE_CUDA
    if (backend == "cuda") return cuda::make_executor(plan);
#endif
#if PYRSEG_HAVE_VULKAN
    if (backend == "vulkan") return vulkan::make_executor(plan);
#endif
#if PYRSEG_HAVE_OPENCL
    if (backend == "opencl") return opencl::make_executor(plan);
#endif
    throw Error(ErrorCode::backend_unavailable, "backend '" + std::string(backend) + "' is not built in");
}

}  // namespace core
}  // namespace pyrseg
