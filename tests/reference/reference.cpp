// The oracle, written from shared/spec/algorithm-contract.md and docs/algorithm.md only. It favours the most literal
// reading of the text over speed: one std::vector per pyramid level, BFS for the fixed points of steps 2 and 4 (by
// their definition, not by iterating the propagation rule), literal sequential sweeps for step 6, std::map and a
// union-find over labels for the merge (step 6d). Every algorithm is linear in the pixel count (up to a log factor in
// compaction and the merge), so full camera frames stay cheap.
#include "reference/reference.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <numbers>
#include <queue>
#include <string>
#include <utility>
#include <vector>

namespace pyrseg_ref {
namespace {

constexpr std::uint64_t kMaxU32 = 0xFFFFFFFFull;

struct Dims {
    std::int64_t w = 0;
    std::int64_t h = 0;
};

// What the parameters and the image size resolve to, computed before anything big is allocated.
struct Plan {
    bool fallback = false;              // plain 4-connected components (contract section 4, small images)
    int n = 0;                          // N
    int m = 0;                          // M = N - b
    int u = 0;                          // U = M - g
    std::vector<Dims> dims;             // dims[k] for k = 1..N (index 0 unused)
    std::vector<std::uint64_t> offset;  // offset[k] for k = 1..N+1 (index 0 unused)
};

bool point_valid(const float* p) {
    return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && p[2] > 0.0f;
}

bool normal_valid(const float* n) {
    if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2])) return false;
    // Compared as floats on purpose: -0.0 counts as zero and a subnormal as non-zero, the IEEE meaning.
    return !(n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f);
}

// N = 1 + ceil(log2(max(W, H))), by integers so no floating-point log can be off by one at a power of two.
int level_count(int width, int height) {
    const std::int64_t longest = std::max(width, height);
    int n = 0;
    while ((std::int64_t{1} << n) < longest) ++n;
    return 1 + n;
}

// Section 2b's four parameters: in range with the robust metric, at their defaults with the paper one.
std::string check_metric_params(const Params& p) {
    if (p.edge_rounds < 1 || p.edge_rounds > 63) return "edge_rounds must be in 1..63";
    // Section 5 step 6c: c is 0 (no test) or in [1e-6, 1]. Written so that NaN fails too; -0.0 equals 0.
    if (!(p.edge_max_depth_step == 0.0 || (p.edge_max_depth_step >= 1e-6 && p.edge_max_depth_step <= 1.0))) {
        return "edge_max_depth_step must be 0 or in [1e-6, 1]";
    }
    if (p.metric == Metric::paper) {
        const Params defaults;
        if (p.normal_window != defaults.normal_window)
            return "normal_window must keep its default (3) with metric paper";
        if (p.curvature_stride != defaults.curvature_stride) {
            return "curvature_stride must keep its default (4) with metric paper";
        }
        // Compared as doubles on purpose: -0.0 equals the default 0 and NaN does not.
        if (!(p.dt_per_m2 == defaults.dt_per_m2)) return "dt_per_m2 must keep its default (0) with metric paper";
        if (!(p.ct_growth_per_m2 == defaults.ct_growth_per_m2)) {
            return "ct_growth_per_m2 must keep its default (0) with metric paper";
        }
        return {};
    }
    if (p.metric != Metric::robust) return "metric must be paper or robust";
    if (p.normal_window < 1 || p.normal_window > 7) return "normal_window must be in 1..7";
    if (p.curvature_stride < 1 || p.curvature_stride > 64) return "curvature_stride must be in 1..64";
    if (!std::isfinite(p.dt_per_m2) || p.dt_per_m2 < 0.0) return "dt_per_m2 must be finite and >= 0";
    if (!std::isfinite(p.ct_growth_per_m2) || p.ct_growth_per_m2 < 0.0)
        return "ct_growth_per_m2 must be finite and >= 0";
    if (p.metric == Metric::robust) {
        // Section 2b: constants that are not finite as float32 are rejected.
        const double z2 = (p.unit_mm / 1000.0) * (p.unit_mm / 1000.0);
        const double c0 = p.ct >= std::numbers::pi ? 0.0 : 1.0 - std::cos(p.ct);
        if (!std::isfinite(static_cast<float>(c0 * 67108864.0 * p.ct_growth_per_m2 * z2))) {
            return "ct_growth_per_m2 is too large: its growth overflows float32";
        }
        if (!std::isfinite(static_cast<float>(p.dt_per_m2 * 1e-6 * p.unit_mm))) {
            return "dt_per_m2 is too large: its growth overflows float32";
        }
    }
    return {};
}

int point_shift(double unit_mm);

// Section 5b's host constants, computed in double in the order written and converted to float32 once.
struct MergeConstants {
    int e = 0;           // the exponent of section 10, also G's (section 8b)
    float t0 = 0.0f;     // T0
    float t2 = 0.0f;     // T2
    std::int64_t s = 0;  // S = rint(f * 256), 0..256
};

MergeConstants merge_constants(const Params& p) {
    MergeConstants k;
    k.e = point_shift(p.unit_mm);
    const double u = std::ldexp(1.0, k.e + 13);  // u = 2^(e + 13), exact in double (e + 13 <= 140)
    k.t0 = static_cast<float>((p.merge_tolerance_mm / p.unit_mm) * u);
    k.t2 = static_cast<float>(((p.merge_tolerance_per_m2 * 1e-6) * p.unit_mm) * u);
    k.s = static_cast<std::int64_t>(std::nearbyint(p.merge_max_bad_share * 256.0));  // round half to even
    return k;
}

// Section 5b's parameters, checked whether or not merge is on (unit_mm has been checked before).
std::string check_merge_params(const Params& p) {
    if (p.merge_reach < 1 || p.merge_reach > 16) return "merge_reach must be in 1..16";
    if (!std::isfinite(p.merge_tolerance_mm) || p.merge_tolerance_mm < 0.0) {
        return "merge_tolerance_mm must be finite and >= 0";
    }
    if (!std::isfinite(p.merge_tolerance_per_m2) || p.merge_tolerance_per_m2 < 0.0) {
        return "merge_tolerance_per_m2 must be finite and >= 0";
    }
    if (p.merge_min_crossings < 1) return "merge_min_crossings must be >= 1";
    // Written so that NaN fails too.
    if (!(p.merge_max_bad_share >= 0.0 && p.merge_max_bad_share <= 1.0)) {
        return "merge_max_bad_share must be in [0, 1]";
    }
    const MergeConstants k = merge_constants(p);
    if (!std::isfinite(k.t0)) return "merge_tolerance_mm is too large: T0 overflows float32";
    if (!std::isfinite(k.t2)) return "merge_tolerance_per_m2 is too large: T2 overflows float32";
    return {};
}

std::string check_params(int width, int height, const Params& p) {
    if (width < 1 || height < 1) return "width and height must be >= 1";
    if (!std::isfinite(p.ct) || p.ct < 0.0) return "ct must be finite and >= 0";
    if (std::isnan(p.dt) || p.dt < 0.0) return "dt must be >= 0 (+inf allowed)";
    if (!std::isfinite(p.unit_mm) || p.unit_mm <= 0.0) return "unit_mm must be finite and > 0";
    if (p.bridge_levels < 1) return "bridge_levels must be >= 1";
    if (p.unjoinable_gap < 1) return "unjoinable_gap must be >= 1";
    if (std::string why = check_metric_params(p); !why.empty()) return why;
    if (std::string why = check_merge_params(p); !why.empty()) return why;
    if (p.color_edge_threshold < 0 || p.color_edge_threshold > 765) return "color_edge_threshold must be in 0..765";
    if (p.color_edge_stride < 1 || p.color_edge_stride > 16) return "color_edge_stride must be in 1..16";
    // Written so that NaN fails too.
    if (!(p.color_edge_curvature_share >= 0.0 && p.color_edge_curvature_share <= 1.0)) {
        return "color_edge_curvature_share must be in [0, 1]";
    }
    // Robust only (section 2c). Compared as doubles on purpose: -0.0 equals the default 0.
    if (p.metric != Metric::robust && !(p.color_edge_curvature_share == 0.0)) {
        return "color_edge_curvature_share must keep its default (0) with metric paper";
    }
    const std::uint64_t pixels = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
    if (pixels > kMaxU32) return "image too large: W*H does not fit in 32 bits";
    return {};
}

