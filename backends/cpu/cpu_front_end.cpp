// Points to the fillable mask: normals (when estimated), quantize and the metric (paper or robust) as separate passes,
// or the paper metric's three fused (points_to_mask, backends/cpu/points_to_mask.hpp).
#include <bit>

#include "backends/cpu/cpu_executor.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

namespace {

void store_normal_q(const PyrIVec3& q, float* n) {
    n[0] = float(q.x) * PYR_NORMAL_UNIT;
    n[1] = float(q.y) * PYR_NORMAL_UNIT;
    n[2] = float(q.z) * PYR_NORMAL_UNIT;
}

}  // namespace

void CpuExecutor::estimate_normals() {
    const size_t w = size_t(plan_.width);
    if (normals_.empty()) normals_.resize(3 * plan_.pixel_count());  // once per Segmenter
    const auto radius = uint32_t(plan_.params.normal_radius);
    const auto window = uint32_t(plan_.params.normal_window);
    const float scale = plan_.thresholds.point_scale;
    const bool robust = plan_.params.metric == Metric::robust;
    const auto h = uint32_t(plan_.height);
    PassContext c = context();
    if (robust) {
        // Each pixel's tangents once, rather than once for every window that holds the pixel.
        c.robust_texels = robust_planes();
        if (simd_ != nullptr) {
            rows(size_t(h), [&](size_t y) { simd_->robust_texels_row(c, uint32_t(w), h, uint32_t(y), radius, scale); });
        } else {
            rows(size_t(h), [&](size_t y) {
                for (size_t x = 0; x < w; ++x) {
                    c.robust_texels.store(
                        y * w + x, pixel::pyr_robust_texel(c, uint32_t(w), h, uint32_t(x), uint32_t(y), radius, scale));
                }
            });
        }
        // The vector rows take the windows inside the image's columns; the others are the scalar code's.
        const size_t words = (w + 63) / 64;
        if (simd_ != nullptr && robust_rest_.size() < size_t(h) * words) robust_rest_.resize(size_t(h) * words);
        windows_.run(pool_, c.robust_texels, w, size_t(h), window, simd_,
                     [&](size_t y, const simd::RobustWindowRow& sums) {
                         float* normals = normals_.data() + 3 * y * w;
                         if (simd_ == nullptr) {
                             for (size_t x = 0; x < w; ++x) {
                                 store_normal_q(robust_normal(c, sums, x, y), normals + 3 * x);
                             }
                             return;
                         }
                         std::uint64_t* rest = robust_rest_.data() + y * words;
                         simd_->robust_normals_row(c, sums, uint32_t(w), h, uint32_t(y), window, normals, rest);
                         for (size_t i = 0; i < words; ++i) {
                             for (std::uint64_t bits = rest[i]; bits != 0; bits &= bits - 1) {
                                 const size_t x = i * 64 + size_t(std::countr_zero(bits));
                                 store_normal_q(robust_normal(c, sums, x, y), normals + 3 * x);
                             }
                         }
                     });
        normals_estimated_ = true;
        return;
    }
    if (simd_ != nullptr) {
        rows(size_t(plan_.height), [&](size_t y) {
            simd_->normals_row(c, uint32_t(w), h, uint32_t(y), radius, normals_.data() + 3 * y * w);
        });
        normals_estimated_ = true;
        return;
    }
    rows(size_t(plan_.height), [&](size_t y) {
        for (size_t x = 0; x < w; ++x) {
            store_normal_q(pixel::pyr_normal_q(c, uint32_t(w), h, uint32_t(x), uint32_t(y), radius),
                           normals_.data() + 3 * (y * w + x));
        }
    });
    normals_estimated_ = true;
}

