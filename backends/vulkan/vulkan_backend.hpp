#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/backend_registry.hpp"
#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::vulkan {

// The Vulkan backend on the device chosen by $PYRSEG_VULKAN_DEVICE (else the most capable one). Throws
// pyrseg::Error when there is no usable device or the image does not fit the device's limits.
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan);

// For `pyrseg backends`: the devices (unusable ones say why), and *why_none when none is usable (then the
// vector may still list the unusable ones).
[[nodiscard]] std::vector<std::string> describe_devices(std::string* why_none, bool* any_usable);

// This backend in the registry (core/backend_registry.hpp).
extern const core::BackendEntry kBackend;

}  // namespace pyrseg::vulkan
