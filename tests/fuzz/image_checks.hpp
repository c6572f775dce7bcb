#pragma once
// The shapes io::Image and io::DepthImage promise (include/pyrseg/io.hpp).
#include <cstddef>

#include "pyrseg/io.hpp"
#include "tests/fuzz/fuzz_input.hpp"

namespace pyrseg::fuzz {

inline std::size_t pixels(int width, int height) {
    expect(width > 0 && height > 0);
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
}

inline void check_image(const io::Image& image) {
    expect(image.bit_depth == 8 || image.bit_depth == 16);
    expect(image.channels >= 1 && image.channels <= 4);
    const auto bytes = static_cast<std::size_t>(image.channels) * static_cast<std::size_t>(image.bit_depth / 8);
    expect(image.data.size() == pixels(image.width, image.height) * bytes);
}

inline void check_depth(const io::DepthImage& image) {
    expect(image.depth.size() == pixels(image.width, image.height));
}

}  // namespace pyrseg::fuzz
