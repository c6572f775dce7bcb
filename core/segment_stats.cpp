#include "core/segment_stats.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "pyrseg/error.hpp"

#include "shaders/pyr_types.h"

namespace pyrseg::core {
namespace {

std::int64_t sum64(const std::uint32_t* w) {
    return static_cast<std::int64_t>(std::uint64_t(w[0]) | (std::uint64_t(w[1]) << 32));
}

}  // namespace

void decode_segment_stats(const std::uint32_t* words, std::uint32_t count, const Plan& plan, bool with_points,
                          std::vector<SegmentStats>& out) {
    if (count > plan.stats_slots) {
        throw Error(ErrorCode::internal, std::to_string(count) + " segments but " + std::to_string(plan.stats_slots) +
                                             " statistics slots (the bound of core/plan.cpp does not hold)");
    }
    out.resize(count);
    const double unit = std::ldexp(1.0, -plan.stats_point_shift);
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    for (std::uint32_t k = 0; k < count; ++k) {
        const std::uint32_t* w = words + std::size_t(k) * PYR_STATS_WORDS;
        SegmentStats& s = out[k];
        s.label = plan.params.compact ? k + 1 : w[PYR_STATS_RAW_LABEL];
        s.pixel_count = w[PYR_STATS_COUNT];
        s.x_min = int(~w[PYR_STATS_NOT_X_MIN]);
        s.y_min = int(~w[PYR_STATS_NOT_Y_MIN]);
        s.x_max = int(w[PYR_STATS_X_MAX]);
        s.y_max = int(w[PYR_STATS_Y_MAX]);
        s.point_shift = plan.stats_point_shift;
        double length2 = 0;
        for (std::size_t c = 0; c < 3; ++c) {
            s.point_sum[c] = sum64(w + PYR_STATS_POINT_SUM + 2 * c);
            s.normal_sum[c] = sum64(w + PYR_STATS_NORMAL_SUM + 2 * c);
            length2 += double(s.normal_sum[c]) * double(s.normal_sum[c]);
        }
        const double length = std::sqrt(length2);
        for (std::size_t c = 0; c < 3; ++c) {
            s.centroid[c] = with_points ? double(s.point_sum[c]) * unit / double(s.pixel_count) : kNaN;
            s.mean_normal[c] = !with_points ? kNaN : length > 0 ? double(s.normal_sum[c]) / length : 0.0;
        }
    }
}

}  // namespace pyrseg::core
