#include "pyrseg/error.hpp"

namespace pyrseg {

const char* to_string(ErrorCode code) noexcept {
    switch (code) {
        case ErrorCode::invalid_argument:
            return "invalid argument";
        case ErrorCode::invalid_parameter:
            return "invalid parameter";
        case ErrorCode::size_mismatch:
            return "size mismatch";
        case ErrorCode::image_too_large:
            return "image too large";
        case ErrorCode::out_of_memory:
            return "out of memory";
        case ErrorCode::backend_unavailable:
            return "backend unavailable";
        case ErrorCode::io:
            return "I/O error";
        case ErrorCode::format:
            return "format error";
        case ErrorCode::internal:
            return "internal error";
    }
    return "unknown error";
}

Error::Error(ErrorCode code, const std::string& message)
    : std::runtime_error(std::string("pyrseg: ") + message), code_(code) {}

}  // namespace pyrseg
