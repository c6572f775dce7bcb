#pragma once
// How a failed call of a GPU API reaches the caller, for every GPU backend. Each backend sorts its own codes into a
// gpu::Fault (which mean out of memory, which a device that cannot go on: only that API knows its list) and names
// them in its own words; what each kind means to the caller is decided here, once: an allocation failure is the
// caller's to handle (a smaller frame, fewer Segmenters), a lost device cannot run this Segmenter any more, and
// anything else is pyrseg's bug.
#include <optional>
#include <string>

#include "core/gpu/device.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::gpu {

struct ApiFailure {
    const char* api = "";         // "Vulkan"
    const char* what = "";        // the call that failed, in the backend's words
    std::string code;             // the API's name for the code, as its users know it: "VK_ERROR_DEVICE_LOST (-4)"
    std::optional<Fault> fault;   // the kind the backend sorted the code into; none: pyrseg's bug
    const char* after_lost = "";  // what the message adds for a lost device: the API's words for what happened
};

// The ErrorCode of a fault of that kind (none: ErrorCode::internal).
[[nodiscard]] ErrorCode error_code_of(std::optional<Fault> fault);

// Throws "<api>: <what> failed: <code>" (and after_lost for a lost device) as a pyrseg::Error of error_code_of.
[[noreturn]] void throw_api_failure(const ApiFailure& failure);

}  // namespace pyrseg::gpu
