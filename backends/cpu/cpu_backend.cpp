#include "backends/cpu/cpu_backend.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "backends/cpu/cpu_kernels.hpp"
#include "backends/cpu/points_to_mask.hpp"
#include "backends/cpu/robust_windows.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "backends/cpu/thread_pool.hpp"
#include "backends/cpu/union_find_fill.hpp"
#include "core/cloud_layout.hpp"
#include "core/depth_tables.hpp"
#include "core/segment_stats.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::cpu {
namespace {

using std::size_t;
using std::uint32_t;

constexpr size_t kColumnBlock = 64;  // the narrowest strip of columns swept together, row by row

// Union-find scratch for the largest level a fixed-point fill runs on: N-1, or N itself for the tiny-image fallback.
size_t fill_scratch_size(const core::Plan& plan) {
    const PyrLevel& lv = plan.small_image ? plan.full() : plan.level(plan.level_count - 1);
    return union_find_scratch_size(lv.width, lv.height);
}

// PYRSEG_CPU_FILL=sweeps runs steps 2 and 4 as repeated row/column sweeps of the shared relaxation (the GPU
// scheme) instead of union-find; both reach the contract's fixed point, and the tests check that they agree.
bool use_sweeps_for_fixed_points() {
    const char* env = std::getenv("PYRSEG_CPU_FILL");
    return env != nullptr && std::strcmp(env, "sweeps") == 0;
}

class CpuExecutor final : public core::PassExecutor {
public:
    explicit CpuExecutor(const core::Plan& plan)
        : plan_(plan),
          quant_(kQuantWords * plan.pixel_count()),
          mask_valid_(plan.pixel_count()),
          mask_(plan.total_texels),
          labels_(plan.total_texels),
          lut_(plan.lut_size()),
          fill_scratch_(fill_scratch_size(plan)),
          stats_(plan.stats_words()),
          simd_(simd::kernels_from_environment()),
          sweeps_(use_sweeps_for_fixed_points()) {}

    [[nodiscard]] uint32_t fill_rounds() const override { return fill_rounds_; }

    void bind_cloud(const CloudView& cloud) override {
        fill_rounds_ = 0;
        cloud_ = cloud;
        layout_ = core::cloud_layout(cloud);
        normals_estimated_ = false;
        valid_bytes_ = false;
        from_mask_ = false;
    }

    // The depth image stays where the caller has it; depth_to_points writes the points this backend owns.
    void bind_depth(const DepthView& depth, const core::DepthTables& tables) override {
        fill_rounds_ = 0;
        depth_ = depth;
        depth_tables_ = &tables;
        normals_estimated_ = false;
        valid_bytes_ = false;
        from_mask_ = false;
    }

    void depth_to_points() override {
        const size_t w = size_t(plan_.width);
        if (depth_points_.empty()) depth_points_.resize(3 * plan_.pixel_count());  // once per Segmenter
        const size_t sample = core::DepthTables::sample_bytes(depth_.format);
        const size_t step = depth_.row_step_bytes == 0 ? w * sample : depth_.row_step_bytes;
        const auto format = depth_.format == DepthFormat::u16 ? PYR_DEPTH_U16 : PYR_DEPTH_F32;
        const core::DepthTables& t = *depth_tables_;
        if (simd_ != nullptr) {
            rows(size_t(plan_.height), [&](size_t y) {
                simd_->depth_row(static_cast<const unsigned char*>(depth_.depth) + y * step, format, uint32_t(w),
                                 t.scale, t.ku.data(), t.kv[y], depth_points_.data() + 3 * y * w);
            });
        } else {
            rows(size_t(plan_.height), [&](size_t y) {
                const auto* row = static_cast<const unsigned char*>(depth_.depth) + y * step;
                for (size_t x = 0; x < w; ++x) {
                    uint32_t bits = 0;
                    if (format == PYR_DEPTH_U16) {
                        std::uint16_t d = 0;
                        std::memcpy(&d, row + 2 * x, 2);  // rows may start at any byte
                        bits = d;
                    } else {
                        std::memcpy(&bits, row + 4 * x, 4);
                    }
                    const PyrFVec3 p = kernels::pyr_depth_point(bits, format, t.scale, t.ku[x], t.kv[y]);
                    float* out = depth_points_.data() + 3 * (y * w + x);
                    out[0] = p.x;
                    out[1] = p.y;
                    out[2] = p.z;
                }
            });
        }
        CloudView cloud;
        cloud.points = depth_points_.data();
        cloud.width = plan_.width;
        cloud.height = plan_.height;
        cloud_ = cloud;
        layout_ = core::cloud_layout(cloud);
    }

    void bind_mask(const MaskView& mask) override {
        fill_rounds_ = 0;
        from_mask_ = true;
        const size_t w = size_t(plan_.width);
        const size_t stride = mask.row_stride == 0 ? w : mask.row_stride;
        std::uint8_t* full = mask_.data() + plan_.full().offset;
        std::uint8_t* valid = mask_valid_.data();
        const std::uint8_t* in_fillable = mask.fillable;
        const std::uint8_t* in_valid = mask.valid;
        rows(size_t(plan_.height), [&](size_t y) {
            // Everything the loops read in locals: byte stores may alias anything, so a captured reference (the
            // width too) would be reloaded per pixel and the loops would not vectorise.
            const size_t n = w;
            const std::uint8_t* in = in_fillable + y * stride;
            std::uint8_t* out = full + y * n;
            for (size_t x = 0; x < n; ++x) out[x] = in[x] != 0 ? 1 : 0;
            std::uint8_t* out_valid = valid + y * n;
            if (in_valid == nullptr) {
                std::memset(out_valid, 1, n);
                return;
            }
            const std::uint8_t* in_v = in_valid + y * stride;
            for (size_t x = 0; x < n; ++x) out_valid[x] = in_v[x] != 0 ? 1 : 0;
        });
    }

