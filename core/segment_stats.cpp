#include "core/segment_stats.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "core/symmetric_eigen.hpp"
#include "pyrseg/error.hpp"

#include "shaders/pyr_types.h"

namespace pyrseg::core {
namespace {

// __int128 holds every exact product the covariance needs (section 10b's bounds), where double would not.
__extension__ typedef __int128 Int128;
__extension__ typedef unsigned __int128 UInt128;

std::int64_t sum64(const std::uint32_t* w) {
    return static_cast<std::int64_t>(std::uint64_t(w[0]) | (std::uint64_t(w[1]) << 32));
}

// Three words of a 96-bit two's-complement sum, sign-extended to 128 bits.
WideSum sum96(const std::uint32_t* w) {
    WideSum s;
    s.low = std::uint64_t(w[0]) | (std::uint64_t(w[1]) << 32);
    s.high = static_cast<std::int32_t>(w[2]);
    return s;
}

Int128 wide(const WideSum& s) {
    return static_cast<Int128>((static_cast<UInt128>(static_cast<std::uint64_t>(s.high)) << 64) | s.low);
}

std::int32_t z_from_key(std::uint32_t key) {
    return static_cast<std::int32_t>(key ^ 0x80000000u);
}

// A planar segment's second variance is at least this many times its smallest (its second side at least 4 times its
// thickness).
constexpr double kPlanarSpread = 16.0;

// Section 10b: the covariance from the exact sums, then the plane, the box and the planar flag.
void derive_geometry(const Params& params, double unit, SegmentStats& s) {
    const auto n = Int128(s.fillable_count);
    constexpr std::array<std::array<int, 2>, 6> kPairs = {{{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}}};
    const double scale = unit * unit / (double(s.fillable_count) * double(s.fillable_count));
    for (std::size_t i = 0; i < 6; ++i) {
        // n * S_ab - S_a * S_b, exact: |n| < 2^32, |S_ab| < 2^94, |S_a| < 2^63.
        const Int128 centred = n * wide(s.point_product_sum[i]) - Int128(s.point_sum[std::size_t(kPairs[i][0])]) *
                                                                      Int128(s.point_sum[std::size_t(kPairs[i][1])]);
        s.covariance[i] = double(centred) * scale;
    }
    s.z_min = double(s.z_fixed_min) * unit;
    s.z_max = double(s.z_fixed_max) * unit;
    const Eigen3 e = symmetric_eigen(s.covariance);
    const double smallest = std::max(e.values[2], 0.0);
    const double total = std::max(e.values[0], 0.0) + std::max(e.values[1], 0.0) + smallest;
    std::array<double, 3> normal = e.vectors[2];
    const double towards = normal[0] * s.centroid[0] + normal[1] * s.centroid[1] + normal[2] * s.centroid[2];
    if (towards > 0 || (towards == 0 && normal[2] > 0)) {
        for (double& c : normal) c = -c;
    }
    s.plane_normal = normal;
    s.plane_offset = -(normal[0] * s.centroid[0] + normal[1] * s.centroid[1] + normal[2] * s.centroid[2]);
    s.plane_rms = std::sqrt(smallest);
    s.curvature = total > 0 ? smallest / total : 0.0;
    // A right-handed box frame: the first axis with its largest component positive, the third the plane normal.
    std::array<double, 3> first = e.vectors[0];
    std::size_t largest = 0;
    for (std::size_t c = 1; c < 3; ++c) {
        if (std::fabs(first[c]) > std::fabs(first[largest])) largest = c;
    }
    if (first[largest] < 0) {
        for (double& c : first) c = -c;
    }
    s.axes[0] = first;
    s.axes[2] = normal;
    s.axes[1] = {normal[1] * first[2] - normal[2] * first[1], normal[2] * first[0] - normal[0] * first[2],
                 normal[0] * first[1] - normal[1] * first[0]};
    for (std::size_t i = 0; i < 3; ++i) s.extents[i] = 2.0 * std::sqrt(3.0 * std::max(e.values[i], 0.0));
    const double z_m = std::fabs(s.centroid[2]) * params.unit_mm * 1e-3;
    const double tolerance_mm = params.planar_tolerance_mm + params.planar_tolerance_per_m2 * z_m * z_m;
    // Spread in two dimensions, not along a line: a sliver's plane is any plane through it.
    const bool two_dimensional = std::max(e.values[1], 0.0) >= kPlanarSpread * smallest;
    s.planar = s.fillable_count >= 3 && two_dimensional && s.plane_rms * params.unit_mm <= tolerance_mm;
}

void no_geometry(SegmentStats& s) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    s.centroid.fill(kNaN);
    s.mean_normal.fill(kNaN);
    s.covariance.fill(kNaN);
    s.z_min = s.z_max = kNaN;
    s.plane_normal.fill(kNaN);
    s.plane_offset = s.plane_rms = s.curvature = kNaN;
    for (auto& axis : s.axes) axis.fill(kNaN);
    s.extents.fill(kNaN);
    s.planar = false;
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
    for (std::uint32_t k = 0; k < count; ++k) {
        const std::uint32_t* w = words + std::size_t(k) * PYR_STATS_WORDS;
        SegmentStats& s = out[k];
        s = SegmentStats{};
        s.label = plan.params.compact ? k + 1 : w[PYR_STATS_RAW_LABEL];
        s.pixel_count = w[PYR_STATS_COUNT];
        s.x_min = int(~w[PYR_STATS_NOT_X_MIN]);
        s.y_min = int(~w[PYR_STATS_NOT_Y_MIN]);
        s.x_max = int(w[PYR_STATS_X_MAX]);
        s.y_max = int(w[PYR_STATS_Y_MAX]);
        s.point_shift = plan.stats_point_shift;
        s.fillable_count = with_points ? w[PYR_STATS_FILLABLE_COUNT] : 0u;
        if (s.fillable_count == 0) {
            no_geometry(s);
            continue;
        }
        double length2 = 0;
        for (std::size_t c = 0; c < 3; ++c) {
            s.point_sum[c] = sum64(w + PYR_STATS_POINT_SUM + 2 * c);
            s.normal_sum[c] = sum64(w + PYR_STATS_NORMAL_SUM + 2 * c);
            length2 += double(s.normal_sum[c]) * double(s.normal_sum[c]);
        }
        for (std::size_t i = 0; i < 6; ++i) s.point_product_sum[i] = sum96(w + PYR_STATS_PRODUCT_SUM + 3 * i);
        s.z_fixed_max = z_from_key(w[PYR_STATS_Z_KEY_MAX]);
        s.z_fixed_min = z_from_key(~w[PYR_STATS_NOT_Z_KEY_MIN]);
        const double length = std::sqrt(length2);
        for (std::size_t c = 0; c < 3; ++c) {
            s.centroid[c] = double(s.point_sum[c]) * unit / double(s.fillable_count);
            s.mean_normal[c] = length > 0 ? double(s.normal_sum[c]) / length : 0.0;
        }
        derive_geometry(plan.params, unit, s);
    }
}

}  // namespace pyrseg::core
