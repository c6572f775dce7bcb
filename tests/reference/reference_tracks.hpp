#pragma once
// The independent oracle for tracks (docs/algorithm.md section 11): segment ids that carry over from frame to frame,
// written from that text only. Plain rather than fast: the overlap counts are a std::map over the pixels.
#include <cstdint>
#include <map>
#include <vector>

#include "reference/reference.hpp"

namespace pyrseg_ref {

struct TrackParams {
    double unit_mm = 1.0;           // the caller's unit in millimetres (finite, > 0)
    double max_distance_mm = 50.0;  // track_max_distance_mm (not NaN, >= 0)
    int hold_frames = 10;           // track_hold_frames (>= 0)
};

// How a segment got its id: a new track, step 1 (overlap) or step 3 (position).
enum class TrackMatch { new_track, overlap, position };

// One segment's track (section 11's result).
struct Track {
    std::uint32_t label = 0;          // k
    std::uint32_t id = 0;             // the track id, from 1
    std::uint32_t first_frame = 0;    // the frame the id was first seen in
    std::uint32_t age = 0;            // the frames it was seen in, this one included
    std::uint32_t hidden_frames = 0;  // the frames it was hidden before this one (0 when seen in the previous or new)
    TrackMatch how = TrackMatch::new_track;
};

class Tracker {
public:
    // Throws std::invalid_argument for parameters out of their ranges above.
    explicit Tracker(const TrackParams& params);

    // The next frame of the stream: its compacted labels (width*height, row-major, 0 = unlabelled, 1..K) and K
    // segments' statistics (segments[k-1] is label k; step 2 reads their bounding boxes against W = width and
    // H = height). Returns K tracks, in k's order. Throws std::invalid_argument (and changes nothing) when width or
    // height is negative, the labels' size is not width*height, a label exceeds K, or width or height differs from
    // the previous frame's.
    std::vector<Track> next(const std::vector<std::uint32_t>& labels, int width, int height,
                            const std::vector<Segment>& segments);
    // Convenience: next(out.labels, width, height, out.segments). Throws std::invalid_argument when !out.ok.
    std::vector<Track> next(const Output& out, int width, int height);
    // A new stream: frame 0 next, no previous labels, no tracks, ids from 1 again.
    void reset();

private:
    struct State {
        std::uint32_t first_frame = 0;
        std::uint32_t age = 0;
        std::uint32_t last_seen = 0;
        bool has_centroid = false;
        double centroid[3] = {0, 0, 0};
        std::uint32_t pixel_count = 0;
        bool border = false;      // whether its last segment touched the image's border (step 2)
        std::uint32_t label = 0;  // its label in the previous frame; meaningful only when last_seen + 1 == frame_
    };

    TrackParams params_;
    std::uint32_t frame_ = 0;  // f of the next frame
    std::uint32_t next_id_ = 1;
    bool has_previous_ = false;
    int previous_width_ = 0;
    int previous_height_ = 0;
    std::vector<std::uint32_t> previous_;    // P
    std::map<std::uint32_t, State> tracks_;  // by id: the tracks still held (seen in the previous frame, or hidden)
};

}  // namespace pyrseg_ref