// Resolves N, M, U, the level sizes and the label offsets; only small vectors (one entry per level) are allocated.
std::string make_plan(int width, int height, const Params& p, Plan& plan) {
    plan.n = level_count(width, height);
    const std::int64_t u = std::int64_t{plan.n} - p.bridge_levels - p.unjoinable_gap;
    if (u < 1) {
        if (p.bg_explicit) {
            return "bridge_levels and unjoinable_gap do not fit the image: U = N - b - g = " + std::to_string(u) +
                   " < 1 (N = " + std::to_string(plan.n) + ")";
        }
        plan.fallback = true;
        return {};
    }
    plan.m = plan.n - p.bridge_levels;
    plan.u = plan.m - p.unjoinable_gap;
    const int n = plan.n;
    plan.dims.assign(static_cast<std::size_t>(n) + 1, Dims{});
    plan.dims[static_cast<std::size_t>(n)] = Dims{width, height};
    for (int k = n; k > 1; --k) {
        const Dims& finer = plan.dims[static_cast<std::size_t>(k)];
        plan.dims[static_cast<std::size_t>(k) - 1] = Dims{(finer.w + 1) / 2, (finer.h + 1) / 2};
    }
    plan.offset.assign(static_cast<std::size_t>(n) + 2, 0);
    for (int k = 1; k <= n; ++k) {
        const Dims& d = plan.dims[static_cast<std::size_t>(k)];
        plan.offset[static_cast<std::size_t>(k) + 1] =
            plan.offset[static_cast<std::size_t>(k)] + static_cast<std::uint64_t>(d.w * d.h);
    }
    if (plan.offset[static_cast<std::size_t>(plan.m) + 1] > kMaxU32) {
        return "image too large: labels up to offset_{M+1} do not fit in 32 bits";
    }
    return {};
}

// ---------------------------------------------------------------------------------------------------------------
// Normals pass (docs/algorithm.md section 8).

using Vec3f = std::array<float, 3>;
using Vec3i = std::array<std::int64_t, 3>;

// F(v): the fixed-point conversion with 15 significant bits, read off the float bit patterns.
Vec3i fixed_point(const Vec3f& v) {
    std::array<std::uint32_t, 3> bits{};
    std::array<int, 3> expo{};
    std::array<bool, 3> nonzero{};
    int largest = -1;
    for (std::size_t c = 0; c < 3; ++c) {
        bits[c] = std::bit_cast<std::uint32_t>(v[c]);
        expo[c] = static_cast<int>((bits[c] >> 23) & 0xFFu);
        nonzero[c] = expo[c] != 0 && expo[c] != 255;
        if (nonzero[c]) largest = std::max(largest, expo[c]);
    }
    Vec3i out{0, 0, 0};
    if (largest < 0) return out;
    for (std::size_t c = 0; c < 3; ++c) {
        if (!nonzero[c]) continue;
        const std::uint32_t significand = (bits[c] & 0x7FFFFFu) | 0x800000u;
        const int shift = 9 + largest - expo[c];
        // A C++ shift by >= 32 is undefined, and the text says such a shift gives 0.
        const std::int64_t magnitude = shift > 31 ? 0 : static_cast<std::int64_t>(significand >> shift);
        out[c] = (bits[c] >> 31) != 0 ? -magnitude : magnitude;
    }
    return out;
}

std::uint64_t isqrt(std::uint64_t value) {
    auto root = static_cast<std::uint64_t>(std::sqrt(static_cast<double>(value)));
    // The double estimate can be one off either way; settle it exactly.
    while (root > 0 && root * root > value) --root;
    while ((root + 1) * (root + 1) <= value) ++root;
    return root;
}

