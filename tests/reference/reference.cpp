// The oracle, written from shared/spec/algorithm-contract.md and docs/algorithm.md only. It favours the most literal
// reading of the text over speed: one std::vector per pyramid level, BFS for the fixed points of steps 2 and 4 (by
// their definition, not by iterating the propagation rule), literal sequential sweeps for step 6. Every algorithm is
// linear in the pixel count (up to a log factor in compaction), so full camera frames stay cheap.
#include "reference/reference.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
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

std::string check_params(int width, int height, const Params& p) {
    if (width < 1 || height < 1) return "width and height must be >= 1";
    if (!std::isfinite(p.ct) || p.ct < 0.0) return "ct must be finite and >= 0";
    if (std::isnan(p.dt) || p.dt < 0.0) return "dt must be >= 0 (+inf allowed)";
    if (!std::isfinite(p.unit_mm) || p.unit_mm <= 0.0) return "unit_mm must be finite and > 0";
    if (p.bridge_levels < 1) return "bridge_levels must be >= 1";
    if (p.unjoinable_gap < 1) return "unjoinable_gap must be >= 1";
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

    const Vec3i fu = fixed_point(u);
    const Vec3i fv = fixed_point(v);
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

std::vector<std::uint8_t> metric(const float* points, const float* normals, const std::vector<std::uint8_t>& valid,
                                 std::int64_t width, std::int64_t height, const Params& p) {
    const std::int64_t tc = curvature_threshold(p.ct);
    const auto dt_units = static_cast<float>(p.dt / p.unit_mm);
    const std::size_t count = valid.size();
    std::vector<std::array<std::int64_t, 3>> qn(count, {0, 0, 0});
    for (std::size_t i = 0; i < count; ++i) {
        if (valid[i] == 0) continue;
        for (std::size_t c = 0; c < 3; ++c) qn[i][c] = quantize(normals[3 * i + c]);
    }
    std::vector<std::uint8_t> fillable(count, 0);
    for (std::int64_t y = 0; y < height; ++y) {
        for (std::int64_t x = 0; x < width; ++x) {
            const auto i = static_cast<std::size_t>(y * width + x);
            if (valid[i] == 0) continue;
            const float zi = points[3 * i + 2];
            std::int64_t k = 0;
            std::int64_t s = 0;
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
                    s += qn[i][0] * qn[j][0] + qn[i][1] * qn[j][1] + qn[i][2] * qn[j][2];
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
            const float d = dd_max - dd_min;
            fillable[i] = (k >= 1 && s >= k * tc && d <= dt_units) ? 1 : 0;
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

std::vector<std::uint32_t> pyramid_labels(const std::vector<std::uint8_t>& fillable,
                                          const std::vector<std::uint8_t>& valid, const Plan& plan, bool label_edges) {
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
    // 6c: reads the state after 6b only, so edge labels never spread to further edge pixels.
    if (label_edges) {
        const std::vector<std::uint32_t> after_b = lab;
        for (std::size_t t = 0; t < lab.size(); ++t) {
            if (valid[t] == 0 || fill[n][t] != 0 || after_b[t] != 0) continue;
            std::uint32_t best = 0;
            for_each_4_neighbour(t, d.w, d.h, [&](std::size_t nb) {
                const std::uint32_t l = after_b[nb];
                if (fill[n][nb] != 0 && l != 0 && (best == 0 || l < best)) best = l;
            });
            lab[t] = best;
        }
    }
    return lab;
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

// Section 10. The fixed point's exponent: the smallest e (within -126..127) with 2^e >= 16 * unit_mm.
int point_shift(double unit_mm) {
    int e = -126;
    while (e < 127 && std::ldexp(1.0, e) < 16.0 * unit_mm) ++e;
    return e;
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
        if (points == nullptr) continue;
        for (std::size_t c = 0; c < 3; ++c) {
            const float v = std::clamp(points[3 * i + c] * scale, -limit, limit);
            s.point_sum[c] += static_cast<std::int64_t>(std::nearbyint(v));
            s.normal_sum[c] += quantize(normals[3 * i + c]);
        }
    }
    std::vector<Segment> segments;
    segments.reserve(by_raw.size());
    for (const auto& entry : by_raw) segments.push_back(entry.second);
    return segments;
}

Output failure(std::string why) {
    Output out;
    out.ok = false;
    out.error = std::move(why);
    return out;
}

Output label_from_mask(std::vector<std::uint8_t> fillable, const std::vector<std::uint8_t>& valid, int width,
                       int height, const Params& p, const Plan& plan) {
    Output out;
    std::vector<std::uint32_t> raw =
        plan.fallback ? fallback_labels(fillable, width, height) : pyramid_labels(fillable, valid, plan, p.label_edges);
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

Output segment(const float* points, const float* normals, int width, int height, const Params& params) {
    if (std::string why = check_params(width, height, params); !why.empty()) return failure(std::move(why));
    if (normals == nullptr && params.normal_radius < 1) return failure("normal_radius must be >= 1");
    Plan plan;
    if (std::string why = make_plan(width, height, params, plan); !why.empty()) return failure(std::move(why));

    const auto count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<float> used = normals != nullptr ? std::vector<float>(normals, normals + 3 * count)
                                                 : estimate_normals(points, width, height, params.normal_radius);
    std::vector<std::uint8_t> valid(count, 0);
    for (std::size_t i = 0; i < count; ++i) {
        valid[i] = (point_valid(points + 3 * i) && normal_valid(used.data() + 3 * i)) ? 1 : 0;
    }
    std::vector<std::uint8_t> fillable = metric(points, used.data(), valid, width, height, params);
    Output out = label_from_mask(std::move(fillable), valid, width, height, params, plan);
    out.segments = segment_statistics(out, points, used.data(), width, params);
    out.normals = std::move(used);
    return out;
}

Output segment_mask(const std::uint8_t* fillable, const std::uint8_t* valid, int width, int height,
                    const Params& params) {
    if (std::string why = check_params(width, height, params); !why.empty()) return failure(std::move(why));
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
    return out;
}

}  // namespace pyrseg_ref