void CpuExecutor::quantize() {
    const size_t w = size_t(plan_.width);
    if (simd_ != nullptr) {
        const size_t normal_floats = normals_estimated_ ? 3 : layout_.point_floats;
        rows(size_t(plan_.height), [&](size_t y) {
            simd_->quantize_row(point(0, y), layout_.point_floats, normal(0, y), normal_floats, uint32_t(w),
                                quant_.data() + kQuantWords * y * w);
        });
        return;
    }
    rows(size_t(plan_.height), [&](size_t y) {
        for (size_t x = 0; x < w; ++x) {
            const float* p = point(x, y);
            const float* n = normal(x, y);
            const PyrQuant q = pixel::pyr_quantize(p[0], p[1], p[2], n[0], n[1], n[2]);
            store_quant(quant_.data() + kQuantWords * (y * w + x), q.qx, q.qy, q.qz, q.valid, p[2]);
        }
    });
}

void CpuExecutor::metric() {
    const PassContext c = context();
    const PyrLevel full = plan_.full();
    const core::Thresholds t = plan_.thresholds;
    const bool robust = plan_.params.metric == Metric::robust;
    const auto stride = uint32_t(plan_.params.curvature_stride);
    if (simd_ != nullptr) {
        rows(full.height, [&](size_t y) {
            std::uint8_t* out = mask_.data() + full.offset + y * full.width;
            if (robust) {
                simd_->metric_robust_row(c, full.width, full.height, uint32_t(y), stride, t.curvature_base,
                                         t.curvature_growth, t.depth, t.depth_growth, out);
            } else {
                simd_->metric_row(c, full.width, full.height, uint32_t(y), t.curvature, t.depth, out);
            }
        });
        return;
    }
    rows(full.height, [&](size_t y) {
        std::uint8_t* out = mask_.data() + full.offset + y * full.width;
        for (uint32_t x = 0; x < full.width; ++x) {
            out[x] = std::uint8_t(
                robust
                    ? pixel::pyr_metric_robust_fillable(c, full.width, full.height, x, uint32_t(y), stride,
                                                        t.curvature_base, t.curvature_growth, t.depth, t.depth_growth)
                    : pixel::pyr_metric_fillable(c, full.width, full.height, x, uint32_t(y), t.curvature, t.depth));
        }
    });
}

void CpuExecutor::points_to_mask(bool estimate_normals) {
    PointsToMaskFrame f;
    f.points = context();
    f.given_normals = estimate_normals ? nullptr : cloud_.normals;
    f.width = plan_.width;
    f.height = plan_.height;
    f.normal_radius = uint32_t(plan_.params.normal_radius);
    f.curvature = plan_.thresholds.curvature;
    f.depth = plan_.thresholds.depth;
    if (estimate_normals && plan_.keep_normals) {
        if (normals_.empty()) normals_.resize(3 * plan_.pixel_count());  // once per Segmenter
        f.normals_out = normals_.data();
    }
    // The statistics, the merge and the graph read each pixel's qn, step 6c's depth test its z; nothing else reads
    // the quantized pixels after the metric.
    if (plan_.stats_slots != 0 || plan_.params.merge || plan_.graph_slots != 0 || uses_edge_depth_step(plan_.params)) {
        f.quant_out = quant_.data();
    }
    f.mask_out = mask_.data() + plan_.full().offset;
    f.valid_out = mask_valid_.data();
    points_to_mask_.run(pool_, *simd_, f);
    normals_estimated_ = estimate_normals;
    valid_bytes_ = true;
}

namespace {

// |R_a - R_b| + |G_a - G_b| + |B_a - B_b| of two pixels' bytes (pyr_color_difference, on the bytes in place).
inline uint32_t byte_difference(const std::uint8_t* a, const std::uint8_t* b) {
    const auto d = [](int u, int v) { return uint32_t(u > v ? u - v : v - u); };
    return d(a[0], b[0]) + d(a[1], b[1]) + d(a[2], b[2]);
}

}  // namespace

