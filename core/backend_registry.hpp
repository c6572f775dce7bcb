#pragma once
// The registry of backends. Each backend describes itself once, as a BackendEntry in its own files
// (backends/<name>/<name>_backend.hpp); backends/CMakeLists.txt generates the list of every backend pyrseg knows, in
// the order 'auto' prefers them, with the built ones' entries and why the others are not built. Adding a backend: its
// entry, and its name in PYRSEG_BACKENDS (cmake/PyrsegBackends.cmake).
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::core {

struct BackendEntry {
    // The devices the backend can see (an unusable one says why); sets *available, and *why_none when no device
    // can run pyrseg here. Never throws.
    std::vector<std::string> (*describe)(std::string* why_none, bool* available) = nullptr;
    // The executor on the chosen device; throws pyrseg::Error. `plan` must outlive it.
    std::unique_ptr<PassExecutor> (*make_executor)(const Plan& plan) = nullptr;
    // Whether the device make_executor would use is a CPU running the API in software (lavapipe, PoCL's CPU
    // device), which 'auto' never prefers to the native CPU backend; sets *device to its description then. nullptr:
    // the backend's devices are never such (CUDA). Never throws.
    bool (*emulated)(std::string* device) = nullptr;
};

struct KnownBackend {
    const char* name;
    const BackendEntry* entry;  // nullptr when this build does not have the backend
    const char* why_not_built;  // when entry is nullptr
};

// Every backend pyrseg knows, GPUs first and the CPU last (generated: backends/CMakeLists.txt).
[[nodiscard]] std::span<const KnownBackend> known_backends();

// Creates the executor of a backend that resolve_backend_name() accepted. `plan` must outlive it.
[[nodiscard]] std::unique_ptr<PassExecutor> make_executor(std::string_view backend, const Plan& plan);

}  // namespace pyrseg::core
