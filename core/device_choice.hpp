#pragma once
// Choosing a device from an environment variable, the same way for every GPU backend: the variable holds a device's
// id (its index, as the backend numbers its devices) or any text of its description, as `pyrseg backends` lists it.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace pyrseg::core {

// The position of the first device whose id equals $variable or whose description contains it; std::nullopt when
// the variable is unset or empty. Throws pyrseg::Error(backend_unavailable) listing the devices when it matches
// none. `kind` names the devices in that message ("OpenCL", "Vulkan", "CUDA").
[[nodiscard]] std::optional<std::size_t> device_from_environment(const char* variable, const char* kind,
                                                                 const std::vector<std::string>& ids,
                                                                 const std::vector<std::string>& descriptions);

}  // namespace pyrseg::core
