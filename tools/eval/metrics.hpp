#pragma once
// Segmentation quality against ground truth, for `pyrseg eval` (docs/quality.md).
//
// Everything is computed over the pixels that have ground truth (truth != 0); other pixels are ignored whatever
// their predicted label. Predicted label 0 means "unlabelled". A ground-truth object is a truth id; it is
// *evaluated* when it has at least min_object_pixels pixels.
//
// - A predicted segment s *claims* object A when s holds more than half of A's pixels (so at most one segment
//   claims A; unlabelled pixels count as not held).
// - Merge: an evaluated object A is *merged* when the segment claiming it also claims another evaluated object.
// - Separable merge: the same, counting only other objects that are not flush with A (synthetic::flush_pairs: two
//   objects, or a chain of them, whose surfaces meet with no depth step and no crease, which depth alone cannot
//   tell apart). Without flush pairs it equals the merge count.
// - Split (over-segmentation): an evaluated object A is *split* when its largest predicted segment holds less than
//   split_share (80%) of A's labelled pixels, or when none of A's pixels is labelled.
// - Labelled: the share of ground-truth pixels with a predicted label.
// - Adjusted Rand index (Hubert and Arabie) of the two partitions of the ground-truth pixels, each unlabelled
//   pixel counting as a cluster of its own (a singleton: it is in no pair with any other pixel).
#include <array>
#include <cstdint>
#include <span>

namespace pyrseg::eval {

inline constexpr std::uint32_t kMinObjectPixels = 100;
inline constexpr double kSplitShare = 0.8;

struct Scores {
    std::uint64_t pixels = 0;            // pixels with ground truth
    std::uint64_t labelled = 0;          // of those, pixels with a predicted label
    std::uint32_t objects = 0;           // evaluated ground-truth objects
    std::uint32_t merged = 0;            // of those, merged
    std::uint32_t merged_separable = 0;  // of those, merged with an object they are not flush with
    std::uint32_t split = 0;             // of those, split
    std::uint32_t segments = 0;          // distinct non-zero predicted labels on ground-truth pixels
    double ari = 1.0;  // adjusted Rand index; 1 when both partitions are trivial (fewer than 2 pixels, or
                       // a denominator of 0, as scikit-learn does)
};

// truth and predicted have the same length (one entry per pixel). Linear in the pixels plus the contingency
// table's entries; counts are 64-bit integers, the index is exact up to the final division.
// flush_pairs: pairs of truth ids that are flush (synthetic::flush_pairs); ids absent from truth are ignored.
[[nodiscard]] Scores score(std::span<const std::uint32_t> truth, std::span<const std::uint32_t> predicted,
                           std::uint32_t min_object_pixels = kMinObjectPixels, double split_share = kSplitShare,
                           std::span<const std::array<std::uint32_t, 2>> flush_pairs = {});

// Only the adjusted Rand index (the same definition as Scores::ari).
[[nodiscard]] double adjusted_rand_index(std::span<const std::uint32_t> truth,
                                         std::span<const std::uint32_t> predicted);

}  // namespace pyrseg::eval
