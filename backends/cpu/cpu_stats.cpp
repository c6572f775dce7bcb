// The per-segment statistics pass (docs/algorithm.md section 10) on the CPU: rows in parallel, each stretch of equal
// labels summed in native 64-bit and 128-bit integers and added to its slot's words at once, with the shared
// dialect's word arithmetic (shaders/pyr_stats.h: pyr_stats_flush), so the words are those of every other backend.
// Sums of integers do not depend on how they are grouped, so summing a stretch in wide native integers instead of
// the shader's 32-bit words changes nothing but the time. PYRSEG_CPU_SIMD=scalar runs the shared row function
// itself (pyr_stats_row_run), which the conformance suite compares with this one.
#include <cmath>
#include <cstdint>

#include "backends/cpu/cpu_executor.hpp"

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

// A stretch's wide sums. A product of two fixed-point coordinates is below 2^62 in magnitude, so products are summed
// in 64 bits and folded into 128 when an addition would overflow (never, on real frames).
struct Stretch {
    uint32_t slot = 0xffffffffu;
    uint32_t raw = 0;
    uint32_t count = 0;
    uint32_t x_min = 0;
    uint32_t x_max = 0;
    std::int64_t point[3] = {0, 0, 0};
    std::int64_t normal[3] = {0, 0, 0};
    std::int32_t z_min = 0;
    std::int32_t z_max = 0;
    std::int64_t product[6] = {0, 0, 0, 0, 0, 0};
    Int128 product_carry[6] = {0, 0, 0, 0, 0, 0};

    void add_product(size_t i, std::int64_t p) {
        std::int64_t sum = 0;
        if (__builtin_add_overflow(product[i], p, &sum)) {
            product_carry[i] += Int128(product[i]) + p;
            product[i] = 0;
        } else {
            product[i] = sum;
        }
    }
};

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
    r.x_max = s.x_max;
    if (with_points != 0u) {
        r.px = sum64(s.point[0]);
        r.py = sum64(s.point[1]);
        r.pz = sum64(s.point[2]);
        r.nx = sum64(s.normal[0]);
        r.ny = sum64(s.normal[1]);
        r.nz = sum64(s.normal[2]);
        r.z_key_min = uint32_t(s.z_min) ^ 0x80000000u;
        r.z_key_max = uint32_t(s.z_max) ^ 0x80000000u;
        pixel::PyrSum96* products[6] = {&r.xx, &r.xy, &r.xz, &r.yy, &r.yz, &r.zz};
        for (size_t i = 0; i < 6; ++i) *products[i] = sum96(s.product_carry[i] + s.product[i]);
    }
    pixel::pyr_stats_flush(c, 0u, r, y, with_points);
}

void stats_row(const PassContext& c, const PyrLevel& full, uint32_t y, uint32_t with_points, float scale,
               uint32_t slots) {
    const uint32_t* labels = c.labels + full.offset + size_t(y) * full.width;
    Stretch s;
    for (uint32_t x = 0; x < full.width; ++x) {
        const uint32_t raw = labels[x];
        uint32_t slot = raw != 0u ? c.lut[raw] - 1u : 0xffffffffu;
        if (slot >= slots) slot = 0xffffffffu;
        if (slot != s.slot) {
            if (s.slot != 0xffffffffu) flush(c, s, y, with_points);
            s = Stretch{};
            s.slot = slot;
            s.raw = raw;
            s.x_min = x;
        }
        if (slot == 0xffffffffu) continue;
        ++s.count;
        s.x_max = x;
        if (with_points == 0u) continue;
        const float* p = c.points + size_t(y) * c.row_floats + size_t(x) * c.point_floats;
        const std::int64_t q[3] = {fixed(p[0], scale), fixed(p[1], scale), fixed(p[2], scale)};
        const size_t pixel_index = size_t(y) * full.width + x;
        for (int k = 0; k < 3; ++k) {
            s.point[k] += q[k];
            s.normal[k] += quant_component(c.quant, pixel_index, k);
        }
        const auto z = static_cast<std::int32_t>(q[2]);
        s.z_min = s.count == 1 ? z : (z < s.z_min ? z : s.z_min);
        s.z_max = s.count == 1 ? z : (z > s.z_max ? z : s.z_max);
        s.add_product(0, q[0] * q[0]);
        s.add_product(1, q[0] * q[1]);
        s.add_product(2, q[0] * q[2]);
        s.add_product(3, q[1] * q[1]);
        s.add_product(4, q[1] * q[2]);
        s.add_product(5, q[2] * q[2]);
    }
    if (s.slot != 0xffffffffu) flush(c, s, y, with_points);
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
            stats_row(c, full, uint32_t(y), with_points, scale, plan_.stats_slots);
        }
    });
}

}  // namespace pyrseg::cpu
