#pragma once
// Identity over time, for `pyrseg eval --tracks` (docs/quality.md): how well ids that carry over from frame to frame
// follow the ground truth's objects, as multi-object tracking measures it, and the host-side matcher a user would
// write as the baseline. Plain C++: no dependency on the library.
//
// Per frame, each ground-truth object in view (at least min_pixels pixels) is *matched* to the predicted id that
// covers most of its pixels among the ids whose IoU with it is at least 0.5 (so at most one; the smaller id among
// equals), or *missed*. The predicted *detections* of a frame are its matched ids and the ids of at least
// min_pixels pixels that lie mostly (more than half) on objects; ids mostly on the floor, the bin or pixels without
// ground truth are not scored (as benchmarks leave out detections of what is not a target).
//
// Over a sequence, per object (its frames in view, in order):
// - ID switches (CLEAR MOT, Bernardin and Stiefelhagen 2008): a matched frame whose id differs from the id of the
//   object's previous matched frame. Counted twice: all of them, and *in view* only: those where the object was in
//   view in every frame since that previous match (an object that left the view or was hidden and came back under
//   another id is not an in-view switch).
// - Fragmentations (as py-motmetrics counts them): the times a matched frame is followed by a missed one, between
//   the object's first and last matched frames; the object's trajectory is interrupted there.
// - IDF1 (Ristani et al. 2016): the one-to-one assignment between truth objects and predicted ids (over the whole
//   sequence) that maximizes the frames in which the two are matched, IDTP; IDFN = object frames in view - IDTP,
//   IDFP = predicted detections - IDTP, IDF1 = 2 IDTP / (2 IDTP + IDFP + IDFN).
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace pyrseg::eval {

inline constexpr double kTrackMatchIou = 0.5;

// The rows-to-columns assignment of least total cost (Kuhn-Munkres with potentials, O(n^2 m) for n = min(rows,
// cols), m = max(rows, cols)): result[r] is row r's column, or -1 when there are more rows than columns and r is
// left out. cost is rows x cols, row-major, finite.
[[nodiscard]] std::vector<int> min_cost_assignment(std::span<const double> cost, std::size_t rows, std::size_t cols);

// One frame: the objects in view, each with its matched id (0: missed), by increasing truth id; and the predicted
// detections, distinct, increasing.
struct FrameMatches {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> objects;
    std::vector<std::uint32_t> detections;
};

// truth: the frame's ground truth ids (objects are the ids >= first_object_id; 0 is no ground truth); ids: the
// predicted ids (0: unlabelled), one per pixel as truth.
[[nodiscard]] FrameMatches match_frame(std::span<const std::uint32_t> truth, std::span<const std::uint32_t> ids,
                                       std::uint32_t first_object_id, std::uint32_t min_pixels);

// One method's scores over one sequence, or summed over several (add).
struct TrackScores {
    std::uint64_t sequences = 0;
    std::uint64_t frames = 0;
    std::uint64_t objects = 0;        // objects in view in some frame (per sequence)
    std::uint64_t object_frames = 0;  // (object, frame) pairs in view
    std::uint64_t matched = 0;        // of those, matched to an id
    std::uint64_t detections = 0;     // predicted detections, all frames
    std::uint64_t switches = 0;       // ID switches
    std::uint64_t switches_in_view = 0;
    std::uint64_t fragmentations = 0;
    std::uint64_t idtp = 0;
    // The most in-view switches per 100 of its frames in view of one object that was in view for at least
    // kWorstObjectFrames frames (0 when none was).
    double worst_object_rate = 0;
    void add(const TrackScores& other);
    [[nodiscard]] double switches_per_100() const;  // in-view switches per object per 100 frames in view; NaN: none
    [[nodiscard]] double idf1() const;              // NaN when there is nothing to score
    [[nodiscard]] double matched_share() const;     // matched / object_frames; NaN when none
    [[nodiscard]] double identity_share() const;    // idtp / matched: identity alone; NaN when none matched
};
inline constexpr std::uint64_t kWorstObjectFrames = 100;

// An in-view ID switch: the frame (index in the sequence) and the object, for callers that look into the causes.
struct SwitchEvent {
    std::size_t frame = 0;
    std::uint32_t object = 0;
    std::uint32_t id = 0;  // the id the object switched to
    friend bool operator==(const SwitchEvent&, const SwitchEvent&) = default;
};

// in_view_switches, when given, receives every in-view switch, by object then frame.
[[nodiscard]] TrackScores score_tracks(std::span<const FrameMatches> frames,
                                       std::vector<SwitchEvent>* in_view_switches = nullptr);

// The baseline: a host-side tracker as a user would write it over per-frame labels. Each frame's segments are
// matched to the previous frame's ids by the assignment that maximizes the pixels they share (min_cost_assignment on
// minus the overlap), a pair counting only when its IoU is at least min_iou; a segment left unmatched gets a new id
// (from 1, never reused).
class OverlapMatcher {
public:
    explicit OverlapMatcher(double min_iou) : min_iou_(min_iou) {}
    // labels: one frame's labels (0: unlabelled), the same size every frame; ids: the same size, each labelled
    // pixel's id (0 where unlabelled).
    void track(std::span<const std::uint32_t> labels, std::vector<std::uint32_t>& ids);
    void reset();  // the next frame starts a new sequence

private:
    double min_iou_;
    std::vector<std::uint32_t> previous_;  // the previous frame's ids (empty before the first frame)
    std::uint32_t next_id_ = 1;
};

}  // namespace pyrseg::eval
