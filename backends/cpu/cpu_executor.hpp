#pragma once
// The CPU backend's executor: the shared pass functions (cpu_dialect.hpp) or their vector rows (simd/cpu_simd.hpp)
// over the image's rows on a thread pool. Its methods live with the passes they run: cpu_executor.cpp (its buffers,
// the pyramid's passes, statistics), cpu_inputs.cpp, cpu_front_end.cpp (normals to mask), cpu_fills.cpp (steps 2
// and 4), cpu_final_fill.cpp (steps 5 and 6 a, b), cpu_edges.cpp (6c), cpu_compact.cpp (7), cpu_read_back.cpp.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "backends/cpu/points_to_mask.hpp"
#include "backends/cpu/robust_windows.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "backends/cpu/thread_pool.hpp"
#include "core/cloud_layout.hpp"
#include "core/depth_tables.hpp"
#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::cpu {

class CpuExecutor final : public core::PassExecutor {
public:
    CpuExecutor(const core::Plan& plan, const ThreadSetting& threads);

    // Union-find scratch for the largest level a fixed-point fill runs on: N-1, or N itself for the tiny-image
    // fallback.
    [[nodiscard]] static std::size_t fill_scratch_size(const core::Plan& plan);

    void bind_cloud(const CloudView& cloud) override;
    void bind_mask(const MaskView& mask) override;
    void bind_depth(const DepthView& depth, const core::DepthTables& tables) override;
    void depth_to_points() override;
    void bind_color(const std::uint8_t* rgb, std::size_t row_step_bytes) override;  // cpu_inputs.cpp
    void color_edges() override;                                                    // cpu_front_end.cpp

    void estimate_normals() override;
    void quantize() override;
    void metric() override;
    // The paper metric on the vector rows: fused (backends/cpu/points_to_mask.hpp). The robust metric's windows
    // and the scalar path run as separate passes.
    [[nodiscard]] bool fuses_points_to_mask() const override {
        return simd_ != nullptr && plan_.params.metric == Metric::paper;
    }
    void points_to_mask(bool estimate_normals) override;

    void mip(int parent_level) override;
    void init_labels(int level, std::uint32_t mode) override;
    void fill_to_fixed_point(int level, std::uint32_t anchor_max) override;
    void final_fill(int level) override;
    // One edge round fits the vector path's pass over the rows (final_fill_rows); several need rounds of their own.
    [[nodiscard]] bool fuses_edges_into_final_fill() const override {
        return simd_ != nullptr && plan_.params.edge_rounds == 1;
    }
    void final_fill_with_edges(int level) override;
    void label_edges() override;
    void merge_segments() override;  // cpu_merge.cpp
    [[nodiscard]] bool marks_labels_in_merge() const override { return true; }
    // label_edges marks each row once its labels are final: one pass over the image fewer.
    [[nodiscard]] bool marks_labels_before_compact() const override { return true; }
    void mark_labels(int level) override;
    void compact(bool apply) override;
    void segment_stats() override;
    void segment_graph() override;   // cpu_graph.cpp
    void track_overlaps() override;  // cpu_tracks.cpp
    void forget_previous_labels() override { previous_count_ = 0; }
    [[nodiscard]] const std::uint32_t* track_pairs(std::uint32_t& count) const override;
    void read_back(Result& out, const Outputs& outputs) override;

    [[nodiscard]] std::uint32_t fill_rounds() const override { return fill_rounds_; }

private:
    template <class RowBody>
    void rows(std::size_t count, const RowBody& body) {
        const std::size_t grain = std::max<std::size_t>(1, count / pool_.pieces());
        pool_.parallel_for(count, grain, [&](std::size_t begin, std::size_t end) {
            for (std::size_t y = begin; y < end; ++y) body(y);
        });
    }

    [[nodiscard]] PassContext context();
    [[nodiscard]] const float* point(std::size_t x, std::size_t y) const { return cloud_.points + layout_.at(x, y); }
    [[nodiscard]] const float* normal(std::size_t x, std::size_t y) const {
        if (normals_estimated_) return normals_.data() + 3 * (y * std::size_t(plan_.width) + x);
        return cloud_.normals + layout_.at(x, y);
    }
    void init_row(const PassContext& c, const PyrLevel& lv, const PyrLevel& parent, std::uint32_t y,
                  std::uint32_t mode);

