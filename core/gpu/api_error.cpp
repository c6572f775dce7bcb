#include "core/gpu/api_error.hpp"

namespace pyrseg::gpu {

ErrorCode error_code_of(std::optional<Fault> fault) {
    if (!fault) return ErrorCode::internal;
    return *fault == Fault::out_of_memory ? ErrorCode::out_of_memory : ErrorCode::backend_unavailable;
}

void throw_api_failure(const ApiFailure& failure) {
    std::string message = std::string(failure.api) + ": " + failure.what + " failed: " + failure.code;
    if (failure.fault == Fault::device_lost) message += failure.after_lost;
    throw Error(error_code_of(failure.fault), message);
}

}  // namespace pyrseg::gpu
