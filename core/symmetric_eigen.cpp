#include "core/symmetric_eigen.hpp"

#include <algorithm>
#include <cmath>

namespace pyrseg::core {

Eigen3 symmetric_eigen(const std::array<double, 6>& a) {
    double m[3][3] = {{a[0], a[1], a[2]}, {a[1], a[3], a[4]}, {a[2], a[4], a[5]}};
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    // Cyclic Jacobi: each rotation zeroes one off-diagonal entry; the off-diagonal mass falls quadratically, so a
    // few sweeps reach double precision (the bound only guards against a pathological input such as NaN).
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
        const double diag = m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[2][2] * m[2][2];
        if (!(off > 1e-30 * diag) || off == 0.0) break;
        for (int p = 0; p < 2; ++p) {
            for (int q = p + 1; q < 3; ++q) {
                if (m[p][q] == 0.0) continue;
                const double theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
                const double t = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0);
                const double s = t * c;
                for (int k = 0; k < 3; ++k) {  // m <- m J (columns p, q)
                    const double mkp = m[k][p];
                    const double mkq = m[k][q];
                    m[k][p] = c * mkp - s * mkq;
                    m[k][q] = s * mkp + c * mkq;
                }
                for (int k = 0; k < 3; ++k) {  // m <- J^T m (rows p, q)
                    const double mpk = m[p][k];
                    const double mqk = m[q][k];
                    m[p][k] = c * mpk - s * mqk;
                    m[q][k] = s * mpk + c * mqk;
                }
                for (int k = 0; k < 3; ++k) {  // v <- v J: the columns of v are the eigenvectors
                    const double vkp = v[k][p];
                    const double vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
        }
    }
    std::array<int, 3> order = {0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int i, int j) { return m[i][i] > m[j][j]; });
    Eigen3 e;
    for (int i = 0; i < 3; ++i) {
        const int c = order[static_cast<std::size_t>(i)];
        e.values[static_cast<std::size_t>(i)] = m[c][c];
        for (int k = 0; k < 3; ++k) e.vectors[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = v[k][c];
    }
    return e;
}

}  // namespace pyrseg::core