Vec3f sub(const float* a, const float* b) {
    return Vec3f{a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

// Steps 2 (from "C = U x V") to 5 of section 8 on two integer tangents: the normal as the integer vector q
// (|q_c| <= 8192), or (0, 0, 0) when the cross product is zero. p is the pixel's point, for the orientation.
Vec3i normal_of_tangents(const Vec3i& fu, const Vec3i& fv, const float* p) {
    const Vec3i none{0, 0, 0};
    const Vec3i c{fu[1] * fv[2] - fu[2] * fv[1], fu[2] * fv[0] - fu[0] * fv[2], fu[0] * fv[1] - fu[1] * fv[0]};
    if (c[0] == 0 && c[1] == 0 && c[2] == 0) return none;

    std::int64_t largest = 0;
    for (std::int64_t comp : c) largest = std::max(largest, comp < 0 ? -comp : comp);
    const int s = static_cast<int>(std::bit_width(static_cast<std::uint64_t>(largest))) - 1;
    Vec3i d{};
    for (std::size_t i = 0; i < 3; ++i) {
        std::int64_t mag = c[i] < 0 ? -c[i] : c[i];
        if (s > 14) {
            mag >>= (s - 14);
        } else if (s < 14) {
            mag <<= (14 - s);
        }
        d[i] = c[i] < 0 ? -mag : mag;
    }

    const auto sum = static_cast<std::uint64_t>(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const std::uint64_t len = isqrt(sum);
    Vec3i q{};
    for (std::size_t i = 0; i < 3; ++i) {
        const auto mag = static_cast<std::uint64_t>(d[i] < 0 ? -d[i] : d[i]);
        const auto qm = static_cast<std::int64_t>((mag * 16384u + len) / (2u * len));
        q[i] = d[i] < 0 ? -qm : qm;
    }

    const Vec3i w = fixed_point(Vec3f{p[0], p[1], p[2]});
    if (q[0] * w[0] + q[1] * w[1] + q[2] * w[2] > 0) {
        for (std::int64_t& comp : q) comp = -comp;
    }
    return q;
}

// The normal of one pixel as the integer vector q (|q_c| <= 8192), or (0, 0, 0) when it is undefined.
Vec3i pixel_normal(const float* points, std::int64_t width, std::int64_t height, std::int64_t x, std::int64_t y,
                   std::int64_t r) {
    const Vec3i none{0, 0, 0};
    auto at = [&](std::int64_t px, std::int64_t py) { return points + 3 * (py * width + px); };
    const float* p = at(x, y);
    if (!point_valid(p)) return none;

    // Tangent from the neighbours on either side: both -> central difference, one -> one-sided, none -> undefined.
    auto tangent = [&](const float* after, const float* before, Vec3f& t) {
        if (after != nullptr && before != nullptr) {
            t = sub(after, before);
        } else if (after != nullptr) {
            t = sub(after, p);
        } else if (before != nullptr) {
            t = sub(p, before);
        } else {
            return false;
        }
        return true;
    };
    auto usable = [&](std::int64_t px, std::int64_t py) -> const float* {
        if (px < 0 || py < 0 || px >= width || py >= height) return nullptr;
        const float* q = at(px, py);
        return point_valid(q) ? q : nullptr;
    };
    Vec3f u{};
    Vec3f v{};
    if (!tangent(usable(x + r, y), usable(x - r, y), u)) return none;
    if (!tangent(usable(x, y + r), usable(x, y - r), v)) return none;

    return normal_of_tangents(fixed_point(u), fixed_point(v), p);
}

// Sections 10 and 8b. The fixed point's exponent: the smallest e (within -126..127) with 2^e >= 16 * unit_mm.
int point_shift(double unit_mm) {
    int e = -126;
    while (e < 127 && std::ldexp(1.0, e) < 16.0 * unit_mm) ++e;
    return e;
}

// ---------------------------------------------------------------------------------------------------------------
// Robust normals (docs/algorithm.md section 8b).

// G(v) = rint(clamp(v * 2^e, -2^22, 2^22)), round half to even. v * 2^e is a float32 product (exact unless it
// overflows, which the clamp then saturates, or lands among the subnormals); std::nearbyint rounds half to even in
// the default rounding mode.
std::int64_t fixed_coordinate(float v, float scale) {
    const float scaled = v * scale;
    const float limit = 4194304.0f;  // 2^22
    return static_cast<std::int64_t>(std::nearbyint(std::clamp(scaled, -limit, limit)));
}

// Brings a non-zero integer vector to 15 significant bits: the largest magnitude ends up in [2^14, 2^15), every
// magnitude shifted by the same amount (right: truncating), signs kept.
Vec3i to_15_bits(const Vec3i& v) {
    std::int64_t largest = 0;
    for (std::int64_t comp : v) largest = std::max(largest, comp < 0 ? -comp : comp);
    const int s = static_cast<int>(std::bit_width(static_cast<std::uint64_t>(largest))) - 1 - 14;
    Vec3i out{};
    for (std::size_t c = 0; c < 3; ++c) {
        std::int64_t mag = v[c] < 0 ? -v[c] : v[c];
        if (s > 0) {
            mag >>= s;
        } else if (s < 0) {
            mag <<= -s;
        }
        out[c] = v[c] < 0 ? -mag : mag;
    }
    return out;
}

// Every pixel's robust normal as the integer vector q, (0, 0, 0) where undefined.
std::vector<Vec3i> robust_normals_q(const float* points, std::int64_t width, std::int64_t height, std::int64_t r,
                                    std::int64_t window, double unit_mm) {
    const auto count = static_cast<std::size_t>(width * height);
    const float scale = std::ldexp(1.0f, point_shift(unit_mm));
    std::vector<std::uint8_t> pv(count, 0);
    std::vector<Vec3i> g(count, Vec3i{0, 0, 0});
    for (std::size_t i = 0; i < count; ++i) {
        const float* p = points + 3 * i;
        if (!point_valid(p)) continue;
        pv[i] = 1;
        for (std::size_t c = 0; c < 3; ++c) g[i][c] = fixed_coordinate(p[c], scale);
    }
    const auto idx = [&](std::int64_t x, std::int64_t y) { return static_cast<std::size_t>(y * width + x); };

    // Tangents of every pixel; no one-sided fallback. The pixel itself need not be point-valid for its tangent to
    // exist, but only point-valid pixels are ever in a window.
    std::vector<std::uint8_t> has_h(count, 0);
    std::vector<std::uint8_t> has_v(count, 0);
    std::vector<Vec3i> th(count, Vec3i{0, 0, 0});
    std::vector<Vec3i> tv(count, Vec3i{0, 0, 0});
    for (std::int64_t y = 0; y < height; ++y) {
        for (std::int64_t x = 0; x < width; ++x) {
            const std::size_t j = idx(x, y);
            if (x - r >= 0 && x + r < width && pv[idx(x - r, y)] != 0 && pv[idx(x + r, y)] != 0) {
                has_h[j] = 1;
                for (std::size_t c = 0; c < 3; ++c) th[j][c] = g[idx(x + r, y)][c] - g[idx(x - r, y)][c];
            }
            if (y - r >= 0 && y + r < height && pv[idx(x, y - r)] != 0 && pv[idx(x, y + r)] != 0) {
                has_v[j] = 1;
                for (std::size_t c = 0; c < 3; ++c) tv[j][c] = g[idx(x, y + r)][c] - g[idx(x, y - r)][c];
            }
        }
    }

    std::vector<Vec3i> q(count, Vec3i{0, 0, 0});
    for (std::int64_t y = 0; y < height; ++y) {
        for (std::int64_t x = 0; x < width; ++x) {
            const std::size_t i = idx(x, y);
            if (pv[i] == 0) continue;
            const std::int64_t zi = g[i][2];
            const std::int64_t jmax = zi >> 4;  // J; zi >= 0 here, so the shift is a plain floor division by 16
            Vec3i u{0, 0, 0};
            Vec3i v{0, 0, 0};
            for (std::int64_t dy = -window; dy <= window; ++dy) {
                for (std::int64_t dx = -window; dx <= window; ++dx) {
                    const std::int64_t nx = x + dx;
                    const std::int64_t ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
                    const std::size_t j = idx(nx, ny);
                    if (pv[j] == 0) continue;
                    const std::int64_t dz = g[j][2] - zi;
                    if ((dz < 0 ? -dz : dz) > jmax) continue;
                    for (std::size_t c = 0; c < 3; ++c) {
                        if (has_h[j] != 0) u[c] += th[j][c];
                        if (has_v[j] != 0) v[c] += tv[j][c];
                    }
                }
            }
            const bool u_zero = u[0] == 0 && u[1] == 0 && u[2] == 0;
            const bool v_zero = v[0] == 0 && v[1] == 0 && v[2] == 0;
            if (u_zero || v_zero) continue;
            q[i] = normal_of_tangents(to_15_bits(u), to_15_bits(v), points + 3 * i);
        }
    }
    return q;
}

std::vector<float> normals_from_q(const std::vector<Vec3i>& q) {
    std::vector<float> normals(3 * q.size(), 0.0f);
    for (std::size_t i = 0; i < q.size(); ++i) {
        // q / 2^13 is exact: |q| <= 2^13 fits the float significand and the scale is a power of two.
        for (std::size_t c = 0; c < 3; ++c) normals[3 * i + c] = static_cast<float>(q[i][c]) / 8192.0f;
    }
    return normals;
}

// ---------------------------------------------------------------------------------------------------------------
// Metric pass (contract section 2).

std::int64_t curvature_threshold(double ct) {
    // ct >= pi must always pass the curvature test; -2^28 is below any possible mean dot product (>= -3 * 2^26).
    if (ct >= std::numbers::pi) return -(std::int64_t{1} << 28);
    return static_cast<std::int64_t>(std::floor(std::cos(ct) * 67108864.0));
}

std::int64_t quantize(float n) {
    return static_cast<std::int64_t>(std::nearbyint(std::clamp(n, -1.0f, 1.0f) * 8192.0f));
}

using QuantizedNormals = std::vector<std::array<std::int64_t, 3>>;

// Section 2's quantization of every valid pixel's normal (zero elsewhere, never read).
QuantizedNormals quantize_normals(const float* normals, const std::vector<std::uint8_t>& valid) {
    QuantizedNormals qn(valid.size(), {0, 0, 0});
    for (std::size_t i = 0; i < valid.size(); ++i) {
        if (valid[i] == 0) continue;
        for (std::size_t c = 0; c < 3; ++c) qn[i][c] = quantize(normals[3 * i + c]);
    }
    return qn;
}

struct CurvatureSum {
    std::int64_t k = 0;  // how many of the pixels (or pairs) taking part exist and are valid
    std::int64_t s = 0;  // the sum of the integer dot products qn_i . qn_j over them
};

// Over the pixels (x + stride*dx, y + stride*dy), (dx, dy) != (0, 0) in {-1, 0, 1}^2, that exist and are valid.
CurvatureSum curvature_sum(const QuantizedNormals& qn, const std::vector<std::uint8_t>& valid, std::int64_t width,
                           std::int64_t height, std::int64_t x, std::int64_t y, std::int64_t stride) {
    const auto i = static_cast<std::size_t>(y * width + x);
    CurvatureSum out;
    for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0) continue;
            const std::int64_t nx = x + stride * dx;
            const std::int64_t ny = y + stride * dy;
            if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            const auto j = static_cast<std::size_t>(ny * width + nx);
            if (valid[j] == 0) continue;
            out.s += qn[i][0] * qn[j][0] + qn[i][1] * qn[j][1] + qn[i][2] * qn[j][2];
            ++out.k;
        }
    }
    return out;
}

// Section 2b: over the 4 axes, the pairs of pixels s before and after (x, y) that both exist and are valid; the sum
// of the dot products of each pair's two normals (the pixel's own normal takes no part).
CurvatureSum pair_curvature_sum(const QuantizedNormals& qn, const std::vector<std::uint8_t>& valid, std::int64_t width,
                                std::int64_t height, std::int64_t x, std::int64_t y, std::int64_t stride) {
    CurvatureSum out;
    const std::int64_t axes[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    const auto valid_at = [&](std::int64_t px, std::int64_t py) {
        return px >= 0 && py >= 0 && px < width && py < height && valid[static_cast<std::size_t>(py * width + px)] != 0;
    };
    for (const auto& axis : axes) {
        const std::int64_t ax = x + stride * axis[0], ay = y + stride * axis[1];
        const std::int64_t bx = x - stride * axis[0], by = y - stride * axis[1];
        if (!valid_at(ax, ay) || !valid_at(bx, by)) continue;
        const auto a = static_cast<std::size_t>(ay * width + ax);
        const auto b = static_cast<std::size_t>(by * width + bx);
        out.s += qn[a][0] * qn[b][0] + qn[a][1] * qn[b][1] + qn[a][2] * qn[b][2];
        ++out.k;
    }
    return out;
}

struct DepthSpread {
    std::int64_t k = 0;  // valid 8-neighbours (stride 1)
    float d = 0.0f;      // max_j dd_j - min_j dd_j in float32 (0 when k = 0, never used then)
};

// Section 2's depth term: dd_j = |z_i - z_j| over the valid 8-neighbours, d = max - min, all in float32.
DepthSpread depth_spread(const float* points, const std::vector<std::uint8_t>& valid, std::int64_t width,
                         std::int64_t height, std::int64_t x, std::int64_t y) {
    const auto i = static_cast<std::size_t>(y * width + x);
    const float zi = points[3 * i + 2];
    std::int64_t k = 0;
    float dd_min = 0.0f;
    float dd_max = 0.0f;
    for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0) continue;
            const std::int64_t nx = x + dx;
            const std::int64_t ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            const auto j = static_cast<std::size_t>(ny * width + nx);
            if (valid[j] == 0) continue;
            const float diff = zi - points[3 * j + 2];
            const float dd = std::fabs(diff);
            if (k == 0) {
                dd_min = dd;
                dd_max = dd;
            } else {
                dd_min = std::min(dd_min, dd);
                dd_max = std::max(dd_max, dd);
            }
            ++k;
        }
    }
    DepthSpread out;
    out.k = k;
    out.d = dd_max - dd_min;
    return out;
}

