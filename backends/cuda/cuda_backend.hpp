#pragma once
// Plain C++: core/ includes this without the CUDA headers.
#include <memory>
#include <string>
#include <vector>

#include "core/backend_registry.hpp"
#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::cuda {

// The CUDA backend on device $PYRSEG_CUDA_DEVICE (an index, or text of the name; default device 0). Throws
// pyrseg::Error when there is no CUDA device, the buffers do not fit, or a CUDA call fails (with CUDA's message).
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan);

// For `pyrseg backends`: the devices, or why there are none (then the vector is empty).
[[nodiscard]] std::vector<std::string> describe_devices(std::string* why_none);

// This backend in the registry (core/backend_registry.hpp).
extern const core::BackendEntry kBackend;

}  // namespace pyrseg::cuda