    void estimate_normals() override {
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
                rows(size_t(h),
                     [&](size_t y) { simd_->robust_texels_row(c, uint32_t(w), h, uint32_t(y), radius, scale); });
            } else {
                rows(size_t(h), [&](size_t y) {
                    for (size_t x = 0; x < w; ++x) {
                        c.robust_texels.store(y * w + x, kernels::pyr_robust_texel(c, uint32_t(w), h, uint32_t(x),
                                                                                   uint32_t(y), radius, scale));
                    }
                });
            }
            windows_.build(c.robust_texels, w, size_t(h), window, simd_,
                           [&](size_t n, const auto& body) { rows(n, body); });
            if (simd_ != nullptr) {
                // The vector rows take the windows inside the image's columns; the others are the scalar code's.
                const size_t words = (w + 63) / 64;
                if (robust_rest_.size() < size_t(h) * words) robust_rest_.resize(size_t(h) * words);  // once
                rows(size_t(h), [&](size_t y) {
                    std::uint64_t* rest = robust_rest_.data() + y * words;
                    simd_->robust_normals_row(c, windows_.row(y), uint32_t(w), h, uint32_t(y), window,
                                              normals_.data() + 3 * y * w, rest);
                    for (size_t i = 0; i < words; ++i) {
                        for (std::uint64_t bits = rest[i]; bits != 0; bits &= bits - 1) {
                            const size_t x = i * 64 + size_t(std::countr_zero(bits));
                            store_normal_q(robust_normal(c, x, y), normals_.data() + 3 * (y * w + x));
                        }
                    }
                });
                normals_estimated_ = true;
                return;
            }
        }
        if (!robust && simd_ != nullptr) {
            rows(size_t(plan_.height), [&](size_t y) {
                simd_->normals_row(c, uint32_t(w), h, uint32_t(y), radius, normals_.data() + 3 * y * w);
            });
            normals_estimated_ = true;
            return;
        }
        rows(size_t(plan_.height), [&](size_t y) {
            for (size_t x = 0; x < w; ++x) {
                const PyrIVec3 q = robust ? robust_normal(c, x, y)
                                          : kernels::pyr_normal_q(c, uint32_t(w), h, uint32_t(x), uint32_t(y), radius);
                store_normal_q(q, normals_.data() + 3 * (y * w + x));
            }
        });
        normals_estimated_ = true;
    }

    void quantize() override {
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
                const PyrQuant q = kernels::pyr_quantize(p[0], p[1], p[2], n[0], n[1], n[2]);
                store_quant(quant_.data() + kQuantWords * (y * w + x), q.qx, q.qy, q.qz, q.valid, p[2]);
            }
        });
    }

    void metric() override {
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
                out[x] = std::uint8_t(robust ? kernels::pyr_metric_robust_fillable(
                                                   c, full.width, full.height, x, uint32_t(y), stride, t.curvature_base,
                                                   t.curvature_growth, t.depth, t.depth_growth)
                                             : kernels::pyr_metric_fillable(c, full.width, full.height, x, uint32_t(y),
                                                                            t.curvature, t.depth));
            }
        });
    }

    // The paper metric on the vector kernels: fused (backends/cpu/points_to_mask.hpp). The robust metric's windows
    // and the scalar path run as separate passes.
    [[nodiscard]] bool fuses_points_to_mask() const override {
        return simd_ != nullptr && plan_.params.metric == Metric::paper;
    }

    void points_to_mask(bool estimate_normals) override {
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
        // The statistics read each pixel's qn; nothing else reads the quantized pixels after the metric.
        if (plan_.stats_slots != 0) f.quant_out = quant_.data();
        f.mask_out = mask_.data() + plan_.full().offset;
        f.valid_out = mask_valid_.data();
        points_to_mask_.run(pool_, *simd_, f);
        normals_estimated_ = estimate_normals;
        valid_bytes_ = true;
    }

    void mip(int parent_level) override {
        const PassContext c = context();
        const PyrLevel parent = plan_.level(parent_level);
        const PyrLevel child = plan_.level(parent_level + 1);
        if (simd_ != nullptr) {
            rows(parent.height, [&](size_t y) {
                const size_t cy = 2 * y;
                const std::uint8_t* top =
                    cy + 1 < child.height ? mask_.data() + child.offset + cy * child.width : nullptr;
                simd_->mip_row(top, child.width, parent.width, mask_.data() + parent.offset + y * parent.width);
            });
            return;
        }
        rows(parent.height, [&](size_t y) {
            std::uint8_t* out = mask_.data() + parent.offset + y * parent.width;
            for (uint32_t x = 0; x < parent.width; ++x)
                out[x] = std::uint8_t(kernels::pyr_mip_texel(c, child, x, uint32_t(y)));
        });
    }

    void init_labels(int level, uint32_t mode) override {
        const PassContext c = context();
        const PyrLevel lv = plan_.level(level);
        const PyrLevel parent = level > 1 ? plan_.level(level - 1) : PyrLevel{0, 0, 0};
        if (simd_ != nullptr && mode == PYR_INIT_INHERIT && level > 1) {
            rows(lv.height, [&](size_t y) {
                simd_->inherit_row(c.mask + lv.offset + y * lv.width,
                                   c.labels + parent.offset + (y >> 1) * parent.width, lv.width,
                                   c.labels + lv.offset + y * lv.width, nullptr);
            });
            return;
        }
        rows(lv.height, [&](size_t y) { init_row(c, lv, parent, uint32_t(y), mode); });
    }

    void fill_to_fixed_point(int level, uint32_t anchor_max) override {
        const PyrLevel lv = plan_.level(level);
        if (anchor_max != 0) {
            std::uint8_t* mask = mask_.data();
            const uint32_t* labels = labels_.data();
            rows(lv.height, [&](size_t y) {
                // Locals: byte stores may alias the captured references, which would be reloaded per texel.
                std::uint8_t* m = mask + lv.offset + y * lv.width;
                const uint32_t* l = labels + lv.offset + y * lv.width;
                const uint32_t n = lv.width;
                const uint32_t max = anchor_max;
                for (uint32_t x = 0; x < n; ++x) m[x] = std::uint8_t(kernels::pyr_anchor_mask(m[x], l[x], max));
            });
        }
        if (sweeps_) {
            do {
                ++fill_rounds_;
            } while (sweep(lv, false));
        } else {
            union_find_fill(pool_, lv, mask_.data(), labels_.data(), anchor_max != 0, fill_scratch_.data());
        }
    }

    // Steps 5 and 6 a, b: each row's step-5 labels just before its row sweeps, while the row is in cache.
    // The vector path runs steps 5, 6 a, b (and 6c, with one edge round) in one pass over the rows instead.
    void final_fill(int level) override {
        edges_fused_ = false;
        if (simd_ == nullptr) {
            sweep(plan_.level(level), true, true);
            return;
        }
        edges_fused_ = plan_.params.label_edges && plan_.params.edge_rounds == 1;
        final_fill_rows(plan_.level(level), plan_.level(level - 1), edges_fused_);
    }

    // Step 6c, and compaction's marking of each row once its labels are final (one pass over the image fewer).
    void label_edges() override {
        const PassContext c = context();
        const PyrLevel full = plan_.full();
        std::fill(lut_.begin(), lut_.end(), 0u);
        const auto rounds = uint32_t(plan_.params.edge_rounds);
        if (edges_fused_) {
            // final_fill labelled the edges. Every label of the full level comes from level N-1 (step 5 copies
            // each one to the four children of its texel, and steps 6 only copy labels): marking that level's
            // labels marks the same set from a quarter of the texels.
            const PyrLevel below = plan_.level(plan_.level_count - 1);
            rows(below.height,
                 [&](size_t y) { mark_labels(labels_.data() + below.offset + y * below.width, below.width); });
            return;
        }
        if (rounds == 1) {
            rows(full.height, [&](size_t y) {
                for (uint32_t x = 0; x < full.width; ++x) {
                    const uint32_t i = full.offset + uint32_t(y) * full.width + x;
                    // Only edge pixels change, and no other pixel reads them: writing only changes keeps rows
                    // free of races on the fillable labels they read.
                    const uint32_t l = kernels::pyr_edge_label(c, full, x, uint32_t(y), 1u);
                    if (l != labels_[i]) labels_[i] = l;
                }
                mark_row(y);
            });
            return;
        }
        // Several rounds: each one reads its neighbours' masks, which the round's own writes change, so it first
        // computes every new label and then writes them (with the round in the mask). A pixel can only take a label
        // in a round after the first when a neighbour took one in the round before (only those became candidates),
        // so a round skips the rows with no changed row next to them, and a round that labels nothing ends them.
        const size_t h = full.height;
        const size_t w = full.width;
        if (edge_next_.empty()) edge_next_.resize(plan_.pixel_count());  // once per Segmenter
        if (edge_changed_.size() < 2 * h) edge_changed_.resize(2 * h);
        std::uint8_t* changed = edge_changed_.data();  // this round's, per row
        std::uint8_t* before = changed + h;            // the round before's
        std::fill_n(changed, h, std::uint8_t{1});
        const std::uint8_t* valid = validity_bytes(c);
        const size_t words = (w + 63) / 64;
        if (edge_bits_.size() < h * words) edge_bits_.resize(h * words);  // once per Segmenter
        for (uint32_t round = 1; round <= rounds; ++round) {
            std::swap(changed, before);
            const auto open = [&](size_t y) {
                return round == 1 || before[y] != 0 || (y > 0 && before[y - 1] != 0) ||
                       (y + 1 < h && before[y + 1] != 0);
            };
            // Each open row's new labels (edge_next_) and the pixels that take one (edge_bits_), then written.
            rows(h, [&](size_t y) {
                changed[y] = 0;
                if (!open(y)) return;
                uint32_t* next = edge_next_.data() + y * w;
                std::uint64_t* bits = edge_bits_.data() + y * words;
                if (simd_ != nullptr) {
                    const size_t i = full.offset + y * w;
                    const bool up = y > 0;
                    const bool down = y + 1 < h;
                    changed[y] = std::uint8_t(simd_->edge_round_row(
                        up ? c.mask + i - w : nullptr, c.mask + i, down ? c.mask + i + w : nullptr,
                        up ? c.labels + i - w : nullptr, c.labels + i, down ? c.labels + i + w : nullptr, valid + y * w,
                        uint32_t(w), round, next, bits));
                    return;
                }
                std::fill_n(bits, words, std::uint64_t{0});
                for (uint32_t x = 0; x < w; ++x) {
                    next[x] = kernels::pyr_edge_label(c, full, x, uint32_t(y), round);
                    if (next[x] == labels_[full.offset + y * w + x]) continue;
                    bits[x / 64] |= std::uint64_t{1} << (x % 64);
                    changed[y] = 1;
                }
            });
            const auto round_bits = std::uint8_t(round < rounds ? round << PYR_MASK_EDGE_SHIFT : 0u);
            rows(h, [&](size_t y) {
                if (changed[y] == 0) return;
                uint32_t* l = labels_.data() + full.offset + y * w;
                std::uint8_t* m = mask_.data() + full.offset + y * w;
                const uint32_t* next = edge_next_.data() + y * w;
                const std::uint64_t* bits = edge_bits_.data() + y * words;
                for (size_t i = 0; i < words; ++i) {
                    for (std::uint64_t b = bits[i]; b != 0; b &= b - 1) {
                        const size_t x = i * 64 + size_t(std::countr_zero(b));
                        l[x] = next[x];
                        m[x] = std::uint8_t(m[x] | round_bits);
                    }
                }
            });
            if (std::find(changed, changed + h, std::uint8_t{1}) == changed + h) break;
        }
        rows(h, [&](size_t y) { mark_row(y); });
    }

    // Validity bytes of the full level: the caller's mask's or points_to_mask's, else made from the quantized
    // pixels into mask_valid_ (unused in such a frame).
    const std::uint8_t* validity_bytes(const PassContext& c) {
        if (c.mask_valid != nullptr) return c.mask_valid;
        const size_t w = plan_.width;
        rows(size_t(plan_.height), [&](size_t y) {
            std::uint8_t* out = mask_valid_.data() + y * w;
            const uint32_t* q = c.quant + kQuantWords * y * w;
            for (size_t x = 0; x < w; ++x) out[x] = std::uint8_t(q[kQuantWords * x + 1] >> 16);
        });
        return mask_valid_.data();
    }

    void compact(bool apply, bool after_edges) override {
        if (!after_edges) {  // else label_edges marked every row already
            std::fill(lut_.begin(), lut_.end(), 0u);
            rows(size_t(plan_.height), [&](size_t y) { mark_row(y); });
        }
        lut_[0] = 0;  // mark_labels marks 0 as well
        uint32_t count = 0;
        for (uint32_t& entry : lut_) {
            if (entry != 0) entry = ++count;
        }
        segment_count_ = count;
        compacted_ = apply;
    }

    // Rows in parallel, each in one run: a row adds each stretch of equal labels to its slot at once.
    void segment_stats() override {
        std::fill_n(stats_.begin(), std::min(stats_.size(), size_t(segment_count_) * PYR_STATS_WORDS), 0u);
        const PassContext c = context();
        const PyrLevel full = plan_.full();
        const uint32_t with_points = from_mask_ ? 0u : 1u;
        const float scale = plan_.stats_point_scale();
        rows(full.height, [&](size_t y) {
            kernels::pyr_stats_row_run(c, full, uint32_t(y), 0u, full.width, with_points, scale, 0u, plan_.stats_slots);
        });
    }

    void read_back(Result& out, const Outputs& outputs) override {
        const size_t pixels = plan_.pixel_count();
        const uint32_t* raw = labels_.data() + plan_.full().offset;
        out.width = plan_.width;
        out.height = plan_.height;
        out.segment_count = segment_count_;
        out.labels.resize(pixels);
        const PassContext c = context();
        uint32_t* labels = out.labels.data();
        const bool compacted = compacted_;
        const size_t width = size_t(plan_.width);
        if (!compacted) {
            std::copy_n(raw, pixels, labels);
        } else {
            // lut_[0] is 0 (compact): every pixel is one lookup.
            const uint32_t* lut = c.lut;
            const bool vector = simd_ != nullptr && lut_.size() <= (size_t{1} << 31);
            rows(size_t(plan_.height), [&](size_t y) {
                const uint32_t* in = raw + y * width;
                uint32_t* to = labels + y * width;
                if (vector) {
                    simd_->compact_row(in, lut, uint32_t(width), to);
                } else {
                    for (size_t x = 0; x < width; ++x) to[x] = lut[in[x]];
                }
            });
        }
        if (outputs.raw_labels) {
            out.raw_labels.assign(raw, raw + pixels);
        } else {
            out.raw_labels.clear();
        }
        if (outputs.fillable_mask) {
            const std::uint8_t* m = mask_.data() + plan_.full().offset;
            out.fillable_mask.resize(pixels);
            // Bit 0 is B; edge labelling's rounds live in the bits above it.
            std::transform(m, m + pixels, out.fillable_mask.begin(),
                           [](std::uint8_t v) { return std::uint8_t(v & PYR_MASK_FILLABLE); });
        } else {
            out.fillable_mask.clear();
        }
        out.segments.clear();
        if (plan_.stats_slots != 0)
            core::decode_segment_stats(stats_.data(), segment_count_, plan_, !from_mask_, out.segments);
        out.normals.clear();
        if (outputs.normals && !from_mask_) {
            out.normals.resize(3 * pixels);
            const size_t w = size_t(plan_.width);
            for (size_t y = 0; y < size_t(plan_.height); ++y) {
                for (size_t x = 0; x < w; ++x) std::copy_n(normal(x, y), 3, out.normals.data() + 3 * (y * w + x));
            }
        }
    }

