// The pass order of the contract (docs/algorithm.md section 5), written once for every backend.
#include "core/pipeline.hpp"

#include <chrono>
#include <cstring>

namespace pyrseg::core {
namespace {

class PassClock {
public:
    PassClock(std::vector<PassTiming>& timings, PassExecutor& ex) : timings_(timings), ex_(ex) { timings_.clear(); }

    template <class F>
    void run(const char* pass, F&& body) {
        ex_.begin_pass(pass);
        const auto start = std::chrono::steady_clock::now();
        body();
        const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
        for (PassTiming& t : timings_) {
            if (std::strcmp(t.pass, pass) == 0) {
                t.milliseconds += elapsed.count();
                return;
            }
        }
        timings_.push_back(PassTiming{pass, elapsed.count()});
    }

private:
    std::vector<PassTiming>& timings_;
    PassExecutor& ex_;
};

}  // namespace

void run_pipeline(const Plan& plan, InputKind input, bool with_color, PassExecutor& ex,
                  std::vector<PassTiming>& timings) {
    PassClock clock(timings, ex);
    const int n = plan.level_count;
    if (input != InputKind::mask) {
        if (input == InputKind::depth) clock.run("depth", [&] { ex.depth_to_points(); });
        const bool estimate = input != InputKind::cloud_with_normals;
        if (ex.fuses_points_to_mask()) {
            clock.run("points_to_mask", [&] { ex.points_to_mask(estimate); });  // the next three, fused
        } else {
            if (estimate) clock.run("normals", [&] { ex.estimate_normals(); });
            clock.run("quantize", [&] { ex.quantize(); });
            clock.run("metric", [&] { ex.metric(); });
        }
        if (with_color && plan.params.color_edge_threshold < kMaxColorEdgeThreshold) {
            clock.run("color", [&] { ex.color_edges(); });  // step 0c
        }
    }
    const bool marks = ex.marks_labels_before_compact();
    bool marked = false;  // the labels present are marked for step 7 (marks only)
    if (plan.small_image) {
        // The contract's fallback: plain 4-connected components of B, each labelled 1 + its smallest index,
        // which is the fixed point of the step-2 fill from pixel-index labels.
        clock.run("labels", [&] { ex.init_labels(n, PYR_INIT_PIXEL_INDEX); });
        clock.run("fill", [&] { ex.fill_to_fixed_point(n, 0); });
    } else {
        const int m = plan.bridge_level;
        clock.run("mip", [&] {
            for (int k = n - 1; k >= 1; --k) ex.mip(k);
        });
        clock.run("labels", [&] {
            for (int k = 1; k <= m; ++k) ex.init_labels(k, PYR_INIT_NEW);  // step 1
        });
        clock.run("fill", [&] { ex.fill_to_fixed_point(m, 0); });  // step 2
        clock.run("labels", [&] {
            for (int k = m + 1; k <= n - 1; ++k) ex.init_labels(k, PYR_INIT_INHERIT);  // step 3
        });
        clock.run("fill", [&] { ex.fill_to_fixed_point(n - 1, plan.old_label_max); });  // step 4
        const bool edges = plan.params.label_edges;
        const bool merge = plan.params.merge;  // a mask frame is refused before (core/segmenter.cpp)
        if (edges && ex.fuses_edges_into_final_fill()) {
            clock.run("final_fill", [&] { ex.final_fill_with_edges(n); });  // steps 5, 6 a, b, c
            // Every label of level N comes from level N - 1 (step 5 copies each one to the four children of its
            // texel, and steps 6 only copy labels): marking that level's labels marks the same set from a quarter
            // of the texels.
            if (marks && !merge) clock.run("edges", [&] { ex.mark_labels(n - 1); });
        } else {
            clock.run("final_fill", [&] { ex.final_fill(n); });        // steps 5, 6 a, b
            if (edges) clock.run("edges", [&] { ex.label_edges(); });  // step 6 c (and the marks, with marks)
        }
        // The merge changes labels after the edges marked them: the marks are made again, by it or after it.
        if (merge) clock.run("merge", [&] { ex.merge_segments(); });  // step 6d
        marked = marks && (merge ? ex.marks_labels_in_merge() : edges);
    }
    if (marks && !marked) clock.run("compact", [&] { ex.mark_labels(n); });
    clock.run("compact", [&] { ex.compact(plan.params.compact); });  // step 7
    if (plan.stats_slots != 0) clock.run("stats", [&] { ex.segment_stats(); });
    if (plan.graph_slots != 0) clock.run("graph", [&] { ex.segment_graph(); });
    if (plan.track_slots != 0) clock.run("tracks", [&] { ex.track_overlaps(); });
}

}  // namespace pyrseg::core
