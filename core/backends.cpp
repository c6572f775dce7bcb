#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "core/backend_registry.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg {

// In the registry's order (core/backend_registry.hpp): GPUs first, the CPU always last and always there.
namespace {

BackendInfo describe(const core::KnownBackend& k) {
    BackendInfo info;
    info.name = k.name;
    if (k.entry == nullptr) {
        info.reason = k.why_not_built;
    } else {
        info.devices = k.entry->describe(&info.reason, &info.available);
        if (info.available && k.entry->emulated != nullptr) info.emulated = k.entry->emulated(&info.emulated_device);
    }
    return info;
}

}  // namespace

std::vector<std::string> backend_names() {
    std::vector<std::string> names;
    for (const core::KnownBackend& k : core::known_backends()) names.emplace_back(k.name);
    return names;
}

std::string backend_names_text() {
    std::string text;
    for (const core::KnownBackend& k : core::known_backends()) text += (text.empty() ? "" : ", ") + std::string(k.name);
    return text;
}

std::vector<BackendInfo> list_backends() {
    std::vector<BackendInfo> all;
    for (const core::KnownBackend& k : core::known_backends()) all.push_back(describe(k));
    return all;
}

BackendChoice choose_backend(std::string_view requested) {
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
    if (name == "auto") {
        const std::vector<BackendInfo> all = list_backends();
        // GPUs first; a GPU API running in software on the CPU is slower than the native CPU backend.
        std::string passed;
        for (const BackendInfo& b : all) {
            if (!b.available) continue;
            if (b.emulated) {
                passed += (passed.empty() ? "" : "; ") + b.name + "'s device " + b.emulated_device;
                continue;
            }
            std::string reason = "auto: ";
            reason += b.name == "cpu" ? "no GPU backend has a GPU here" : "the first backend with a GPU";
            if (!passed.empty())
                reason += " (passed by, as CPU emulations slower than the cpu backend: " + passed + ")";
            return {b.name, reason};
        }
        throw Error(ErrorCode::internal, "no backend is available, not even the CPU");
    }
    // A named backend asks only its own API: a CPU Segmenter never loads a GPU driver (nor waits on one, nor fails in
    // one).
    std::string known;
    for (const core::KnownBackend& k : core::known_backends()) {
        if (k.name == name) {
            const BackendInfo b = describe(k);
            if (!b.available) {
                std::string message = "backend '" + name;
                message += "' (" + origin + ") is unavailable: ";
                message += b.reason;
                throw Error(ErrorCode::backend_unavailable, message);
            }
            return {b.name, origin == "requested" ? std::string("requested") : "PYRSEG_BACKEND=" + name};
        }
        known += (known.empty() ? "" : ", ") + std::string(k.name);
    }
    throw Error(ErrorCode::backend_unavailable,
                "unknown backend '" + name + "' (" + origin + "); known backends: " + known + ", auto");
}

std::string resolve_backend_name(std::string_view requested) {
    return choose_backend(requested).name;
}

namespace core {

std::unique_ptr<PassExecutor> make_executor(std::string_view backend, const Plan& plan) {
    for (const KnownBackend& k : known_backends()) {
        if (k.entry != nullptr && backend == k.name) return k.entry->make_executor(plan);
    }
    throw Error(ErrorCode::backend_unavailable, "backend '" + std::string(backend) + "' is not built in");
}

}  // namespace core
}  // namespace pyrseg