private:
    static void store_normal_q(const PyrIVec3& q, float* n) {
        n[0] = float(q.x) * PYR_NORMAL_UNIT;
        n[1] = float(q.y) * PYR_NORMAL_UNIT;
        n[2] = float(q.z) * PYR_NORMAL_UNIT;
    }

    // The robust texels' planes (RobustTexelPlanes) in robust_texels_, sized on first use.
    RobustTexelPlanes robust_planes() {
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

    // Section 8b's normal of pixel (x, y): from the box sums when its whole window is members, else the window
    // pixel by pixel (the shared function); the same words either way (backends/cpu/robust_windows.hpp).
    PyrIVec3 robust_normal(const PassContext& c, size_t x, size_t y) const {
        const float scale = plan_.thresholds.point_scale;
        const float* p = point(x, y);
        if (kernels::pyr_point_valid(p[0], p[1], p[2]) != 0u) {
            const std::int32_t zi = kernels::pyr_robust_fixed(p[2], scale);
            if (windows_.all_members(x, y, zi, zi >> 4)) {
                PyrIVec3 u{};
                PyrIVec3 v{};
                windows_.sums(x, y, u, v);
                return kernels::pyr_robust_normal_from_sums(u, v, p[0], p[1], p[2]);
            }
        }
        return kernels::pyr_robust_normal_q(c, uint32_t(plan_.width), uint32_t(plan_.height), uint32_t(x), uint32_t(y),
                                            uint32_t(plan_.params.normal_window), scale);
    }

    template <class RowBody>
    void rows(size_t count, const RowBody& body) {
        const size_t grain = std::max<size_t>(1, count / (size_t(pool_.size()) * 8));
        pool_.parallel_for(count, grain, [&](size_t begin, size_t end) {
            for (size_t y = begin; y < end; ++y) body(y);
        });
    }

    // Marks the labels of row y of the full level in the compaction table (concurrent rows write the same value).
    void mark_row(size_t y) {
        mark_labels(labels_.data() + plan_.full().offset + y * size_t(plan_.width), plan_.width);
    }

    // lut_[0] is set too: compact clears it. A label is stored once per run of it and only while unmarked: the
    // other stores go to a local instead of a branch on it (which mispredicts on fragmented masks), and not to the
    // table, whose lines would then move between the threads' caches for every label both of them see.
    void mark_labels(const uint32_t* row, size_t w) {
        uint32_t previous = 0;
        uint32_t sink = 0;
        for (size_t x = 0; x < w; ++x) {
            const uint32_t l = row[x];
            const bool unmarked = std::atomic_ref<uint32_t>(lut_[l]).load(std::memory_order_relaxed) == 0;
            uint32_t* entry = l != previous && unmarked ? &lut_[l] : &sink;
            std::atomic_ref<uint32_t>(*entry).store(1u, std::memory_order_relaxed);
            previous = l;
        }
    }

    void init_row(const PassContext& c, const PyrLevel& lv, const PyrLevel& parent, uint32_t y, uint32_t mode) {
        uint32_t* out = labels_.data() + lv.offset + size_t(y) * lv.width;
        for (uint32_t x = 0; x < lv.width; ++x) out[x] = kernels::pyr_label_init_texel(c, lv, parent, x, y, mode);
    }

    [[nodiscard]] PassContext context() {
        PassContext c;
        c.points = cloud_.points;
        c.row_floats = layout_.row_floats;
        c.point_floats = layout_.point_floats;
        c.quant = quant_.data();
        c.mask_valid = from_mask_ || valid_bytes_ ? mask_valid_.data() : nullptr;
        c.mask = mask_.data();
        c.labels = labels_.data();
        c.lut = lut_.data();
        c.stats = stats_.data();
        return c;
    }

    [[nodiscard]] const float* point(size_t x, size_t y) const { return cloud_.points + layout_.at(x, y); }
    [[nodiscard]] const float* normal(size_t x, size_t y) const {
        if (normals_estimated_) return normals_.data() + 3 * (y * size_t(plan_.width) + x);
        return cloud_.normals + layout_.at(x, y);
    }

    // One round of the four directional sweeps (rows left-right then right-left, then columns top-down then
    // bottom-up). Rows are independent, and so are columns: each runs in parallel. Returns whether a label changed.
    // init_rows_first: run step 5's label init of each row just before its sweep (the row is then in cache).
    bool sweep(const PyrLevel& lv, bool once, bool init_rows_first = false) {
        const PassContext c = context();
        const uint32_t onceu = once ? 1u : 0u;
        std::atomic<bool> changed{false};
        const PyrLevel parent = plan_.level(std::max(1, plan_.level_count - 1));
        rows(lv.height, [&](size_t y) {
            if (init_rows_first) init_row(c, lv, parent, uint32_t(y), PYR_INIT_INHERIT);
            const bool row_changed =
                once ? sweep_row_once(c, lv, uint32_t(y)) : kernels::pyr_sweep_row(c, lv, uint32_t(y), onceu) != 0u;
            if (row_changed) changed.store(true, std::memory_order_relaxed);
        });
        // Columns in a few wide strips, one per task: each row of a strip is a long contiguous run.
        const size_t strips = size_t(pool_.size()) * 2;
        const size_t strip = std::max(kColumnBlock, (size_t(lv.width) + strips - 1) / strips);
        const size_t blocks = (size_t(lv.width) + strip - 1) / strip;
        pool_.parallel_for(blocks, 1, [&](size_t b0, size_t b1) {
            const uint32_t x0 = uint32_t(b0 * strip);
            const uint32_t x1 = uint32_t(std::min(size_t(lv.width), b1 * strip));
            bool ch = false;
            // Row by row, each column's sequential order is kept: row y reads row y -/+ 1 already updated.
            for (uint32_t y = 1; y < lv.height; ++y) ch |= column_step(c, lv, y, y - 1, x0, x1, once);
            for (uint32_t y = lv.height - 1; y-- > 0;) ch |= column_step(c, lv, y, y + 1, x0, x1, once);
            if (ch) changed.store(true, std::memory_order_relaxed);
        });
        return changed.load();
    }

    // Step 6 changes only fillable pixels without a label (labelled ones never change), so a block of a row that
    // has none stays as it is whatever its neighbours do: the sweeps skip such blocks after a vectorised check.
    static constexpr uint32_t kSkipBlock = 64;

    [[nodiscard]] static bool has_unlabelled_fillable(const std::uint8_t* mask, const uint32_t* labels,
                                                      uint32_t count) {
        bool any = false;
        for (uint32_t x = 0; x < count; ++x) any |= ((mask[x] & PYR_MASK_FILLABLE) != 0) & (labels[x] == 0);
        return any;
    }

    // Step 6a on row y: the shared sweep, there and back, over the blocks that can change (with the pixel before
    // each block, which the sweep reads first).
    bool sweep_row_once(const PassContext& c, const PyrLevel& lv, uint32_t y) {
        const uint32_t row = lv.offset + y * lv.width;
        bool changed = false;
        for (uint32_t b = 0; b < lv.width; b += kSkipBlock) {
            const uint32_t n = std::min(kSkipBlock, lv.width - b);
            if (!has_unlabelled_fillable(c.mask + row + b, c.labels + row + b, n)) continue;
            const uint32_t start = b == 0 ? row : row + b - 1;
            changed |= kernels::pyr_sweep_line(c, start, 1u, b == 0 ? n : n + 1, 1u) != 0u;
        }
        for (uint32_t e = lv.width; e > 0; e -= std::min(kSkipBlock, e)) {
            const uint32_t n = std::min(kSkipBlock, e);
            const uint32_t b = e - n;
            if (!has_unlabelled_fillable(c.mask + row + b, c.labels + row + b, n)) continue;
            const uint32_t start = e == lv.width ? row + e - 1 : row + e;
            changed |= kernels::pyr_sweep_line(c, start, 0xffffffffu, e == lv.width ? n : n + 1, 1u) != 0u;
        }
        return changed;
    }

    bool column_step(const PassContext& c, const PyrLevel& lv, uint32_t y, uint32_t from_y, uint32_t x0, uint32_t x1,
                     bool once) {
        const uint32_t row = lv.offset + y * lv.width;
        const uint32_t from = lv.offset + from_y * lv.width;
        const std::uint8_t* m = c.mask;
        uint32_t* l = c.labels;
        if (once) {
            bool ch = false;
            for (uint32_t b = x0; b < x1; b += kSkipBlock) {
                const uint32_t e = std::min(x1, b + kSkipBlock);
                if (has_unlabelled_fillable(m + row + b, l + row + b, e - b))
                    ch |= column_block(c, row, from, b, e, true);
            }
            return ch;
        }
        return column_block(c, row, from, x0, x1, false);
    }

    static bool column_block(const PassContext& c, uint32_t row, uint32_t from, uint32_t x0, uint32_t x1, bool once) {
        const std::uint8_t* m = c.mask;
        uint32_t* l = c.labels;
        bool ch = false;
        for (uint32_t x = x0; x < x1; ++x) {
            if ((m[row + x] & PYR_MASK_FILLABLE) == 0) continue;
            const uint32_t cur = l[row + x];
            const uint32_t next = kernels::pyr_fill_step(cur, m[row + x], l[from + x], m[from + x], once ? 1u : 0u);
            if (next != cur) {
                l[row + x] = next;
                ch = true;
            }
        }
        return ch;
    }

    // ---- Steps 5 and 6 on the vector kernels (final_fill_rows)
    // Step 6 changes only the pixels that are fillable and unlabelled after step 5, few of them (the children of
    // non-fillable texels at the regions' borders), and its schedule reduces to runs of them: a row's run takes the
    // label of the pixel left of it when that one is fillable (so labelled), else of the one right of it, else stays
    // 0; then a column's run of those still unlabelled takes the label above it, else the one below it. So one pass
    // over the rows runs step 5 with a vector kernel that also marks those pixels in a bitmap, and steps 6 a and the
    // downward sweep then touch only the marked pixels; the upward sweep visits the pixels still marked, bottom up.

    [[nodiscard]] static bool any_bits(const uint64_t* bits, size_t words) {
        uint64_t any = 0;
        for (size_t i = 0; i < words; ++i) any |= bits[i];
        return any != 0;
    }

    // Row y's validity bytes: the mask's own, else from the quantized pixels into scratch.
    [[nodiscard]] const std::uint8_t* valid_row(const PassContext& c, size_t y, std::uint8_t* scratch) const {
        const size_t w = plan_.width;
        if (c.mask_valid != nullptr) return c.mask_valid + y * w;
        for (size_t x = 0; x < w; ++x) scratch[x] = std::uint8_t(c.quant[kQuantWords * (y * w + x) + 1] >> 16);
        return scratch;
    }

    void edge_row(const PassContext& c, const PyrLevel& lv, size_t y, std::uint8_t* scratch) const {
        const size_t w = lv.width;
        const size_t i = lv.offset + y * w;
        const bool up = y > 0;
        const bool down = y + 1 < lv.height;
        simd_->edge_row(up ? c.mask + i - w : nullptr, c.mask + i, down ? c.mask + i + w : nullptr,
                        up ? c.labels + i - w : nullptr, c.labels + i, down ? c.labels + i + w : nullptr,
                        valid_row(c, y, scratch), lv.width);
    }

    void final_fill_rows(const PyrLevel& lv, const PyrLevel& parent, bool edges) {
        const PassContext c = context();
        const size_t w = lv.width;
        const size_t h = lv.height;
        const size_t words = (w + 63) / 64;
        if (unlabelled_.size() < h * words) unlabelled_.resize(h * words);  // once per Segmenter
        if (pending_.size() < h) pending_.resize(h);
        // Bands of rows run in parallel; the column sweeps cross their borders afterwards, in order.
        const size_t bands = std::min(h, size_t(pool_.size()) * 2);
        if (edges && c.mask_valid == nullptr && valid_scratch_.size() < bands * w) valid_scratch_.resize(bands * w);
        const auto band_begin = [&](size_t b) { return h * b / bands; };
        const auto row_of = [&](size_t y) { return c.labels + lv.offset + y * w; };
        const auto mask_of = [&](size_t y) { return c.mask + lv.offset + y * w; };
        const auto bits_of = [&](size_t y) { return unlabelled_.data() + y * words; };
        // One column step of row y from row `from` (y - 1 down, y + 1 up).
        const auto step = [&](size_t y, size_t from) {
            return simd_->column_step(mask_of(from), row_of(from), row_of(y), bits_of(y), uint32_t(w));
        };
        // A row is pending when marked pixels remain in it after the band pass: only those can change later, so the
        // edges next to them wait for the end, and the others' edges are final during the band pass.
        const auto settled = [&](size_t y) {
            return ((pending_[y] | (y > 0 ? pending_[y - 1] : 0) | (y + 1 < h ? pending_[y + 1] : 0)) & kPending) == 0;
        };
        pool_.parallel_for(bands, 1, [&](size_t b0, size_t b1) {
            for (size_t b = b0; b < b1; ++b) {
                const size_t y0 = band_begin(b);
                const size_t y1 = band_begin(b + 1);
                std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data() + b * w;
                for (size_t y = y0; y < y1; ++y) {
                    uint32_t* row = row_of(y);
                    const std::uint8_t* m = mask_of(y);
                    bool marks = simd_->inherit_row(m, c.labels + parent.offset + (y >> 1) * parent.width, uint32_t(w),
                                                    row, bits_of(y));
                    if (marks) marks = simd_->row_runs(m, row, bits_of(y), uint32_t(w));
                    if (marks && y > y0) {
                        simd_->column_step(mask_of(y - 1), row_of(y - 1), row, bits_of(y), uint32_t(w));
                        marks = any_bits(bits_of(y), words);
                    }
                    pending_[y] = marks ? kPending : 0;
                    // Edges read rows y - 2 .. y: all of this band's.
                    if (edges && y >= y0 + 2 && settled(y - 1)) edge_row(c, lv, y - 1, scratch);
                }
            }
        });
        // The downward sweep across each band's top, down as far as it changes something.
        for (size_t b = 1; b < bands; ++b) {
            for (size_t y = band_begin(b); y < h && step(y, y - 1); ++y) {
            }
        }
        // The upward sweep: inside each band in parallel (each band's last row aside), then across the bands' bottoms
        // from the last band up, each as far as it changes something. A row stepped again from a row that gained
        // labels meanwhile ends as one step from that row's final labels would leave it: labels only ever appear.
        // The edges the band pass left wait for the first part: after it only the rows the crossings reach change.
        // Those edges read each row's candidates (edge_candidates), made once a row's labels are final for the pass
        // and kept for the three rows around it, where one of them needs them.
        if (edges && candidates_.size() < bands * 3 * w) candidates_.resize(bands * 3 * w);
        const auto needs_candidates = [&](size_t y) {
            return !settled(y) || (y > 0 && !settled(y - 1)) || (y + 1 < h && !settled(y + 1));
        };
        pool_.parallel_for(bands, 1, [&](size_t b0, size_t b1) {
            for (size_t b = b0; b < b1; ++b) {
                const size_t y0 = band_begin(b);
                const size_t y1 = band_begin(b + 1);
                std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data() + b * w;
                uint32_t* ring = edges ? candidates_.data() + b * 3 * w : nullptr;
                const auto candidates_of = [&](size_t y) { return ring + (y % 3) * w; };
                const auto make_candidates = [&](size_t y) {
                    if (edges && needs_candidates(y))
                        simd_->edge_candidates(mask_of(y), row_of(y), uint32_t(w), candidates_of(y));
                };
                make_candidates(y1 - 1);
                for (size_t y = y1 - 1; y-- > y0;) {
                    if (pending_[y] != 0) step(y, y + 1);
                    make_candidates(y);
                    if (edges && y + 2 < y1 && !settled(y + 1)) {
                        simd_->edge_row_from_candidates(candidates_of(y), candidates_of(y + 1), candidates_of(y + 2),
                                                        mask_of(y + 1), valid_row(c, y + 1, scratch), row_of(y + 1),
                                                        uint32_t(w));
                    }
                }
            }
        });
        for (size_t b = bands; b-- > 1;) {
            for (size_t y = band_begin(b); y-- > 0 && step(y, y + 1);) pending_[y] |= kLate;
        }
        if (!edges) return;
        // Edges again next to the rows the upward crossings changed, in parallel inside each band, then the bands'
        // first and last rows, which read their neighbour bands' rows. edge_row takes the minimum again: a row done
        // twice comes out the same.
        const auto late = [&](size_t y) {
            return ((pending_[y] | (y > 0 ? pending_[y - 1] : 0) | (y + 1 < h ? pending_[y + 1] : 0)) & kLate) != 0;
        };
        pool_.parallel_for(bands, 1, [&](size_t b0, size_t b1) {
            for (size_t b = b0; b < b1; ++b) {
                std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data() + b * w;
                for (size_t y = band_begin(b) + 1; y + 1 < band_begin(b + 1); ++y) {
                    if (late(y)) edge_row(c, lv, y, scratch);
                }
            }
        });
        std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data();
        for (size_t b = 0; b < bands; ++b) {
            edge_row(c, lv, band_begin(b), scratch);
            if (band_begin(b + 1) - 1 > band_begin(b)) edge_row(c, lv, band_begin(b + 1) - 1, scratch);
        }
    }

    const core::Plan& plan_;
    ThreadPool pool_;
    CloudView cloud_{};
    core::CloudLayout layout_{};
    std::vector<float> normals_;               // estimated, packed
    std::vector<std::int32_t> robust_texels_;  // the robust normals' texels as 8 planes (metric robust only)
    std::vector<std::uint64_t> robust_rest_;   // the pixels the robust normals' vector rows leave, a bit each
    RobustWindows windows_;                    // their box sums and window depth ranges
    std::vector<std::uint32_t> edge_next_;     // a round's new edge labels (edge_rounds > 1 only)
    std::vector<std::uint8_t> edge_changed_;   // per row, whether a round changed it (edge_rounds > 1 only)
    std::vector<std::uint64_t> edge_bits_;     // per row, the pixels a round labels, a bit each (edge_rounds > 1)
    DepthView depth_{};                        // a depth frame, as the caller has it
    const core::DepthTables* depth_tables_ = nullptr;
    std::vector<float> depth_points_;       // its back-projection (depth frames only)
    std::vector<uint32_t> quant_;           // kQuantWords per pixel
    std::vector<std::uint8_t> mask_valid_;  // validity of a caller's mask, or from points_to_mask (bytes)
    PointsToMask points_to_mask_;           // its per-thread windows
    std::vector<std::uint8_t> mask_;        // all levels
    std::vector<uint32_t> labels_;          // all levels
    std::vector<uint32_t> lut_;             // raw label -> compacted label
    // Union-find scratch (union_find_scratch_size).
    std::vector<uint32_t> fill_scratch_;
    std::vector<std::uint64_t> unlabelled_;    // final_fill_rows: the pixels step 6 can change, a bit each
    std::vector<std::uint8_t> valid_scratch_;  // final_fill_rows: validity rows, when they are in the quant words
    // final_fill_rows, per row: kPending when marked pixels remain after the band pass, kLate when the upward
    // crossing changed it.
    std::vector<std::uint8_t> pending_;
    std::vector<uint32_t> candidates_;  // final_fill_rows: three rows of edge candidates a band
    static constexpr std::uint8_t kPending = 1;
    static constexpr std::uint8_t kLate = 2;
    bool edges_fused_ = false;     // final_fill_rows labelled the edges too
    std::vector<uint32_t> stats_;  // per-segment statistics words, when asked for
    // The vector row passes PYRSEG_CPU_SIMD picks (backends/cpu/simd/cpu_simd.hpp); null: the shared scalar
    // functions pixel by pixel.
    const simd::RowKernels* simd_;
    bool sweeps_;
    uint32_t segment_count_ = 0;
    uint32_t fill_rounds_ = 0;
    bool compacted_ = false;
    bool normals_estimated_ = false;
    bool valid_bytes_ = false;  // mask_valid_ holds this frame's validity (points_to_mask wrote it)
    bool from_mask_ = false;
};