// qn: section 2's quantization of the normals (quantize_normals).
std::vector<std::uint8_t> metric(const float* points, const QuantizedNormals& qn,
                                 const std::vector<std::uint8_t>& valid, std::int64_t width, std::int64_t height,
                                 const Params& p) {
    const std::int64_t tc = curvature_threshold(p.ct);
    const auto dt_units = static_cast<float>(p.dt / p.unit_mm);
    const std::size_t count = valid.size();
    std::vector<std::uint8_t> fillable(count, 0);
    for (std::int64_t y = 0; y < height; ++y) {
        for (std::int64_t x = 0; x < width; ++x) {
            const auto i = static_cast<std::size_t>(y * width + x);
            if (valid[i] == 0) continue;
            const CurvatureSum curv = curvature_sum(qn, valid, width, height, x, y, 1);
            const DepthSpread depth = depth_spread(points, valid, width, height, x, y);
            // Over the same 8 neighbours, so curv.k == depth.k.
            fillable[i] = (depth.k >= 1 && curv.s >= curv.k * tc && depth.d <= dt_units) ? 1 : 0;
        }
    }
    return fillable;
}

// The robust metric's host constants (section 2b), computed in double and converted to float32 once.
struct RobustConstants {
    float a = 0.0f;
    float bc = 0.0f;
    float dt_units = 0.0f;
    float bd = 0.0f;
};

RobustConstants robust_constants(const Params& p) {
    RobustConstants k;
    const double z2 = (p.unit_mm / 1000.0) * (p.unit_mm / 1000.0);  // Z2 = (unit_mm / 1000)^2
    if (p.ct >= std::numbers::pi) {
        k.a = 268435456.0f;  // 2^28
        k.bc = 0.0f;
    } else {
        const double c0 = 1.0 - std::cos(p.ct);
        k.a = static_cast<float>(c0 * 67108864.0);
        k.bc = static_cast<float>(c0 * 67108864.0 * p.ct_growth_per_m2 * z2);
    }
    k.dt_units = static_cast<float>(p.dt / p.unit_mm);
    k.bd = static_cast<float>(p.dt_per_m2 * 1e-6 * p.unit_mm);
    return k;
}

// Curvature limit L of a pixel at depth z, an integer in 0..2^28. Each float operation is its own statement, so no
// contraction is possible even without -ffp-contract=off.
std::int64_t curvature_limit(const RobustConstants& k, float z) {
    const float two28 = 268435456.0f;
    float t = k.a;
    if (k.bc != 0.0f) {
        const float zz = z * z;
        const float grow = k.bc * zz;
        t = k.a + grow;
    }
    if (t >= two28) return std::int64_t{1} << 28;
    return static_cast<std::int64_t>(std::floor(t));
}

float depth_limit(const RobustConstants& k, float z) {
    if (k.bd == 0.0f) return k.dt_units;
    const float zz = z * z;
    const float grow = k.bd * zz;
    const float d = k.dt_units + grow;
    return d;
}

// qn: section 2's quantization of the normals (quantize_normals); k: robust_constants(p).
std::vector<std::uint8_t> robust_metric(const float* points, const QuantizedNormals& qn,
                                        const std::vector<std::uint8_t>& valid, std::int64_t width, std::int64_t height,
                                        const Params& p, const RobustConstants& k) {
    const std::int64_t two26 = std::int64_t{1} << 26;
    std::vector<std::uint8_t> fillable(valid.size(), 0);
    for (std::int64_t y = 0; y < height; ++y) {
        for (std::int64_t x = 0; x < width; ++x) {
            const auto i = static_cast<std::size_t>(y * width + x);
            if (valid[i] == 0) continue;
            const float z = points[3 * i + 2];
            const std::int64_t l = curvature_limit(k, z);
            const CurvatureSum curv = pair_curvature_sum(qn, valid, width, height, x, y, p.curvature_stride);
            const bool curvature_ok = curv.k >= 1 && curv.s >= curv.k * (two26 - l);
            const DepthSpread depth = depth_spread(points, valid, width, height, x, y);
            const bool depth_ok = depth.k >= 1 && depth.d <= depth_limit(k, z);
            fillable[i] = (curvature_ok && depth_ok) ? 1 : 0;
        }
    }
    return fillable;
}

// ---------------------------------------------------------------------------------------------------------------
// Labelling (contract sections 3..5).

// The 4-connected component of `start` among the texels with member[t] != 0, found by BFS; marks them in `seen`.
std::vector<std::size_t> component(const std::vector<std::uint8_t>& member, std::int64_t w, std::int64_t h,
                                   std::size_t start, std::vector<std::uint8_t>& seen) {
    std::vector<std::size_t> out;
    std::queue<std::size_t> todo;
    seen[start] = 1;
    todo.push(start);
    while (!todo.empty()) {
        const std::size_t t = todo.front();
        todo.pop();
        out.push_back(t);
        const auto x = static_cast<std::int64_t>(t) % w;
        const auto y = static_cast<std::int64_t>(t) / w;
        const std::array<std::pair<std::int64_t, std::int64_t>, 4> nbs{
            {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}}};
        for (const auto& [nx, ny] : nbs) {
            if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
            const auto n = static_cast<std::size_t>(ny * w + nx);
            if (member[n] == 0 || seen[n] != 0) continue;
            seen[n] = 1;
            todo.push(n);
        }
    }
    return out;
}

template <typename Fn>
void for_each_4_neighbour(std::size_t t, std::int64_t w, std::int64_t h, Fn&& fn) {
    const auto x = static_cast<std::int64_t>(t) % w;
    const auto y = static_cast<std::int64_t>(t) / w;
    if (x > 0) fn(t - 1);
    if (x + 1 < w) fn(t + 1);
    if (y > 0) fn(t - static_cast<std::size_t>(w));
    if (y + 1 < h) fn(t + static_cast<std::size_t>(w));
}

// Small images (contract section 4): each 4-connected component of B is labelled 1 + its smallest row-major index.
std::vector<std::uint32_t> fallback_labels(const std::vector<std::uint8_t>& fillable, std::int64_t width,
                                           std::int64_t height) {
    std::vector<std::uint32_t> labels(fillable.size(), 0);
    std::vector<std::uint8_t> seen(fillable.size(), 0);
    for (std::size_t i = 0; i < fillable.size(); ++i) {
        if (fillable[i] == 0 || seen[i] != 0) continue;
        const std::vector<std::size_t> comp = component(fillable, width, height, i, seen);
        const std::size_t smallest = *std::min_element(comp.begin(), comp.end());
        for (std::size_t t : comp) labels[t] = static_cast<std::uint32_t>(smallest + 1);
    }
    return labels;
}

