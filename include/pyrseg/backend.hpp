#pragma once
// Backend discovery: which backends this build has, which can run here, and why not the others.
#include <string>
#include <string_view>
#include <vector>

#include "pyrseg/export.hpp"

namespace pyrseg {

struct BackendInfo {
    std::string name;                  // one of backend_names()
    bool available = false;            // can run on this machine now
    std::string reason;                // why not, when unavailable
    std::vector<std::string> devices;  // human-readable device descriptions when available
    // Available, but the device it would use is a CPU running the GPU API in software (Mesa's lavapipe, PoCL's
    // CPU device): slower than the cpu backend, so "auto" passes it by. It still runs when named.
    bool emulated = false;
    std::string emulated_device;  // that device, when emulated
};

// Every backend pyrseg knows, in preference order: GPUs first, the CPU last; built or not, and probing no device.
[[nodiscard]] PYRSEG_EXPORT std::vector<std::string> backend_names();
// The same as one line for help texts: "cuda, vulkan, opencl, cpu".
[[nodiscard]] PYRSEG_EXPORT std::string backend_names_text();

// Every backend pyrseg knows (backend_names()), with whether it can run here, why not, and its devices.
[[nodiscard]] PYRSEG_EXPORT std::vector<BackendInfo> list_backends();

// The backend a request resolves to, and why, in one sentence for users ("auto: vulkan's device llvmpipe ... is a
// CPU emulation; cpu runs natively").
struct BackendChoice {
    std::string name;
    std::string reason;
};

// Resolves a backend request: an explicit name, else the PYRSEG_BACKEND environment variable, else "auto" (the
// first available backend whose device is a real GPU, else cpu). Throws pyrseg::Error(backend_unavailable) naming
// the reason when the chosen backend cannot run.
[[nodiscard]] PYRSEG_EXPORT BackendChoice choose_backend(std::string_view requested);
// choose_backend(requested).name
[[nodiscard]] PYRSEG_EXPORT std::string resolve_backend_name(std::string_view requested);

}  // namespace pyrseg
