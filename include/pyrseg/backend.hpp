#pragma once
// Backend discovery: which backends this build has, which can run here, and why not the others.
#include <string>
#include <string_view>
#include <vector>

namespace pyrseg {

struct BackendInfo {
    std::string name;                  // "cpu", "cuda", "vulkan", "opencl"
    bool available = false;            // can run on this machine now
    std::string reason;                // why not, when unavailable
    std::vector<std::string> devices;  // human-readable device descriptions when available
};

// Every backend pyrseg knows, in preference order (the first available one is "auto").
[[nodiscard]] std::vector<BackendInfo> list_backends();

// Resolves a backend request: an explicit name, else the PYRSEG_BACKEND environment variable, else "auto".
// Throws pyrseg::Error(backend_unavailable) naming the reason when the chosen backend cannot run.
[[nodiscard]] std::string resolve_backend_name(std::string_view requested);

}  // namespace pyrseg
