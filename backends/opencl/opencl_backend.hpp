#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/backend_registry.hpp"
#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::opencl {

// The OpenCL backend on the device chosen by $PYRSEG_OPENCL_DEVICE (else the first GPU, else the first device).
// Throws pyrseg::Error when there is no device, the kernels do not build, or the buffers do not fit.
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan);

// For `pyrseg backends`: the devices, or why there are none (then the vector is empty).
[[nodiscard]] std::vector<std::string> describe_devices(std::string* why_none);

// This backend in the registry (core/backend_registry.hpp).
extern const core::BackendEntry kBackend;

}  // namespace pyrseg::opencl