// Step 0c: the fillable pixels on a colour edge that counts (its curvature gate, the shared function) cleared in level
// N. The columns whose row neighbours both lie in the image read the caller's bytes directly; the few others go
// through the shared function (the same test).
void CpuExecutor::color_edges() {
    const PassContext c = context();
    const auto w = uint32_t(plan_.width);
    const auto h = uint32_t(plan_.height);
    const auto s = uint32_t(plan_.params.color_edge_stride);
    const auto threshold = uint32_t(plan_.params.color_edge_threshold);
    const core::Thresholds& t = plan_.thresholds;
    const auto curvature_stride = uint32_t(plan_.params.curvature_stride);
    std::uint8_t* mask = mask_.data() + plan_.full().offset;
    rows(size_t(h), [&](size_t y) {
        std::uint8_t* row = mask + y * w;
        const std::uint8_t* mid = color_ + y * color_row_bytes_;
        const bool vertical = y >= s && y + s < h;
        const std::uint8_t* up = vertical ? color_ + (y - s) * color_row_bytes_ : nullptr;
        const std::uint8_t* down = vertical ? color_ + (y + s) * color_row_bytes_ : nullptr;
        const uint32_t inner_end = w > s ? w - s : 0;
        for (uint32_t x = 0; x < w; ++x) {
            if ((row[x] & PYR_MASK_FILLABLE) == 0) continue;
            bool edge = false;
            if (x >= s && x < inner_end) {
                edge = byte_difference(mid + 3 * size_t(x - s), mid + 3 * size_t(x + s)) > threshold ||
                       (vertical && byte_difference(up + 3 * size_t(x), down + 3 * size_t(x)) > threshold);
            } else {
                edge = pixel::pyr_color_edge(c, w, h, x, uint32_t(y), s, threshold) != 0u;
            }
            if (edge && pixel::pyr_color_edge_counts(c, w, h, x, uint32_t(y), t.color_curvature_gate, curvature_stride,
                                                     t.curvature_base, t.curvature_growth) != 0u) {
                row[x] = std::uint8_t(row[x] & ~PYR_MASK_FILLABLE);
            }
        }
    });
}

// The robust texels' planes (RobustTexelPlanes) in robust_texels_, sized on first use.
RobustTexelPlanes CpuExecutor::robust_planes() {
    const size_t pixels = plan_.pixel_count();
    if (robust_texels_.empty()) robust_texels_.resize(8 * pixels);  // once per Segmenter
    std::int32_t* p = robust_texels_.data();
    RobustTexelPlanes planes;
    planes.gz = p;
    planes.tangents = reinterpret_cast<std::uint32_t*>(p + pixels);
    for (size_t k = 0; k < 3; ++k) {
        planes.th[k] = p + (2 + k) * pixels;
        planes.tv[k] = p + (5 + k) * pixels;
    }
    return planes;
}

// Section 8b's normal of pixel (x, y) (row y's windows: sums): from the box sums when its whole window is members, else
// the window pixel by pixel (the shared function); the same words either way (backends/cpu/robust_windows.hpp).
PyrIVec3 CpuExecutor::robust_normal(const PassContext& c, const simd::RobustWindowRow& sums, size_t x, size_t y) const {
    const float scale = plan_.thresholds.point_scale;
    const float* p = point(x, y);
    if (pixel::pyr_point_valid(p[0], p[1], p[2]) != 0u) {
        const std::int32_t zi = pixel::pyr_robust_fixed(p[2], scale);
        if (RobustWindows::all_members(sums, x, zi, zi >> 4)) {
            PyrIVec3 u{};
            PyrIVec3 v{};
            windows_.sums(sums, x, u, v);
            return pixel::pyr_robust_normal_from_sums(u, v, p[0], p[1], p[2]);
        }
    }
    return pixel::pyr_robust_normal_q(c, uint32_t(plan_.width), uint32_t(plan_.height), uint32_t(x), uint32_t(y),
                                      uint32_t(plan_.params.normal_window), scale);
}

}  // namespace pyrseg::cpu
