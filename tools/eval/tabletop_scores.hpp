#pragma once
// How a segmentation of a real tabletop frame compares with its ground truth (tabletop_truth.hpp), per object:
// - found whole: one segment has IoU >= 0.5 with the object (a segment's pixels counted over the whole frame);
// - found in parts: the union of the segments lying at least 80% inside the object has IoU >= 0.5 with it; its
//   parts are those segments (an object found whole by one such segment is found in 1 part);
// - merged with the table: at least 30% of the object's pixels carry the table's label (the segment that holds
//   most of the table's pixels);
// - its best IoU (over single segments) and its unlabelled pixels (predicted label 0).
// And the table's largest share in one segment. Plain C++, no dependency on the library.
#include <cstdint>
#include <span>
#include <vector>

namespace pyrseg::eval {

inline constexpr double kWholeIou = 0.5;
inline constexpr double kInsideShare = 0.8;
inline constexpr double kTableMergeShare = 0.3;

struct TabletopObjectScore {
    std::uint32_t truth_id = 0;
    std::uint64_t pixels = 0;
    double best_iou = 0;
    bool whole = false;
    bool in_parts = false;
    std::uint32_t parts = 0;  // segments at least 80% inside the object
    bool merged_with_table = false;
    std::uint64_t unlabelled = 0;
};

struct TabletopScores {
    std::vector<TabletopObjectScore> objects;  // in truth id order
    std::uint64_t table_pixels = 0;
    double table_share = 0;         // the largest share of the table's pixels in one segment
    std::uint32_t table_label = 0;  // that segment (0: the table has no labelled pixel)
    [[nodiscard]] std::uint32_t whole() const;
    [[nodiscard]] std::uint32_t in_parts() const;
    [[nodiscard]] std::uint32_t merged_with_table() const;
    [[nodiscard]] double mean_best_iou() const;     // 0 without objects
    [[nodiscard]] double unlabelled_share() const;  // of all object pixels; 0 without objects
};

// truth: kTruthNone, kTruthTable or an object id per pixel; predicted: a segment label per pixel, 0 unlabelled.
// Throws std::invalid_argument when the lengths differ.
[[nodiscard]] TabletopScores score_tabletop(std::span<const std::uint32_t> truth,
                                            std::span<const std::uint32_t> predicted);

}  // namespace pyrseg::eval