size_t physical_memory_bytes() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long page = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? size_t(pages) * size_t(page) : 0;
}

// Bytes a CpuExecutor allocates (estimated normals counted: they are allocated on the first frame without normals).
size_t memory_needed(const core::Plan& plan) {
    const size_t pixels = plan.pixel_count();
    return pixels * (kQuantWords * sizeof(uint32_t) + 1 + 3 * sizeof(float)) +      // quant, validity, normals
           size_t(plan.total_texels) * (sizeof(std::uint8_t) + sizeof(uint32_t)) +  // masks, labels
           (size_t(plan.max_label) + 1) * sizeof(uint32_t) +                        // compaction table
           fill_scratch_size(plan) * sizeof(uint32_t) +                             // union-find
           plan.stats_words() * sizeof(uint32_t) +                                  // statistics
           (plan.params.metric == Metric::robust ? pixels * (sizeof(PyrRobustTexel) + 1) : 0) +  // texels, rest bits
           (plan.params.edge_rounds > 1 ? pixels * sizeof(std::uint32_t) + pixels / 8 + 8 * size_t(plan.height)
                                        : 0) +                                 // labels, bits
           PointsToMask::scratch_bytes(plan.width, plan.params.normal_radius,  // its rows, per thread
                                       ThreadPool::default_size());
}

}  // namespace

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    const size_t needed = memory_needed(plan);
    const size_t available = physical_memory_bytes();
    const auto mib = [](size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; };
    const std::string what = "a " + std::to_string(plan.width) + " x " + std::to_string(plan.height) +
                             " image needs about " + mib(needed) + " on the CPU backend";
    // Checked up front: an allocation this large may succeed on paper and then get the process killed.
    if (available != 0 && needed > available) {
        throw Error(ErrorCode::out_of_memory, what + ", more than this machine's " + mib(available));
    }
    try {
        return std::make_unique<CpuExecutor>(plan);
    } catch (const std::bad_alloc&) {
        throw Error(ErrorCode::out_of_memory, what + ", and allocating it failed");
    }
}

namespace {
std::vector<std::string> describe_host(std::string* /*why_none*/, bool* available) {
    *available = true;
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    return {"host CPU, " + std::to_string(threads) + " hardware threads"};
}
}  // namespace

const core::BackendEntry kBackend = {describe_host, make_executor};

}  // namespace pyrseg::cpu
