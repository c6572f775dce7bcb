#include "tools/cloud_stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace pyrseg::cli {

namespace {

double median_of(std::vector<float>& values) {
    if (values.empty()) return 0.0;
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
    return values[values.size() / 2];
}

}  // namespace

double median_depth(const std::vector<float>& points) {
    std::vector<float> z;
    for (std::size_t i = 2; i < points.size(); i += 3) {
        if (std::isfinite(points[i]) && points[i] > 0) z.push_back(points[i]);
    }
    return median_of(z);
}

double detected_unit_mm(double median) {
    return median > 0 && median < kMetresBelowMedianDepth ? 1000.0 : 1.0;
}

}  // namespace pyrseg::cli