    // cpu_front_end.cpp
    RobustTexelPlanes robust_planes();
    [[nodiscard]] PyrIVec3 robust_normal(const PassContext& c, const simd::RobustWindowRow& sums, std::size_t x,
                                         std::size_t y) const;

    // cpu_fills.cpp
    bool sweep(const PyrLevel& lv, bool once, bool init_rows_first = false);
    bool sweep_row_once(const PassContext& c, const PyrLevel& lv, std::uint32_t y);
    bool column_step(const PassContext& c, const PyrLevel& lv, std::uint32_t y, std::uint32_t from_y, std::uint32_t x0,
                     std::uint32_t x1, bool once);

    // cpu_final_fill.cpp
    [[nodiscard]] const std::uint8_t* valid_row(const PassContext& c, std::size_t y, std::uint8_t* scratch) const;
    void edge_row(const PassContext& c, const PyrLevel& lv, std::size_t y, std::uint8_t* scratch) const;
    void final_fill_rows(const PyrLevel& lv, const PyrLevel& parent, bool edges);

    // cpu_edges.cpp
    const std::uint8_t* validity_bytes(const PassContext& c);

    // cpu_compact.cpp
    void mark_row(std::size_t y);
    void mark_row_labels(const std::uint32_t* row, std::size_t w);

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
    const std::uint8_t* color_ = nullptr;      // the frame's colour image, as the caller has it (or null)
    std::size_t color_row_bytes_ = 0;
    const core::DepthTables* depth_tables_ = nullptr;
    std::vector<float> depth_points_;          // its back-projection (depth frames only)
    std::vector<std::uint32_t> quant_;         // kQuantWords per pixel
    std::vector<std::uint8_t> mask_valid_;     // validity of a caller's mask, or from points_to_mask (bytes)
    PointsToMask points_to_mask_;              // its per-thread windows
    std::vector<std::uint8_t> mask_;           // all levels
    std::vector<std::uint32_t> labels_;        // all levels
    std::vector<std::uint32_t> lut_;           // raw label -> compacted label
    std::vector<std::uint32_t> fill_scratch_;  // union-find scratch (fill_scratch_size)
    std::vector<std::uint64_t> unlabelled_;    // final_fill_rows: the pixels step 6 can change, a bit each
    std::vector<std::uint8_t> valid_scratch_;  // final_fill_rows: validity rows, when they are in the quant words
    // final_fill_rows, per row: whether marked pixels remain after the band pass, and whether the upward crossing
    // changed it (bits of cpu_final_fill.cpp).
    std::vector<std::uint8_t> pending_;
    std::vector<std::uint32_t> candidates_;   // final_fill_rows: three rows of edge candidates a band
    std::vector<std::uint32_t> stats_;        // per-segment statistics words, when asked for
    std::vector<std::uint32_t> merge_words_;  // the merge's label parents and pair table (shaders/pyr_merge_table.h)
    std::vector<std::uint32_t> graph_words_;  // the segment graph's counter, table and list (shaders/pyr_graph.h)
    std::size_t graph_list_ = 0;              // where this frame's list starts in it
    // Tracks: the previous frame's compacted labels, its segment count (0: no previous frame), and the overlap pairs'
    // table (shaders/pyr_track.h), grown to the largest frame so far, with the slots the last frame used.
    std::vector<std::uint32_t> previous_labels_;
    std::uint32_t previous_count_ = 0;
    std::vector<std::uint32_t> track_words_;
    std::uint32_t track_slots_ = 0;
    // The vector row passes PYRSEG_CPU_SIMD picks (backends/cpu/simd/cpu_simd.hpp); null: the shared scalar
    // functions pixel by pixel.
    const simd::VectorRows* simd_;
    bool sweeps_;  // PYRSEG_CPU_FILL=sweeps (cpu_fills.cpp)
    std::uint32_t segment_count_ = 0;
    std::uint32_t fill_rounds_ = 0;
    bool compacted_ = false;
    bool normals_estimated_ = false;
    bool valid_bytes_ = false;  // mask_valid_ holds this frame's validity (points_to_mask wrote it)
    bool from_mask_ = false;
};

}  // namespace pyrseg::cpu