// points: the frame's points (3 per pixel, row-major), read only for step 6c's depth test (edge_max_depth_step > 0 and
// edge_rounds >= 2); null for a mask, which segment_mask() refuses in that case.
std::vector<std::uint32_t> pyramid_labels(const std::vector<std::uint8_t>& fillable,
                                          const std::vector<std::uint8_t>& valid, const Plan& plan, bool label_edges,
                                          int edge_rounds, double edge_max_depth_step, const float* points) {
    const auto n = static_cast<std::size_t>(plan.n);
    const auto m = static_cast<std::size_t>(plan.m);
    const auto dim = [&](std::size_t k) { return plan.dims[k]; };

    // Section 3: threshold + mip. A child past the right or bottom border counts as not fillable.
    std::vector<std::vector<std::uint8_t>> fill(n + 1);
    fill[n] = fillable;
    for (std::size_t k = n - 1; k >= 1; --k) {
        const Dims d = dim(k);
        const Dims f = dim(k + 1);
        fill[k].assign(static_cast<std::size_t>(d.w * d.h), 0);
        for (std::int64_t y = 0; y < d.h; ++y) {
            for (std::int64_t x = 0; x < d.w; ++x) {
                bool all = true;
                for (std::int64_t cy = 2 * y; cy <= 2 * y + 1; ++cy) {
                    for (std::int64_t cx = 2 * x; cx <= 2 * x + 1; ++cx) {
                        if (cx >= f.w || cy >= f.h || fill[k + 1][static_cast<std::size_t>(cy * f.w + cx)] == 0) {
                            all = false;
                        }
                    }
                }
                fill[k][static_cast<std::size_t>(y * d.w + x)] = all ? 1 : 0;
            }
        }
    }

    std::vector<std::vector<std::uint32_t>> label(n + 1);
    const auto parent_label = [&](std::size_t k, std::int64_t x, std::int64_t y) -> std::uint32_t {
        const Dims pd = dim(k - 1);
        return label[k - 1][static_cast<std::size_t>((y / 2) * pd.w + (x / 2))];
    };
    // Label init of one level; `new_labels` says whether a fillable texel without a parent label gets a new one.
    const auto init_level = [&](std::size_t k, bool new_labels) {
        const Dims d = dim(k);
        label[k].assign(static_cast<std::size_t>(d.w * d.h), 0);
        for (std::int64_t y = 0; y < d.h; ++y) {
            for (std::int64_t x = 0; x < d.w; ++x) {
                const auto t = static_cast<std::size_t>(y * d.w + x);
                if (fill[k][t] == 0) continue;
                const std::uint32_t from_parent = k > 1 ? parent_label(k, x, y) : 0;
                if (from_parent != 0 || !new_labels) {
                    label[k][t] = from_parent;
                } else {
                    label[k][t] = static_cast<std::uint32_t>(plan.offset[k] + static_cast<std::uint64_t>(t) + 1);
                }
            }
        }
    };

    // Step 1.
    for (std::size_t k = 1; k <= m; ++k) init_level(k, true);

    // Step 2: each 4-connected component of fillable texels at level M carries its smallest label.
    {
        const Dims d = dim(m);
        std::vector<std::uint8_t> seen(fill[m].size(), 0);
        for (std::size_t t = 0; t < fill[m].size(); ++t) {
            if (fill[m][t] == 0 || seen[t] != 0) continue;
            const std::vector<std::size_t> comp = component(fill[m], d.w, d.h, t, seen);
            std::uint32_t smallest = label[m][comp.front()];
            for (std::size_t c : comp) smallest = std::min(smallest, label[m][c]);
            for (std::size_t c : comp) label[m][c] = smallest;
        }
    }

    // Step 3.
    for (std::size_t k = m + 1; k + 1 <= n; ++k) init_level(k, false);

    // Step 4, by the fixed point's definition: anchors are the texels whose label after step 3 is old.
    {
        const std::size_t k = n - 1;
        const Dims d = dim(k);
        const std::uint64_t old_max = plan.offset[static_cast<std::size_t>(plan.u) + 1];
        const std::vector<std::uint32_t>& lab = label[k];
        std::vector<std::uint8_t> anchored(lab.size(), 0);
        std::vector<std::uint8_t> free_fillable(lab.size(), 0);
        for (std::size_t t = 0; t < lab.size(); ++t) {
            anchored[t] = (lab[t] >= 1 && lab[t] <= old_max) ? 1 : 0;
            free_fillable[t] = (fill[k][t] != 0 && anchored[t] == 0) ? 1 : 0;
        }
        std::vector<std::uint32_t> result = lab;
        std::vector<std::uint8_t> seen(lab.size(), 0);
        for (std::size_t t = 0; t < lab.size(); ++t) {
            if (free_fillable[t] == 0 || seen[t] != 0) continue;
            const std::vector<std::size_t> comp = component(free_fillable, d.w, d.h, t, seen);
            std::uint32_t best = 0;
            const auto consider = [&best](std::uint32_t l) {
                if (l != 0 && (best == 0 || l < best)) best = l;
            };
            for (std::size_t c : comp) {
                consider(lab[c]);
                for_each_4_neighbour(c, d.w, d.h, [&](std::size_t nb) {
                    if (anchored[nb] != 0) consider(lab[nb]);
                });
            }
            for (std::size_t c : comp) result[c] = best;
        }
        label[k] = std::move(result);
    }

    // Step 5.
    init_level(n, false);

    // Step 6: one fill iteration at level N with exactly the contract's sequential schedule.
    std::vector<std::uint32_t>& lab = label[n];
    const Dims d = dim(n);
    const auto idx = [&](std::int64_t x, std::int64_t y) { return static_cast<std::size_t>(y * d.w + x); };
    const auto take = [&](std::size_t to, std::size_t from) {
        if (fill[n][to] != 0 && lab[to] == 0 && fill[n][from] != 0 && lab[from] != 0) lab[to] = lab[from];
    };
    // 6a: rows, left to right then right to left; each update is visible to the next pixel.
    for (std::int64_t y = 0; y < d.h; ++y) {
        for (std::int64_t x = 1; x < d.w; ++x) take(idx(x, y), idx(x - 1, y));
        for (std::int64_t x = d.w - 2; x >= 0; --x) take(idx(x, y), idx(x + 1, y));
    }
    // 6b: columns on the result of 6a, top to bottom then bottom to top.
    for (std::int64_t x = 0; x < d.w; ++x) {
        for (std::int64_t y = 1; y < d.h; ++y) take(idx(x, y), idx(x, y - 1));
        for (std::int64_t y = d.h - 2; y >= 0; --y) take(idx(x, y), idx(x, y + 1));
    }
    // 6c, rounds 1..E: round k reads the state after round k-1 only. A neighbour counts when it is labelled and
    // fillable, or was labelled by an earlier round (round 1: fillable ones only, the contract's step).
    // edge_max_depth_step c > 0: in rounds k >= 2 (never round 1) a neighbour q counts for p only when also
    // |z_p - z_q| <= s * z_p, s = (float)c computed once, z the points' float32 z.
    if (label_edges) {
        const bool depth_test = edge_max_depth_step > 0.0;
        const auto s = static_cast<float>(edge_max_depth_step);
        const auto z = [&](std::size_t t) { return points[3 * t + 2]; };
        // Each float operation its own statement: one correctly rounded float32 result each, no contraction.
        const auto same_surface = [&](std::size_t p, std::size_t q) {
            const float diff = z(p) - z(q);
            const float step = std::fabs(diff);  // exact
            const float limit = s * z(p);
            return step <= limit;
        };
        std::vector<int> labelled_in(lab.size(), 0);  // the round that labelled an edge pixel, 0: none
        for (int round = 1; round <= edge_rounds; ++round) {
            const std::vector<std::uint32_t> before = lab;
            for (std::size_t t = 0; t < lab.size(); ++t) {
                if (valid[t] == 0 || fill[n][t] != 0 || before[t] != 0) continue;
                std::uint32_t best = 0;
                for_each_4_neighbour(t, d.w, d.h, [&](std::size_t nb) {
                    const std::uint32_t l = before[nb];
                    bool counts = fill[n][nb] != 0 || (labelled_in[nb] != 0 && labelled_in[nb] < round);
                    if (counts && l != 0 && round >= 2 && depth_test) counts = same_surface(t, nb);
                    if (counts && l != 0 && (best == 0 || l < best)) best = l;
                });
                if (best != 0) {
                    lab[t] = best;
                    labelled_in[t] = round;
                }
            }
        }
    }
    return lab;
}

// ---------------------------------------------------------------------------------------------------------------
// The merge (docs/algorithm.md section 5b, step 6d).

// The tolerance at depth z: t = T0, or T0 + T2 * (z * z) in float32 when T2 != 0; tol = 2^30 if t >= 2^30, else
// floor(t). Each float operation is its own statement, so no contraction is possible even without -ffp-contract=off.
std::int64_t merge_tolerance(const MergeConstants& k, float z) {
    const float two30 = 1073741824.0f;
    float t = k.t0;
    if (k.t2 != 0.0f) {
        const float zz = z * z;
        const float grow = k.t2 * zz;
        t = k.t0 + grow;
    }
    if (t >= two30) return std::int64_t{1} << 30;
    return static_cast<std::int64_t>(std::floor(t));
}

// qn turned toward the camera: negated when qn . F(P) > 0 (F of section 8).
Vec3i toward_camera(const std::array<std::int64_t, 3>& qn, const float* p) {
    const Vec3i w = fixed_point(Vec3f{p[0], p[1], p[2]});
    Vec3i n{qn[0], qn[1], qn[2]};
    if (n[0] * w[0] + n[1] * w[1] + n[2] * w[2] > 0) {
        for (std::int64_t& c : n) c = -c;
    }
    return n;
}

enum class Boundary { flat, convex, concave, step };

