#pragma once
// The CPU backend's dialect file: the per-pixel functions (shaders/) compiled as C++, with the accessor macros reading
// the backend's buffers through a PassContext. They live in their own namespace so that another backend's
// host-compiled copy with other accessors can never collide with them.
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>

#include "shaders/pyr_types.h"

namespace pyrseg::cpu {

// A quantized pixel (contract section 2) is kQuantWords words of the quant buffer, which the vector passes
// (backends/cpu/simd/) read and write as they are: qx | qy << 16 and qz | valid << 16 (16-bit two's complement
// halves: |q| <= 8192, valid is 0 or 1), then the bits of z.
inline constexpr std::size_t kQuantWords = 3;

inline void store_quant(std::uint32_t* words, std::int32_t qx, std::int32_t qy, std::int32_t qz, std::uint32_t valid,
                        float z) {
    words[0] = (static_cast<std::uint32_t>(qx) & 0xffffu) | (static_cast<std::uint32_t>(qy) << 16);
    words[1] = (static_cast<std::uint32_t>(qz) & 0xffffu) | (valid << 16);
    words[2] = std::bit_cast<std::uint32_t>(z);
}

// Component c (0, 1, 2) of qn of pixel i.
inline std::int32_t quant_component(const std::uint32_t* quant, std::size_t i, int c) {
    const std::uint32_t word = quant[kQuantWords * i + std::size_t(c >> 1)];
    return static_cast<std::int16_t>((c & 1) != 0 ? word >> 16 : word & 0xffffu);
}

// The robust normals' texels (pyr_robust_texel) of a frame as planes of W x H elements, so that rows of them load as
// vectors: G(z) (-1 where the point is not point-valid), the tangent bits, and t_h, t_v per component (0 where
// missing).
struct RobustTexelPlanes {
    std::int32_t* gz = nullptr;
    std::uint32_t* tangents = nullptr;
    std::int32_t* th[3] = {nullptr, nullptr, nullptr};
    std::int32_t* tv[3] = {nullptr, nullptr, nullptr};

    void store(std::size_t i, const PyrRobustTexel& t) const {
        gz[i] = t.gz;
        tangents[i] = t.tangents;
        th[0][i] = t.th.x;
        th[1][i] = t.th.y;
        th[2][i] = t.th.z;
        tv[0][i] = t.tv.x;
        tv[1][i] = t.tv.y;
        tv[2][i] = t.tv.z;
    }
    [[nodiscard]] PyrRobustTexel load(std::size_t i) const {
        PyrRobustTexel t{};
        t.gz = gz[i];
        t.tangents = tangents[i];
        t.th = PyrIVec3{th[0][i], th[1][i], th[2][i]};
        t.tv = PyrIVec3{tv[0][i], tv[1][i], tv[2][i]};
        return t;
    }
};

struct PassContext {
    const float* points = nullptr;             // the caller's cloud, strided
    std::size_t row_floats = 0;                // from one row to the next
    std::size_t point_floats = 3;              // from one point to the next
    const std::uint32_t* quant = nullptr;      // kQuantWords per pixel
    const std::uint8_t* mask_valid = nullptr;  // a caller's mask's validity, else null (validity is in quant)
    std::uint8_t* mask = nullptr;              // all levels
    std::uint32_t* labels = nullptr;           // all levels
    const std::uint32_t* lut = nullptr;
    std::uint32_t* stats = nullptr;       // the statistics words, PYR_STATS_WORDS per slot
    RobustTexelPlanes robust_texels;      // the robust normals' texels of the frame
    std::uint32_t* merge = nullptr;       // the merge's words (backends/cpu/cpu_merge.cpp)
    const std::uint8_t* color = nullptr;  // the caller's colour image (RGB8), when the frame has one
    std::size_t color_row_bytes = 0;
};

// Pixel (x, y)'s colour as 0x00BBGGRR, read where the caller has it.
inline std::uint32_t rgb_at(const PassContext& ctx, std::uint32_t x, std::uint32_t y) {
    const std::uint8_t* p = ctx.color + std::size_t(y) * ctx.color_row_bytes + 3 * std::size_t(x);
    return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16);
}

inline void atomic_max(std::uint32_t& word, std::uint32_t v) {
    std::atomic_ref<std::uint32_t> a(word);
    std::uint32_t old = a.load(std::memory_order_relaxed);
    while (old < v && !a.compare_exchange_weak(old, v, std::memory_order_relaxed)) {
    }
}

// The old value, as the GPUs' atomic min and compare-and-swap return it (the merge's shaders/pyr_merge_table.h).
inline std::uint32_t atomic_min(std::uint32_t& word, std::uint32_t v) {
    std::atomic_ref<std::uint32_t> a(word);
    std::uint32_t old = a.load(std::memory_order_relaxed);
    while (old > v && !a.compare_exchange_weak(old, v, std::memory_order_relaxed)) {
    }
    return old;
}

inline std::uint32_t atomic_cas(std::uint32_t& word, std::uint32_t expected, std::uint32_t v) {
    std::atomic_ref<std::uint32_t>(word).compare_exchange_strong(expected, v, std::memory_order_relaxed);
    return expected;
}

}  // namespace pyrseg::cpu

#define PYR_CTX_PARAM const ::pyrseg::cpu::PassContext& ctx
#define PYR_CTX_ARG ctx
#define PYR_PT(x, y, c) \
    (ctx.points[static_cast<std::size_t>(y) * ctx.row_floats + static_cast<std::size_t>(x) * ctx.point_floats + (c)])
#define PYR_Q_VALID(i) (ctx.quant[::pyrseg::cpu::kQuantWords * static_cast<std::size_t>(i) + 1] >> 16)
#define PYR_QN(i, c) ::pyrseg::cpu::quant_component(ctx.quant, static_cast<std::size_t>(i), (c))
#define PYR_QZ(i) std::bit_cast<float>(ctx.quant[::pyrseg::cpu::kQuantWords * static_cast<std::size_t>(i) + 2])
// The robust normals read the texels estimate_normals computed once per frame (w: the image width, named by the
// function it expands in).
#define PYR_ROBUST_TEXEL(jx, jy) (ctx.robust_texels.load(static_cast<std::size_t>(jy) * (w) + (jx)))
#define PYR_MASK(i) static_cast<std::uint32_t>(ctx.mask[i])
#define PYR_RGB_AT(x, y, w) ::pyrseg::cpu::rgb_at(ctx, (x), (y))
#define PYR_LABEL(i) (ctx.labels[i])
#define PYR_STORE_LABEL(i, v) (ctx.labels[i] = (v))
#define PYR_VALID(p) static_cast<std::uint32_t>(ctx.mask_valid != nullptr ? ctx.mask_valid[p] : PYR_Q_VALID(p))
#define PYR_LUT(l) (ctx.lut[l])
#define PYR_STATS_ADD(w, v) std::atomic_ref<std::uint32_t>(ctx.stats[w]).fetch_add((v), std::memory_order_relaxed)
#define PYR_STATS_MAX(w, v) ::pyrseg::cpu::atomic_max(ctx.stats[w], (v))

namespace pyrseg::cpu::pixel {
#include "shaders/pyr_passes.h"
}  // namespace pyrseg::cpu::pixel
