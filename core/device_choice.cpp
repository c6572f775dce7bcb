#include "core/device_choice.hpp"

#include <cstdlib>

#include "pyrseg/error.hpp"

namespace pyrseg::core {

std::optional<std::size_t> device_from_environment(const char* variable, const char* kind,
                                                   const std::vector<std::string>& ids,
                                                   const std::vector<std::string>& descriptions) {
    const char* env = std::getenv(variable);
    if (env == nullptr || *env == '\0') return std::nullopt;
    const std::string want(env);
    for (std::size_t d = 0; d < descriptions.size(); ++d) {
        if (want == ids[d] || descriptions[d].find(want) != std::string::npos) return d;
    }
    std::string message = std::string(variable) + "='" + want;
    message += "' matches no ";
    message += kind;
    message += " device; the devices are:";
    for (const std::string& d : descriptions) message += "\n  " + d;
    throw Error(ErrorCode::backend_unavailable, message);
}

}  // namespace pyrseg::core