// One crossing from pa (on the a side) to pb (on the b side): its kind (sections 5b and 10d).
Boundary crossing_kind(const float* points, const QuantizedNormals& qn, const MergeConstants& k, std::size_t pa,
                       std::size_t pb) {
    const float* a = points + 3 * pa;
    const float* b = points + 3 * pb;
    const float scale = std::ldexp(1.0f, k.e);
    Vec3i d{};
    for (std::size_t c = 0; c < 3; ++c) {
        d[c] = fixed_coordinate(b[c], scale) - fixed_coordinate(a[c], scale);
        if ((d[c] < 0 ? -d[c] : d[c]) > (std::int64_t{1} << 16)) return Boundary::step;
    }
    const Vec3i na = toward_camera(qn[pa], a);
    const Vec3i nb = toward_camera(qn[pb], b);
    const std::int64_t ha = na[0] * d[0] + na[1] * d[1] + na[2] * d[2];
    const std::int64_t hb = -(nb[0] * d[0] + nb[1] * d[1] + nb[2] * d[2]);
    const std::int64_t tol = merge_tolerance(k, std::min(a[2], b[2]));
    const bool one_above = ha > tol || hb > tol;    // a side clearly above the other's tangent plane
    const bool one_below = ha < -tol || hb < -tol;  // a side clearly below it
    if (!one_above) return one_below ? Boundary::convex : Boundary::flat;
    return one_below ? Boundary::step : Boundary::concave;
}

// Good: flat or convex (section 5b).
bool good_crossing(const float* points, const QuantizedNormals& qn, const MergeConstants& k, std::size_t pa,
                   std::size_t pb) {
    const Boundary kind = crossing_kind(points, qn, k, pa, pb);
    return kind == Boundary::flat || kind == Boundary::convex;
}

// The pixel a side of a crossing is measured at: from (sx, sy), up to r - 1 steps of `step` * (dx, dy) through
// pixels that exist and carry l.
std::size_t crossing_side(const std::vector<std::uint32_t>& lab, std::int64_t width, std::int64_t height,
                          std::int64_t r, std::int64_t sx, std::int64_t sy, std::int64_t dx, std::int64_t dy,
                          std::int64_t step, std::uint32_t l) {
    std::int64_t kk = 0;
    while (kk < r - 1) {
        const std::int64_t nx = sx + step * (kk + 1) * dx;
        const std::int64_t ny = sy + step * (kk + 1) * dy;
        if (nx < 0 || ny < 0 || nx >= width || ny >= height || lab[static_cast<std::size_t>(ny * width + nx)] != l) {
            break;
        }
        ++kk;
    }
    return static_cast<std::size_t>((sy + step * kk * dy) * width + (sx + step * kk * dx));
}

// Step 6d on level N's labels: count every pair's good and bad crossings, join the pairs that pass, and give every
// labelled pixel the smallest label of its group. Every labelled pixel is valid, so its point and qn are defined.
void merge_labels(std::vector<std::uint32_t>& lab, const float* points, const QuantizedNormals& qn, std::int64_t width,
                  std::int64_t height, const Params& p) {
    const MergeConstants k = merge_constants(p);
    const std::int64_t r = p.merge_reach;
    struct Counts {
        std::uint32_t good = 0;
        std::uint32_t bad = 0;
    };
    std::map<std::pair<std::uint32_t, std::uint32_t>, Counts> pairs;  // keyed (smaller label, larger label)
    const auto label_at = [&](std::int64_t x, std::int64_t y) { return lab[static_cast<std::size_t>(y * width + x)]; };
    const std::int64_t dirs[2][2] = {{1, 0}, {0, 1}};
    for (std::int64_t y = 0; y < height; ++y) {
        for (std::int64_t x = 0; x < width; ++x) {
            const std::uint32_t a = label_at(x, y);
            if (a == 0) continue;
            for (const auto& dir : dirs) {
                const std::int64_t dx = dir[0];
                const std::int64_t dy = dir[1];
                const std::int64_t qx = x + dx;
                const std::int64_t qy = y + dy;
                if (qx >= width || qy >= height) continue;
                const std::uint32_t b = label_at(qx, qy);
                if (b == 0 || b == a) continue;
                // The largest k in 0..r-1 with the k pixels beyond the side's own pixel all existing and carrying
                // its label: back from p on the a side, on from q on the b side.
                const std::size_t pa = crossing_side(lab, width, height, r, x, y, dx, dy, -1, a);
                const std::size_t pb = crossing_side(lab, width, height, r, qx, qy, dx, dy, +1, b);
                Counts& counts = pairs[{std::min(a, b), std::max(a, b)}];
                if (good_crossing(points, qn, k, pa, pb)) {
                    ++counts.good;
                } else {
                    ++counts.bad;
                }
            }
        }
    }

    // Union-find over the labels of the pairs that join; a root is always the smallest label of its group.
    std::map<std::uint32_t, std::uint32_t> parent;
    const auto find = [&parent](std::uint32_t l) {
        std::uint32_t root = l;
        while (parent.at(root) != root) root = parent.at(root);
        while (parent.at(l) != root) l = std::exchange(parent.at(l), root);  // path compression
        return root;
    };
    for (const auto& [key, counts] : pairs) {
        const std::uint64_t total = std::uint64_t{counts.good} + std::uint64_t{counts.bad};
        const bool joins = total >= static_cast<std::uint64_t>(p.merge_min_crossings) &&
                           std::uint64_t{counts.bad} * 256 <= static_cast<std::uint64_t>(k.s) * total;
        if (!joins) continue;
        parent.try_emplace(key.first, key.first);
        parent.try_emplace(key.second, key.second);
        const std::uint32_t ra = find(key.first);
        const std::uint32_t rb = find(key.second);
        if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
    if (parent.empty()) return;
    std::map<std::uint32_t, std::uint32_t> group_of;
    for (const auto& entry : parent) group_of[entry.first] = find(entry.first);
    for (std::uint32_t& l : lab) {
        if (l == 0) continue;
        const auto it = group_of.find(l);
        if (it != group_of.end()) l = it->second;
    }
}

// Step 7 and the output fields shared by segment() and segment_mask().
void finish(std::vector<std::uint32_t> raw, const Params& p, Output& out) {
    std::vector<std::uint32_t> distinct;
    for (std::uint32_t l : raw) {
        // Skipping repeats of the previous entry only shrinks what is sorted (labels come in long runs).
        if (l != 0 && (distinct.empty() || distinct.back() != l)) distinct.push_back(l);
    }
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    out.segment_count = static_cast<std::uint32_t>(distinct.size());
    out.labels = raw;
    if (p.compact) {
        for (std::uint32_t& l : out.labels) {
            if (l == 0) continue;
            const auto pos = std::lower_bound(distinct.begin(), distinct.end(), l) - distinct.begin();
            l = static_cast<std::uint32_t>(pos + 1);
        }
    }
    out.raw_labels = std::move(raw);
}

// Section 10: per segment, in order of raw label (the compacted order), over the labelled pixels. points and
// normals are null for a mask.
std::vector<Segment> segment_statistics(const Output& out, const float* points, const float* normals, int width,
                                        const Params& p) {
    const int shift = point_shift(p.unit_mm);
    const float scale = std::ldexp(1.0f, shift);
    const float limit = 2147483520.0f;  // 2^31 - 128, the largest float below 2^31
    std::map<std::uint32_t, Segment> by_raw;
    for (std::size_t i = 0; i < out.raw_labels.size(); ++i) {
        const std::uint32_t raw = out.raw_labels[i];
        if (raw == 0) continue;
        const int x = static_cast<int>(i % static_cast<std::size_t>(width));
        const int y = static_cast<int>(i / static_cast<std::size_t>(width));
        auto [it, added] = by_raw.try_emplace(raw);
        Segment& s = it->second;
        if (added) {
            s.label = out.labels[i];
            s.x_min = s.x_max = x;
            s.y_min = s.y_max = y;
            s.point_shift = shift;
        }
        ++s.pixel_count;
        s.x_min = std::min(s.x_min, x);
        s.x_max = std::max(s.x_max, x);
        s.y_min = std::min(s.y_min, y);
        s.y_max = std::max(s.y_max, y);
        if (points == nullptr || out.fillable[i] == 0) continue;
        const bool first = s.fillable_count == 0;
        ++s.fillable_count;
        std::int64_t q[3];
        for (std::size_t c = 0; c < 3; ++c) {
            const float v = std::clamp(points[3 * i + c] * scale, -limit, limit);
            q[c] = static_cast<std::int64_t>(std::nearbyint(v));
            s.point_sum[c] += q[c];
            s.normal_sum[c] += quantize(normals[3 * i + c]);
        }
        std::size_t product = 0;
        for (std::size_t a = 0; a < 3; ++a) {
            for (std::size_t b = a; b < 3; ++b) s.product_sum[product++] += static_cast<Int128>(q[a] * q[b]);
        }
        s.z_fixed_min = first ? q[2] : std::min(s.z_fixed_min, q[2]);
        s.z_fixed_max = first ? q[2] : std::max(s.z_fixed_max, q[2]);
    }
    std::vector<Segment> segments;
    segments.reserve(by_raw.size());
    for (const auto& entry : by_raw) segments.push_back(entry.second);
    return segments;
}

// Section 10d: every crossing of the final labels between two segments, counted for the pair of their output
// labels, by kind for a cloud (points and qn null for a mask).
std::vector<Edge> segment_graph(const Output& out, const float* points, const QuantizedNormals* qn, int width,
                                int height, const Params& p) {
    const MergeConstants k = merge_constants(p);
    const std::vector<std::uint32_t>& raw = out.raw_labels;
    std::map<std::pair<std::uint32_t, std::uint32_t>, Edge> pairs;
    const std::int64_t w = width;
    const std::int64_t h = height;
    const std::int64_t dirs[2][2] = {{1, 0}, {0, 1}};
    for (std::int64_t y = 0; y < h; ++y) {
        for (std::int64_t x = 0; x < w; ++x) {
            const auto i = static_cast<std::size_t>(y * w + x);
            if (raw[i] == 0) continue;
            for (const auto& dir : dirs) {
                const std::int64_t qx = x + dir[0];
                const std::int64_t qy = y + dir[1];
                if (qx >= w || qy >= h) continue;
                const auto j = static_cast<std::size_t>(qy * w + qx);
                if (raw[j] == 0 || raw[j] == raw[i]) continue;
                const std::uint32_t la = std::min(out.labels[i], out.labels[j]);
                const std::uint32_t lb = std::max(out.labels[i], out.labels[j]);
                Edge& e = pairs[{la, lb}];
                e.a = la;
                e.b = lb;
                ++e.length;
                if (points == nullptr) continue;
                const std::size_t pa = crossing_side(raw, w, h, p.merge_reach, x, y, dir[0], dir[1], -1, raw[i]);
                const std::size_t pb = crossing_side(raw, w, h, p.merge_reach, qx, qy, dir[0], dir[1], +1, raw[j]);
                switch (crossing_kind(points, *qn, k, pa, pb)) {
                    case Boundary::flat:
                        ++e.flat;
                        break;
                    case Boundary::convex:
                        ++e.convex;
                        break;
                    case Boundary::concave:
                        ++e.concave;
                        break;
                    case Boundary::step:
                        ++e.step;
                        break;
                }
            }
        }
    }
    std::vector<Edge> graph;
    graph.reserve(pairs.size());
    for (const auto& entry : pairs) graph.push_back(entry.second);
    return graph;
}

Output failure(std::string why) {
    Output out;
    out.ok = false;
    out.error = std::move(why);
    return out;
}

// Section 1b: float32 bit fields.
std::uint32_t exponent_field(float f) {
    return (std::bit_cast<std::uint32_t>(f) >> 23) & 0xFFu;
}

// Section 1b: a result whose exponent field is 0 becomes a zero of its sign (its bits AND 0x80000000).
float zero_if_subnormal(float f) {
    return exponent_field(f) == 0 ? std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) & 0x80000000u) : f;
}

