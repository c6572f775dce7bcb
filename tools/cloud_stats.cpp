#include "tools/cloud_stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace pyrseg::cli {

double median_depth(const std::vector<float>& points) {
    std::vector<float> z;
    for (std::size_t i = 2; i < points.size(); i += 3) {
        if (std::isfinite(points[i]) && points[i] > 0) z.push_back(points[i]);
    }
    if (z.empty()) return 0.0;
    std::nth_element(z.begin(), z.begin() + std::ptrdiff_t(z.size() / 2), z.end());
    return z[z.size() / 2];
}

}  // namespace pyrseg::cli
