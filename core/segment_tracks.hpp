#pragma once
// Tracks (docs/algorithm.md section 11): the host's side, once for every backend. From a frame's overlap pairs
// (counted on the device, shaders/pyr_track.h) and its statistics, each segment gets the id of the track it
// continues, or a new one.
#include <cstdint>
#include <vector>

#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"

namespace pyrseg::core {

class TrackState {
public:
    // The next frame starts a new stream.
    void reset();
    // The next frame's number in its stream (0 after reset).
    [[nodiscard]] std::uint32_t frame() const { return frame_; }
    // One frame of a width x height stream: `pairs` a backend's table slots (previous label, label, pixels)
    // PYR_TRACK_SLOT_WORDS words each, `pair_count` of them in any order, free ones (a first word of 0) skipped (none
    // on the stream's first frame); `segments` the frame's K statistics (label k at k - 1).
    // Fills `out` with K tracks. Allocates only when the frame has more segments or pairs than any before.
    void next(const std::uint32_t* pairs, std::uint32_t pair_count, const std::vector<SegmentStats>& segments,
              int width, int height, const Params& params, std::vector<SegmentTrack>& out);

    struct Pair {
        std::uint32_t previous = 0, label = 0, pixels = 0;
    };
    struct WeightedPair : Pair {  // step 1's order: pixels times the track's age, the age capped at kMaxAgeWeight
        std::uint64_t weight = 0;
    };
    // The most frames of a track's age that weigh in step 1 (docs/algorithm.md section 11).
    static constexpr std::uint32_t kMaxAgeWeight = 32;
    struct Track {
        std::uint32_t id = 0;
        std::uint32_t first_frame = 0;
        std::uint32_t age = 0;
        std::uint32_t last_seen = 0;
        std::uint32_t pixels = 0;  // its last pixel count
        std::uint32_t label = 0;   // its label in the previous frame; 0 when it was not seen there
        bool has_centroid = false;
        bool on_border = false;  // its last segment touched the image's border
        double centroid[3] = {0, 0, 0};
    };
    struct Candidate {  // step 3's pairs
        double distance2 = 0;
        std::uint32_t id = 0, label = 0, track = 0;
    };

private:
    std::uint32_t frame_ = 0;  // the next frame's number in the stream
    std::uint32_t next_id_ = 1;
    std::vector<Track> tracks_;                 // live and hidden tracks
    std::vector<std::uint32_t> by_previous_;    // previous label j -> index in tracks_ + 1
    std::vector<std::uint32_t> previous_size_;  // previous label j -> its pixel count
    // Per frame, sized to the largest frame so far.
    std::vector<WeightedPair> pairs_;     // step 1's pairs, in the order it takes them
    std::vector<std::uint32_t> matched_;  // label k -> index in tracks_ + 1 (0: not matched yet)
    std::vector<std::uint32_t> overlap_;  // label k -> the pixels it shares with the track it matched in step 1
    std::vector<std::uint8_t> track_taken_;
    std::vector<Candidate> candidates_;
};

}  // namespace pyrseg::core