// Section 1b: the sample's zs, or false when the pixel has no data. Bytes are read with memcpy (rows may be at any
// alignment); a u16 sample is in the host's byte order.
bool depth_sample(const unsigned char* at, DepthFormat format, float& zs) {
    if (format == DepthFormat::u16) {
        std::uint16_t d = 0;
        std::memcpy(&d, at, sizeof d);
        zs = static_cast<float>(d);  // exact
        return d != 0;
    }
    std::uint32_t bits = 0;
    std::memcpy(&bits, at, sizeof bits);
    const std::uint32_t exponent = (bits >> 23) & 0xFFu;
    zs = std::bit_cast<float>(bits);
    return (bits & 0x80000000u) == 0 && exponent != 0 && exponent != 255;
}

}  // namespace

DepthPoints depth_to_points(const DepthInput& depth, double unit_mm) {
    DepthPoints out;
    auto fail = [&out](std::string why) {
        out.ok = false;
        out.error = std::move(why);
        return out;
    };
    if (depth.width < 1 || depth.height < 1) return fail("depth width and height must be >= 1");
    if (depth.format != DepthFormat::u16 && depth.format != DepthFormat::f32) {
        return fail("depth format must be u16 or f32");
    }
    if (depth.samples == nullptr) return fail("depth samples must not be null");
    const std::size_t sample_bytes = depth.format == DepthFormat::u16 ? 2 : 4;
    const std::size_t packed = static_cast<std::size_t>(depth.width) * sample_bytes;
    const std::size_t step = depth.row_step_bytes == 0 ? packed : depth.row_step_bytes;
    if (step < packed) {
        return fail("row_step_bytes must be 0 or >= width * sample size (" + std::to_string(packed) + ")");
    }
    if (!std::isfinite(unit_mm) || unit_mm <= 0.0) return fail("unit_mm must be finite and > 0");
    // The rejections of section 1b, in its order.
    const double m = depth.metres_per_unit;
    if (!std::isfinite(m) || m <= 0.0) return fail("metres_per_unit must be finite and > 0");
    if (!std::isfinite(depth.fx) || depth.fx <= 0.0) return fail("fx must be finite and > 0");
    if (!std::isfinite(depth.fy) || depth.fy <= 0.0) return fail("fy must be finite and > 0");
    if (!std::isfinite(depth.cx)) return fail("cx must be finite");
    if (!std::isfinite(depth.cy)) return fail("cy must be finite");
    // Host constants: double, in the order written, then float32.
    const float s = static_cast<float>((m * 1000.0) / unit_mm);
    // s a finite float32 > 0 and >= 2^-126: sign clear, exponent field neither 0 nor 255.
    if ((std::bit_cast<std::uint32_t>(s) & 0x80000000u) != 0 || exponent_field(s) == 0 || exponent_field(s) == 255) {
        return fail("scale s = (float)((m * 1000) / unit_mm) must be a finite float32 >= 2^-126 (a normal)");
    }
    std::vector<float> ku(static_cast<std::size_t>(depth.width));
    std::vector<float> kv(static_cast<std::size_t>(depth.height));
    for (int u = 0; u < depth.width; ++u) {
        ku[static_cast<std::size_t>(u)] = static_cast<float>((static_cast<double>(u) - depth.cx) / depth.fx);
    }
    for (int v = 0; v < depth.height; ++v) {
        kv[static_cast<std::size_t>(v)] = static_cast<float>((static_cast<double>(v) - depth.cy) / depth.fy);
    }

    const float no_data = std::bit_cast<float>(std::uint32_t{0x7fc00000u});
    const auto* base = static_cast<const unsigned char*>(depth.samples);
    const auto w = static_cast<std::size_t>(depth.width);
    const auto h = static_cast<std::size_t>(depth.height);
    out.points.assign(3 * w * h, no_data);
    for (std::size_t v = 0; v < h; ++v) {
        const unsigned char* row = base + v * step;
        for (std::size_t u = 0; u < w; ++u) {
            float zs = 0.0f;
            if (!depth_sample(row + u * sample_bytes, depth.format, zs)) continue;
            const float z = zs * s;
            if (exponent_field(z) == 0 || exponent_field(z) == 255) continue;  // underflow or overflow: no data
            float* p = out.points.data() + 3 * (v * w + u);
            p[0] = zero_if_subnormal(z * ku[u]);
            p[1] = zero_if_subnormal(z * kv[v]);
            p[2] = z;
        }
    }
    return out;
}

namespace {

// points and normals are what the merge (step 6d) reads, and points what step 6c's depth test (edge_max_depth_step)
// reads; null for a mask, which segment_mask() refuses to merge or to give that test.
Output label_from_mask(std::vector<std::uint8_t> fillable, const std::vector<std::uint8_t>& valid, int width,
                       int height, const Params& p, const Plan& plan, const float* points = nullptr,
                       const float* normals = nullptr) {
    Output out;
    std::vector<std::uint32_t> raw = plan.fallback ? fallback_labels(fillable, width, height)
                                                   : pyramid_labels(fillable, valid, plan, p.label_edges, p.edge_rounds,
                                                                    p.edge_max_depth_step, points);
    // Step 6d, after 6c (or 6b) and before compaction; not in the small-image fallback.
    if (p.merge && !plan.fallback) merge_labels(raw, points, quantize_normals(normals, valid), width, height, p);
    out.fillable = std::move(fillable);
    finish(std::move(raw), p, out);
    return out;
}

}  // namespace

