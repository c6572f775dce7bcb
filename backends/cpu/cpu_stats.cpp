// The per-segment statistics pass (docs/algorithm.md section 10) on the CPU: rows in parallel, each stretch of equal
// labels summed in native 64-bit and 128-bit integers (by the target's stats_sums in vectors, its pixels that are
// not fillable masked out, whatever the points' layout) and added to its slot's words at once, with the shared
// dialect's word arithmetic (shaders/pyr_stats.h: pyr_stats_flush), so the words are those of every other backend.
// Sums of integers do not depend on how they are grouped, so summing a stretch in wide native integers instead of
// the shader's 32-bit words changes nothing but the time. PYRSEG_CPU_SIMD=scalar runs the shared row function
// itself (pyr_stats_row_run), which the conformance suite compares with this one.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "backends/cpu/cpu_executor.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__aarch64__)
#include <arm_neon.h>
#endif

namespace pyrseg::cpu {
namespace {

using std::size_t;
using std::uint32_t;

__extension__ typedef __int128 Int128;
__extension__ typedef unsigned __int128 UInt128;

// rint(clamp(v * scale)) of pyr_stats_fixed in the current rounding mode (round half to even by default), as
// std::nearbyint gives it, without its floating-point environment save and restore.
inline std::int32_t fixed(float v, float scale) {
    float scaled = v * scale;
    scaled = scaled < -PYR_STATS_POINT_LIMIT ? -PYR_STATS_POINT_LIMIT
                                             : (scaled > PYR_STATS_POINT_LIMIT ? PYR_STATS_POINT_LIMIT : scaled);
#if defined(__SSE2__)
    return _mm_cvtss_si32(_mm_set_ss(scaled));
#else
    return static_cast<std::int32_t>(std::nearbyint(scaled));
#endif
}

// One stretch of a row whose pixels have the same slot: its count, x range and sums.
struct Stretch {
    uint32_t slot = 0xffffffffu;
    uint32_t raw = 0;
    uint32_t count = 0;
    uint32_t x_min = 0;
    uint32_t x_max = 0;
    simd::StatsSums sums;
};

// The fillable pixels of [x_begin, x_end) of row y (mask: the row's mask bytes), one at a time, into s.
void add_pixels(const PassContext& c, uint32_t width, uint32_t y, const std::uint8_t* mask, uint32_t x_begin,
                uint32_t x_end, float scale, simd::StatsSums& s) {
    for (uint32_t x = x_begin; x < x_end; ++x) {
        if ((mask[x] & PYR_MASK_FILLABLE) == 0u) continue;
        ++s.fillable;
        const float* p = c.points + size_t(y) * c.row_floats + size_t(x) * c.point_floats;
        const std::int64_t q[3] = {fixed(p[0], scale), fixed(p[1], scale), fixed(p[2], scale)};
        const size_t pixel_index = size_t(y) * width + x;
        for (int k = 0; k < 3; ++k) {
            s.point[k] += q[k];
            s.normal[k] += quant_component(c.quant, pixel_index, k);
        }
        const auto z = static_cast<std::int32_t>(q[2]);
        s.z_min = z < s.z_min ? z : s.z_min;
        s.z_max = z > s.z_max ? z : s.z_max;
        size_t product = 0;
        for (size_t a = 0; a < 3; ++a) {
            for (size_t b = a; b < 3; ++b) s.product[product++] += Int128(q[a] * q[b]);
        }
    }
}

// The fillable pixels of [x_begin, x_end) of row y: in vectors where the target has them, else one at a time.
void add_stretch(const PassContext& c, const simd::VectorRows* rows, uint32_t width, uint32_t y,
                 const std::uint8_t* mask, uint32_t x_begin, uint32_t x_end, float scale, simd::StatsSums& s) {
    uint32_t x = x_begin;
    while (x < x_end && rows != nullptr) {
        x += rows->stats_sums(c.points + size_t(y) * c.row_floats + size_t(x) * c.point_floats, c.point_floats,
                              c.quant + kQuantWords * (size_t(y) * width + x), mask + x, x_end - x, scale, s);
        if (x == x_end) return;
        // A vector with a coordinate of 2^26 or more: pixel by pixel.
        const uint32_t next = std::min(x_end, x + 16u);
        add_pixels(c, width, y, mask, x, next, scale, s);
        x = next;
    }
    add_pixels(c, width, y, mask, x, x_end, scale, s);
}

pixel::PyrSum64 sum64(std::int64_t v) {
    const auto u = static_cast<std::uint64_t>(v);
    return pixel::pyr_sum64(uint32_t(u), uint32_t(u >> 32));
}

pixel::PyrSum96 sum96(Int128 v) {
    const auto u = static_cast<UInt128>(v);
    pixel::PyrSum96 s{};
    s.lo = uint32_t(u);
    s.mid = uint32_t(u >> 32);
    s.hi = uint32_t(u >> 64);
    return s;
}

void flush(const PassContext& c, const Stretch& s, uint32_t y, uint32_t with_points) {
    pixel::PyrStatsRun r = pixel::pyr_stats_run_start(s.slot, s.raw, s.x_min);
    r.count = s.count;
    r.fillable = uint32_t(s.sums.fillable);
    r.x_max = s.x_max;
    if (with_points != 0u) {
        r.px = sum64(s.sums.point[0]);
        r.py = sum64(s.sums.point[1]);
        r.pz = sum64(s.sums.point[2]);
        r.nx = sum64(s.sums.normal[0]);
        r.ny = sum64(s.sums.normal[1]);
        r.nz = sum64(s.sums.normal[2]);
        r.z_key_min = uint32_t(s.sums.z_min) ^ 0x80000000u;
        r.z_key_max = uint32_t(s.sums.z_max) ^ 0x80000000u;
        pixel::PyrSum96* products[6] = {&r.xx, &r.xy, &r.xz, &r.yy, &r.yz, &r.zz};
        for (size_t i = 0; i < 6; ++i) *products[i] = sum96(s.sums.product[i]);
    }
    pixel::pyr_stats_flush(c, 0u, r, y, with_points);
}

// Row y in runs of equal raw labels. A row crosses few segments but often crosses each many times (edge bands, the
// merge's joined parts), so the row keeps the stretches of its last few slots open and adds each to its slot's words
// once, at the end of the row or when a newer slot needs its place: the words are sums, maxima and minima, which
// do not depend on how the row's pixels are grouped.
void stats_row(const PassContext& c, const simd::VectorRows* rows, const PyrLevel& full, uint32_t y,
               uint32_t with_points, float scale, uint32_t slots) {
    constexpr size_t kOpen = 8;
    const uint32_t* labels = c.labels + full.offset + size_t(y) * full.width;
    Stretch open[kOpen];
    size_t used = 0;
    size_t last = 0;
    for (uint32_t x = 0; x < full.width;) {
        const uint32_t raw = labels[x];
        uint32_t end = x + 1;
        while (end < full.width && labels[end] == raw) ++end;
        const uint32_t slot = raw != 0u ? c.lut[raw] - 1u : 0xffffffffu;
        if (slot < slots) {
            size_t k = last < used && open[last].slot == slot ? last : 0;
            while (k < used && open[k].slot != slot) ++k;
            if (k == used) {
                if (used == kOpen) {
                    flush(c, open[0], y, with_points);
                    for (size_t j = 1; j < kOpen; ++j) open[j - 1] = open[j];
                    --used;
                    k = used;
                }
                open[k] = Stretch{};
                open[k].slot = slot;
                open[k].x_min = x;
                ++used;
            }
            Stretch& s = open[k];
            s.raw = std::max(s.raw, raw);
            s.count += end - x;
            s.x_max = end - 1;
            if (with_points != 0u) {
                // The geometry's sums run over the fillable pixels only.
                add_stretch(c, rows, full.width, y, c.mask + full.offset + size_t(y) * full.width, x, end, scale,
                            s.sums);
            }
            last = k;
        }
        x = end;
    }
    for (size_t k = 0; k < used; ++k) flush(c, open[k], y, with_points);
}

}  // namespace

void CpuExecutor::segment_stats() {
    std::fill_n(stats_.begin(), std::min(stats_.size(), size_t(segment_count_) * PYR_STATS_WORDS), 0u);
    const PassContext c = context();
    const PyrLevel full = plan_.full();
    const uint32_t with_points = from_mask_ ? 0u : 1u;
    const float scale = plan_.stats_point_scale();
    rows(full.height, [&](size_t y) {
        if (simd_ == nullptr) {
            pixel::pyr_stats_row_run(c, full, uint32_t(y), 0u, full.width, with_points, scale, 0u, plan_.stats_slots);
        } else {
            stats_row(c, simd_, full, uint32_t(y), with_points, scale, plan_.stats_slots);
        }
    });
}

}  // namespace pyrseg::cpu
