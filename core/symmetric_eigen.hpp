#pragma once
// Eigenvalues and eigenvectors of a symmetric 3x3 matrix (cyclic Jacobi rotations, on the host): the plane fit and
// the oriented box of the segment statistics.
#include <array>

namespace pyrseg::core {

struct Eigen3 {
    std::array<double, 3> values{};                  // decreasing
    std::array<std::array<double, 3>, 3> vectors{};  // vectors[i]: the unit eigenvector of values[i]
};

// a: xx, xy, xz, yy, yz, zz.
Eigen3 symmetric_eigen(const std::array<double, 6>& a);

}  // namespace pyrseg::core
