#pragma once
// Where a CloudView's floats lie, whichever way the caller gave its steps (points and floats, or bytes): one
// validated layout in floats that every backend and the host staging read through.
#include <cstddef>

#include "pyrseg/cloud.hpp"

namespace pyrseg::core {

struct CloudLayout {
    std::size_t point_floats = 3;  // from one point to the next
    std::size_t row_floats = 0;    // from one row to the next
    [[nodiscard]] std::size_t at(std::size_t x, std::size_t y) const { return y * row_floats + x * point_floats; }
    [[nodiscard]] bool packed(std::size_t width) const { return point_floats == 3 && row_floats == 3 * width; }
};

// Throws pyrseg::Error(invalid_argument) naming the field when the steps are inconsistent, too small, not
// multiples of a float, too large to address, or a pointer is not 4-byte aligned.
[[nodiscard]] CloudLayout cloud_layout(const CloudView& cloud);

}  // namespace pyrseg::core
