#include "core/plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "pyrseg/error.hpp"

namespace pyrseg::core {
namespace {

constexpr std::uint64_t kMax32 = std::numeric_limits<std::uint32_t>::max();
// Largest normals radius accepted: beyond this the tangents span most of any real frame.
constexpr int kMaxNormalRadius = 1024;

[[noreturn]] void bad_parameter(const std::string& what) {
    throw Error(ErrorCode::invalid_parameter, what);
}

int ceil_log2(std::uint64_t v) {
    int n = 0;
    while ((std::uint64_t{1} << n) < v) ++n;
    return n;
}

// The smallest e with 2^-e input units <= 1/16 mm (2^e >= 16 * unit_mm), within float's normal exponents so that
// 2^e is an exact float. frexp is exact, unlike log2.
int stats_point_shift(double unit_mm) {
    int e = 0;
    const double m = std::frexp(16.0 * unit_mm, &e);  // 16 * unit_mm = m * 2^e, 0.5 <= m < 1
    if (std::isinf(m)) return 127;
    const int shift = m == 0.5 ? e - 1 : e;
    return std::clamp(shift, -126, 127);
}

void check_metric_parameters(const Params& p) {
    if (p.metric != Metric::paper && p.metric != Metric::robust) bad_parameter("metric must be paper or robust");
    const auto finite_nonnegative = [](double v) { return std::isfinite(v) && v >= 0.0; };
    if (!finite_nonnegative(p.dt_per_m2)) {
        bad_parameter("dt_per_m2 must be a finite number of millimetres per square metre >= 0, got " +
                      std::to_string(p.dt_per_m2));
    }
    if (!finite_nonnegative(p.ct_growth_per_m2)) {
        bad_parameter("ct_growth_per_m2 must be finite and >= 0, got " + std::to_string(p.ct_growth_per_m2));
    }
    if (p.normal_window < 1 || p.normal_window > kMaxNormalWindow) {
        bad_parameter("normal_window must be in 1.." + std::to_string(kMaxNormalWindow) + ", got " +
                      std::to_string(p.normal_window));
    }
    if (p.curvature_stride < 1 || p.curvature_stride > kMaxCurvatureStride) {
        bad_parameter("curvature_stride must be in 1.." + std::to_string(kMaxCurvatureStride) + ", got " +
                      std::to_string(p.curvature_stride));
    }
    if (p.edge_rounds < 1 || p.edge_rounds > kMaxEdgeRounds) {
        bad_parameter("edge_rounds must be in 1.." + std::to_string(kMaxEdgeRounds) + ", got " +
                      std::to_string(p.edge_rounds));
    }
    if (!(p.edge_max_depth_step == 0.0 ||
          (p.edge_max_depth_step >= kMinEdgeMaxDepthStep && p.edge_max_depth_step <= 1.0))) {
        bad_parameter("edge_max_depth_step must be 0 (no test) or a share of the depth in 1e-06..1, got " +
                      std::to_string(p.edge_max_depth_step));
    }
    if (p.metric == Metric::paper &&
        (p.normal_window != kDefaultNormalWindow || p.curvature_stride != kDefaultCurvatureStride ||
         p.dt_per_m2 != 0.0 || p.ct_growth_per_m2 != 0.0)) {
        bad_parameter(
            "normal_window, curvature_stride, dt_per_m2 and ct_growth_per_m2 belong to the robust metric "
            "(metric = robust); the paper metric takes none of them");
    }
}

void check_color_parameters(const Params& p, Thresholds& t) {
    if (p.color_edge_threshold < 0 || p.color_edge_threshold > kMaxColorEdgeThreshold) {
        bad_parameter("color_edge_threshold must be in 0.." + std::to_string(kMaxColorEdgeThreshold) +
                      " (a sum of R, G and B differences; " + std::to_string(kMaxColorEdgeThreshold) +
                      " ignores the colour), got " + std::to_string(p.color_edge_threshold));
    }
    if (p.color_edge_stride < 1 || p.color_edge_stride > kMaxColorEdgeStride) {
        bad_parameter("color_edge_stride must be in 1.." + std::to_string(kMaxColorEdgeStride) + " pixels, got " +
                      std::to_string(p.color_edge_stride));
    }
    if (!std::isfinite(p.color_edge_curvature_share) || p.color_edge_curvature_share < 0.0 ||
        p.color_edge_curvature_share > 1.0) {
        bad_parameter("color_edge_curvature_share must be in [0, 1] (a share of the curvature limit), got " +
                      std::to_string(p.color_edge_curvature_share));
    }
    if (p.metric == Metric::paper && p.color_edge_curvature_share != 0.0) {
        bad_parameter(
            "color_edge_curvature_share belongs to the robust metric (metric = robust): it gates colour edges by "
            "its curvature term");
    }
    t.color_curvature_gate = static_cast<std::uint32_t>(std::nearbyint(p.color_edge_curvature_share * 256.0));
}

void check_planar_parameters(const Params& p) {
    if (!std::isfinite(p.planar_tolerance_mm) || p.planar_tolerance_mm < 0.0) {
        bad_parameter("planar_tolerance_mm must be a finite number of millimetres >= 0, got " +
                      std::to_string(p.planar_tolerance_mm));
    }
    if (!std::isfinite(p.planar_tolerance_per_m2) || p.planar_tolerance_per_m2 < 0.0) {
        bad_parameter("planar_tolerance_per_m2 must be a finite number of millimetres per square metre >= 0, got " +
                      std::to_string(p.planar_tolerance_per_m2));
    }
}

void check_track_parameters(const Params& p) {
    if (!std::isfinite(p.track_max_distance_mm) || p.track_max_distance_mm < 0.0) {
        bad_parameter("track_max_distance_mm must be a finite number of millimetres >= 0, got " +
                      std::to_string(p.track_max_distance_mm));
    }
    if (p.track_hold_frames < 0 || p.track_hold_frames > kMaxTrackHoldFrames) {
        bad_parameter("track_hold_frames must be in 0.." + std::to_string(kMaxTrackHoldFrames) + " frames, got " +
                      std::to_string(p.track_hold_frames));
    }
}

void check_merge_parameters(const Params& p, Thresholds& t) {
    if (p.merge_reach < 1 || p.merge_reach > kMaxMergeReach) {
        bad_parameter("merge_reach must be in 1.." + std::to_string(kMaxMergeReach) + " pixels, got " +
                      std::to_string(p.merge_reach));
    }
    if (!std::isfinite(p.merge_tolerance_mm) || p.merge_tolerance_mm < 0.0) {
        bad_parameter("merge_tolerance_mm must be a finite number of millimetres >= 0, got " +
                      std::to_string(p.merge_tolerance_mm));
    }
    if (!std::isfinite(p.merge_tolerance_per_m2) || p.merge_tolerance_per_m2 < 0.0) {
        bad_parameter("merge_tolerance_per_m2 must be a finite number of millimetres per square metre >= 0, got " +
                      std::to_string(p.merge_tolerance_per_m2));
    }
    if (p.merge_min_crossings < 1) {
        bad_parameter("merge_min_crossings must be >= 1, got " + std::to_string(p.merge_min_crossings));
    }
    if (!(p.merge_max_bad_share >= 0.0 && p.merge_max_bad_share <= 1.0)) {
        bad_parameter("merge_max_bad_share must be a share in 0..1, got " + std::to_string(p.merge_max_bad_share));
    }
    const int e = stats_point_shift(p.unit_mm);
    t.merge_point_scale = std::ldexp(1.0f, e);
    const double unit = std::ldexp(1.0, e + 13);  // tolerance units per input unit
    t.merge_tolerance_base = static_cast<float>((p.merge_tolerance_mm / p.unit_mm) * unit);
    t.merge_tolerance_growth = static_cast<float>(((p.merge_tolerance_per_m2 * 1e-6) * p.unit_mm) * unit);
    t.merge_share = static_cast<std::uint32_t>(std::nearbyint(p.merge_max_bad_share * 256.0));
    if (!std::isfinite(t.merge_tolerance_base) || !std::isfinite(t.merge_tolerance_growth)) {
        bad_parameter("merge_tolerance_mm or merge_tolerance_per_m2 is too large for unit_mm " +
                      std::to_string(p.unit_mm) + ": the tolerance overflows float32");
    }
}

}  // namespace

void check_unit_mm(double unit_mm) {
    if (!std::isfinite(unit_mm) || unit_mm <= 0.0) {
        bad_parameter("unit_mm must be a finite number of millimetres > 0 (1 for millimetres, 1000 for metres), got " +
                      std::to_string(unit_mm));
    }
}

Thresholds compute_thresholds(const Params& params) {
    if (!std::isfinite(params.ct) || params.ct < 0.0) {
        bad_parameter("ct (curvature threshold) must be a finite angle >= 0 radians, got " + std::to_string(params.ct));
    }
    if (std::isnan(params.dt) || params.dt < 0.0) {
        bad_parameter("dt (depth threshold) must be >= 0 millimetres (or +inf), got " + std::to_string(params.dt));
    }
    check_unit_mm(params.unit_mm);
    Thresholds t{};
    // For ct >= pi the curvature test must always pass: -2^28 is below any k * (mean dot) >= k * -3 * 2^26, and
    // k * -2^28 still fits int32 for k <= 8.
    t.curvature = params.ct >= std::numbers::pi
                      ? -(std::int32_t{1} << 28)
                      : static_cast<std::int32_t>(std::floor(std::cos(params.ct) * 67108864.0));  // 2^26
    t.depth = static_cast<float>(params.dt / params.unit_mm);
    check_metric_parameters(params);
    if (params.metric == Metric::robust) {
        const double c0 = 1.0 - std::cos(params.ct);
        const double unit_m2 = (params.unit_mm / 1000.0) * (params.unit_mm / 1000.0);
        constexpr double kCurvatureOne = 67108864.0;  // 2^26
        const bool always = params.ct >= std::numbers::pi;
        t.curvature_base = always ? 268435456.0f : static_cast<float>(c0 * kCurvatureOne);  // 2^28: always passes
        t.curvature_growth = always ? 0.0f : static_cast<float>(c0 * kCurvatureOne * params.ct_growth_per_m2 * unit_m2);
        t.depth_growth = static_cast<float>(params.dt_per_m2 * 1e-6 * params.unit_mm);
        t.point_scale = std::ldexp(1.0f, stats_point_shift(params.unit_mm));
        // Finite float constants keep every per-pixel threshold free of NaN (0 * inf) on every device.
        if (!std::isfinite(t.curvature_growth)) {
            bad_parameter("ct_growth_per_m2 is too large: its growth overflows float32, got " +
                          std::to_string(params.ct_growth_per_m2));
        }
        if (!std::isfinite(t.depth_growth)) {
            bad_parameter("dt_per_m2 is too large: its growth overflows float32, got " +
                          std::to_string(params.dt_per_m2));
        }
    }
    t.edge_depth_step = static_cast<float>(params.edge_max_depth_step);
    check_merge_parameters(params, t);
    check_color_parameters(params, t);
    check_planar_parameters(params);
    check_track_parameters(params);
    return t;
}

Plan make_plan(int width, int height, const Params& params, const Outputs& outputs) {
    if (width < 1 || height < 1) {
        throw Error(ErrorCode::invalid_argument,
                    "image size " + std::to_string(width) + " x " + std::to_string(height) + " is empty");
    }
    Plan plan;
    plan.width = width;
    plan.height = height;
    plan.params = params;
    plan.thresholds = compute_thresholds(params);
    if (params.normal_radius < 1 || params.normal_radius > kMaxNormalRadius) {
        bad_parameter("normal_radius must be in 1.." + std::to_string(kMaxNormalRadius) + ", got " +
                      std::to_string(params.normal_radius));
    }
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
    if (pixels > kMax32) {
        throw Error(ErrorCode::image_too_large, "image " + std::to_string(width) + " x " + std::to_string(height) +
                                                    " has more pixels than 32-bit labels can address");
    }

    const int n = 1 + ceil_log2(std::uint64_t(std::max(width, height)));
    plan.level_count = n;
    plan.levels.resize(static_cast<std::size_t>(n));
    std::uint64_t w = std::uint64_t(width);
    std::uint64_t h = std::uint64_t(height);
    for (int k = n; k >= 1; --k) {
        plan.levels[static_cast<std::size_t>(k - 1)] = PyrLevel{std::uint32_t(w), std::uint32_t(h), 0};
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    std::uint64_t offset = 0;
    std::vector<std::uint64_t> offsets(static_cast<std::size_t>(n) + 2, 0);  // offsets[k] = offset_k
    for (int k = 1; k <= n; ++k) {
        offsets[std::size_t(k)] = offset;
        const PyrLevel& lv = plan.levels[std::size_t(k - 1)];
        offset += std::uint64_t(lv.width) * lv.height;
    }
    offsets[std::size_t(n) + 1] = offset;
    plan.total_texels = offset;
    // Every backend indexes the all-levels buffers with 32-bit integers.
    if (plan.total_texels > kMax32) {
        throw Error(ErrorCode::image_too_large, "image " + std::to_string(width) + " x " + std::to_string(height) +
                                                    " needs " + std::to_string(plan.total_texels) +
                                                    " pyramid texels, more than 32-bit indices address");
    }
    for (int k = 1; k <= n; ++k) plan.levels[std::size_t(k - 1)].offset = std::uint32_t(offsets[std::size_t(k)]);

    const bool explicit_bg = params.bridge_levels.has_value() || params.unjoinable_gap.has_value();
    const int b = params.bridge_levels.value_or(kDefaultBridgeLevels);
    const int g = params.unjoinable_gap.value_or(kDefaultUnjoinableGap);
    if (b < 1) bad_parameter("bridge_levels must be >= 1, got " + std::to_string(b));
    if (g < 1) bad_parameter("unjoinable_gap must be >= 1, got " + std::to_string(g));
    const int m = n - b;
    const int u = m - g;
    if (u < 1) {
        if (explicit_bg) {
            bad_parameter("bridge_levels " + std::to_string(b) + " and unjoinable_gap " + std::to_string(g) +
                          " do not fit a " + std::to_string(width) + " x " + std::to_string(height) +
                          " image: its pyramid has " + std::to_string(n) + " levels and needs " +
                          "levels - bridge_levels - unjoinable_gap >= 1");
        }
        plan.small_image = true;
        plan.max_label = std::uint32_t(pixels);
    } else {
        plan.bridge_level = m;
        plan.unjoinable_level = u;
        plan.old_label_max = std::uint32_t(offsets[std::size_t(u) + 1]);
        plan.max_label = std::uint32_t(offsets[std::size_t(m) + 1]);  // fits: total_texels does
    }
    if (params.merge && !plan.small_image) {
        // Every label's pixels are 4-connected (steps 1 to 6 only copy labels to 4-neighbours, and a texel that
        // inherits a label has all four children fillable), so the pairs of labels that touch are the edges of a
        // planar graph on the K <= w_M * h_M segments: at most 3 K of them.
        const PyrLevel& lm = plan.level(plan.bridge_level);
        const std::uint64_t pairs = 3 * std::uint64_t(lm.width) * lm.height + 3;
        const std::uint64_t slots = std::uint64_t(1) << ceil_log2(2 * pairs + 1);
        if (slots > (kMax32 - plan.max_label) / 4) {
            throw Error(ErrorCode::image_too_large, "image " + std::to_string(width) + " x " + std::to_string(height) +
                                                        " is too large for the merge's 32-bit pair table");
        }
        plan.merge_slots = std::uint32_t(slots);
    }
    plan.keep_normals = outputs.normals;
    if (outputs.segment_graph) {
        // The final labels are 4-connected too (the merge joins touching labels), so their pairs are the edges of a
        // planar graph on at most K of them (K bounded as for the statistics below).
        const PyrLevel& lm = plan.small_image ? plan.full() : plan.level(m);
        const std::uint64_t pairs = 3 * std::uint64_t(lm.width) * lm.height + 3;
        const std::uint64_t slots = std::uint64_t(1) << ceil_log2(2 * pairs + 1);
        if (1 + std::uint64_t(PYR_GRAPH_SLOT_WORDS) * (slots + slots / 2) > kMax32) {
            throw Error(ErrorCode::image_too_large, "image " + std::to_string(width) + " x " + std::to_string(height) +
                                                        " is too large for the segment graph's 32-bit pair table");
        }
        plan.graph_slots = std::uint32_t(slots);
    }
    if (outputs.segment_tracks || outputs.track_ids) {
        if (!params.compact) {
            bad_parameter("tracks follow the compacted labels: segment_tracks and track_ids need compact on");
        }
        // Each pair of (previous label, label) holds at least one pixel; the table gets more than twice as many
        // slots as a frame can have pairs.
        const std::uint64_t slots = std::uint64_t(1) << ceil_log2(2 * pixels + 1);
        if (plan.graph_words() + PYR_TRACK_HEADER_WORDS + std::uint64_t(PYR_TRACK_SLOT_WORDS) * (slots + pixels) >
            kMax32) {
            throw Error(ErrorCode::image_too_large, "image " + std::to_string(width) + " x " + std::to_string(height) +
                                                        " is too large for the tracks' 32-bit pair table");
        }
        plan.track_slots = std::uint32_t(slots);
    }
    if (outputs.segment_stats || plan.track_slots != 0) {
        // Steps 3 to 6 only copy labels, so every final label lies on a fillable texel of level M and
        // K <= w_M * h_M; the fallback's labels are pixels.
        const PyrLevel& lm = plan.small_image ? plan.full() : plan.level(m);
        plan.stats_slots = lm.width * lm.height;
        if (std::uint64_t(plan.lut_size()) + std::uint64_t(plan.stats_slots) * PYR_STATS_WORDS > kMax32) {
            throw Error(ErrorCode::image_too_large, "image " + std::to_string(width) + " x " + std::to_string(height) +
                                                        " is too large for the statistics' 32-bit word indices");
        }
        plan.stats_point_shift = stats_point_shift(params.unit_mm);
    }
    return plan;
}

float Plan::stats_point_scale() const {
    return std::ldexp(1.0f, stats_point_shift);
}

}  // namespace pyrseg::core
