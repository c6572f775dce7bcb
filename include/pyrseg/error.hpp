#pragma once
// pyrseg::Error: every failure the library reports carries a code and a message naming the problem.
#include <stdexcept>
#include <string>

#include "pyrseg/export.hpp"

namespace pyrseg {

enum class ErrorCode {
    invalid_argument,     // a null pointer, a zero size, a stride that does not fit, ...
    invalid_parameter,    // ct, dt, unit_mm, bridge_levels, unjoinable_gap, normal_radius out of range
    size_mismatch,        // a frame whose size differs from the Segmenter's
    image_too_large,      // labels or pixel indices would not fit in 32 bits
    backend_unavailable,  // unknown backend name, or a backend that cannot run here (the message says why)
    out_of_memory,        // the buffers for this image size do not fit in this machine's memory
    io,                   // a file could not be opened, read or written
    format,               // a file's contents are malformed or unsupported
    internal,             // a bug: please report it
};

[[nodiscard]] PYRSEG_EXPORT const char* to_string(ErrorCode code) noexcept;

class PYRSEG_EXPORT Error : public std::runtime_error {
public:
    Error(ErrorCode code, const std::string& message);
    [[nodiscard]] ErrorCode code() const noexcept { return code_; }

private:
    ErrorCode code_;
};

}  // namespace pyrseg
