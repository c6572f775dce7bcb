#pragma once
// The shape io::PointCloud promises (include/pyrseg/io.hpp), checked on every cloud a reader returns.
#include <cstddef>

#include "pyrseg/io.hpp"
#include "tests/fuzz/fuzz_input.hpp"

namespace pyrseg::fuzz {

inline void check_cloud(const io::PointCloud& cloud) {
    expect(cloud.width > 0 && cloud.height > 0);
    const std::size_t n = 3 * static_cast<std::size_t>(cloud.width) * static_cast<std::size_t>(cloud.height);
    expect(cloud.points.size() == n);
    expect(cloud.normals.empty() || cloud.normals.size() == n);
}

}  // namespace pyrseg::fuzz
