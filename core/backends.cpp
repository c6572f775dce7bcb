#include <cstdlib>
#include <string>
#include <utility>

#include "core/backend_registry.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg {

// In the registry's order (core/backend_registry.hpp): GPUs first, the CPU always last and always there.
std::vector<BackendInfo> list_backends() {
    std::vector<BackendInfo> all;
    for (const core::KnownBackend& k : core::known_backends()) {
        BackendInfo info{k.name, false, "", {}};
        if (k.entry == nullptr) {
            info.reason = k.why_not_built;
        } else {
            info.devices = k.entry->describe(&info.reason, &info.available);
        }
        all.push_back(std::move(info));
    }
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
    for (const KnownBackend& k : known_backends()) {
        if (k.entry != nullptr && backend == k.name) return k.entry->make_executor(plan);
    }
    throw Error(ErrorCode::backend_unavailable, "backend '" + std::string(backend) + "' is not built in");
}

}  // namespace core
}  // namespace pyrseg