std::vector<float> estimate_normals(const float* points, int width, int height, int radius) {
    if (width < 1 || height < 1 || radius < 1) return {};
    const auto count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<float> normals(3 * count, 0.0f);
    for (std::int64_t y = 0; y < height; ++y) {
        for (std::int64_t x = 0; x < width; ++x) {
            const Vec3i q = pixel_normal(points, width, height, x, y, radius);
            const auto i = static_cast<std::size_t>(y * width + x);
            for (std::size_t c = 0; c < 3; ++c) {
                // q / 2^13 is exact: |q| <= 2^13 fits the float significand and the scale is a power of two.
                normals[3 * i + c] = static_cast<float>(q[c]) / 8192.0f;
            }
        }
    }
    return normals;
}

std::vector<float> estimate_robust_normals(const float* points, int width, int height, int radius, int window,
                                           double unit_mm) {
    if (width < 1 || height < 1 || radius < 1 || window < 1 || window > 7) return {};
    if (!std::isfinite(unit_mm) || unit_mm <= 0.0) return {};
    return normals_from_q(robust_normals_q(points, width, height, radius, window, unit_mm));
}

namespace {

// Section 2c's curvature gate: G = rint(g * 256), round half to even (std::nearbyint in the default rounding mode),
// an integer 0..256.
std::int64_t curvature_gate(const Params& p) {
    return static_cast<std::int64_t>(std::nearbyint(p.color_edge_curvature_share * 256.0));
}

// Section 2c: B cleared at every colour edge (both pixels of an axis in the image, their colours more than T apart)
// that counts. With G = 0 every colour edge counts. With G > 0 (robust metric only) a colour edge counts only where
// it would fail section 2b's curvature test with the limit Lg = floor(L * G / 256) in place of L: the same L (from
// the pixel's own depth), the same pairs at curvature_stride over the same quantized normals qn as the metric, with
// k = robust_constants(params).
void clear_color_edges(std::vector<std::uint8_t>& fillable, const std::uint8_t* color, int width, int height,
                       const Params& params, const float* points, const std::vector<std::uint8_t>& valid,
                       const QuantizedNormals& qn, const RobustConstants& k) {
    const std::int64_t w = width;
    const std::int64_t h = height;
    const std::int64_t s = params.color_edge_stride;
    const std::int64_t gate = curvature_gate(params);
    const std::int64_t two26 = std::int64_t{1} << 26;
    const auto differ = [&](std::int64_t xa, std::int64_t ya, std::int64_t xb, std::int64_t yb) {
        const std::uint8_t* a = color + 3 * (ya * w + xa);
        const std::uint8_t* b = color + 3 * (yb * w + xb);
        std::int64_t d = 0;
        for (int c = 0; c < 3; ++c) d += std::abs(std::int64_t(a[c]) - std::int64_t(b[c]));
        return d > params.color_edge_threshold;
    };
    // Whether colour edge pixel (x, y) counts. Only asked of fillable pixels (so valid ones, with a finite depth > 0):
    // clearing a pixel whose B is already 0 changes nothing.
    const auto counts = [&](std::int64_t x, std::int64_t y) {
        if (gate == 0) return true;
        const auto i = static_cast<std::size_t>(y * w + x);
        const std::int64_t l = curvature_limit(k, points[3 * i + 2]);
        const std::int64_t lg = (l >> 8) * gate + (((l & 255) * gate) >> 8);  // floor(L * G / 256), exact
        const CurvatureSum curv = pair_curvature_sum(qn, valid, w, h, x, y, params.curvature_stride);
        return curv.k >= 1 && curv.s < curv.k * (two26 - lg);
    };
    for (std::int64_t y = 0; y < h; ++y) {
        for (std::int64_t x = 0; x < w; ++x) {
            const auto i = static_cast<std::size_t>(y * w + x);
            if (fillable[i] == 0) continue;
            const bool along_x = x - s >= 0 && x + s <= w - 1 && differ(x - s, y, x + s, y);
            const bool along_y = y - s >= 0 && y + s <= h - 1 && differ(x, y - s, x, y + s);
            if ((along_x || along_y) && counts(x, y)) fillable[i] = 0;
        }
    }
}

}  // namespace

Output segment(const float* points, const float* normals, int width, int height, const Params& params,
               const std::uint8_t* color) {
    if (std::string why = check_params(width, height, params); !why.empty()) return failure(std::move(why));
    if (normals == nullptr && params.normal_radius < 1) return failure("normal_radius must be >= 1");
    Plan plan;
    if (std::string why = make_plan(width, height, params, plan); !why.empty()) return failure(std::move(why));

    const auto count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    const bool robust = params.metric == Metric::robust;
    std::vector<float> used;
    if (normals != nullptr) {
        used.assign(normals, normals + 3 * count);
    } else if (robust) {
        used = normals_from_q(
            robust_normals_q(points, width, height, params.normal_radius, params.normal_window, params.unit_mm));
    } else {
        used = estimate_normals(points, width, height, params.normal_radius);
    }
    std::vector<std::uint8_t> valid(count, 0);
    for (std::size_t i = 0; i < count; ++i) {
        valid[i] = (point_valid(points + 3 * i) && normal_valid(used.data() + 3 * i)) ? 1 : 0;
    }
    const QuantizedNormals qn = quantize_normals(used.data(), valid);
    const RobustConstants k = robust_constants(params);
    std::vector<std::uint8_t> fillable = robust ? robust_metric(points, qn, valid, width, height, params, k)
                                                : metric(points, qn, valid, width, height, params);
    if (color != nullptr) clear_color_edges(fillable, color, width, height, params, points, valid, qn, k);
    Output out = label_from_mask(std::move(fillable), valid, width, height, params, plan, points, used.data());
    out.segments = segment_statistics(out, points, used.data(), width, params);
    out.graph = segment_graph(out, points, &qn, width, height, params);
    out.normals = std::move(used);
    return out;
}

Output segment_mask(const std::uint8_t* fillable, const std::uint8_t* valid, int width, int height,
                    const Params& params) {
    if (std::string why = check_params(width, height, params); !why.empty()) return failure(std::move(why));
    // Section 5b: the merge needs points and normals, which a mask does not have.
    if (params.merge) return failure("merge needs points and normals: a mask cannot be merged");
    // Section 5 step 6c: the depth test of edge_max_depth_step needs depths, which a mask does not have.
    if (params.label_edges && params.edge_rounds >= 2 && params.edge_max_depth_step > 0.0) {
        return failure("edge_max_depth_step > 0 with edge_rounds >= 2 needs depths: a mask has none");
    }
    Plan plan;
    if (std::string why = make_plan(width, height, params, plan); !why.empty()) return failure(std::move(why));

    const auto count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<std::uint8_t> mask(count, 0);
    std::vector<std::uint8_t> valid_mask(count, 1);
    for (std::size_t i = 0; i < count; ++i) {
        mask[i] = fillable[i] != 0 ? 1 : 0;
        if (valid != nullptr) valid_mask[i] = valid[i] != 0 ? 1 : 0;
    }
    Output out = label_from_mask(std::move(mask), valid_mask, width, height, params, plan);
    out.segments = segment_statistics(out, nullptr, nullptr, width, params);
    out.graph = segment_graph(out, nullptr, nullptr, width, height, params);
    return out;
}

Output segment_depth(const DepthInput& depth, int width, int height, const Params& params, const std::uint8_t* color) {
    if (depth.width != width || depth.height != height) {
        return failure("the depth image is " + std::to_string(depth.width) + " x " + std::to_string(depth.height) +
                       " but width x height is " + std::to_string(width) + " x " + std::to_string(height));
    }
    // Everything that segment() would reject is rejected before the points are made.
    if (std::string why = check_params(width, height, params); !why.empty()) return failure(std::move(why));
    if (params.normal_radius < 1) return failure("normal_radius must be >= 1");
    Plan plan;
    if (std::string why = make_plan(width, height, params, plan); !why.empty()) return failure(std::move(why));
    DepthPoints points = depth_to_points(depth, params.unit_mm);
    if (!points.ok) return failure(std::move(points.error));
    return segment(points.points.data(), nullptr, width, height, params, color);
}

}  // namespace pyrseg_ref
