#include "core/segment_tracks.hpp"

#include <algorithm>
#include <cmath>

#include "shaders/pyr_types.h"

namespace pyrseg::core {

namespace {

bool has_centroid(const SegmentStats& s) {
    return s.fillable_count > 0 && std::isfinite(s.centroid[0]) && std::isfinite(s.centroid[1]) &&
           std::isfinite(s.centroid[2]);
}

// Step 3's distance (docs/algorithm.md section 11): d = c_k - (c_s + t), in this order.
double distance2(const double* c, const double* track, const double* t) {
    const double dx = c[0] - (track[0] + t[0]);
    const double dy = c[1] - (track[1] + t[1]);
    const double dz = c[2] - (track[2] + t[2]);
    return dx * dx + dy * dy + dz * dz;
}

bool sizes_agree(std::uint32_t a, std::uint32_t b) {
    return std::uint64_t(std::max(a, b)) <= 4 * std::uint64_t(std::min(a, b));
}

}  // namespace

void TrackState::reset() {
    frame_ = 0;
    next_id_ = 1;
    tracks_.clear();
    by_previous_.clear();
    previous_size_.clear();
}

void TrackState::next(const std::uint32_t* pairs, std::uint32_t pair_count, const std::vector<SegmentStats>& segments,
                      int width, int height, const Params& params, std::vector<SegmentTrack>& out) {
    const auto count = std::uint32_t(segments.size());
    const std::uint32_t f = frame_;
    const std::uint32_t previous_count = by_previous_.empty() ? 0 : std::uint32_t(by_previous_.size() - 1);
    out.resize(count);
    const auto on_border = [&](const SegmentStats& s) {
        return s.x_min <= 0 || s.y_min <= 0 || s.x_max >= width - 1 || s.y_max >= height - 1;
    };

    // Step 1: by overlap, greedily: the pairs sharing at least an eighth of the smaller, the largest overlap times
    // its track's age (up to 32 frames) first.
    pairs_.clear();
    for (std::uint32_t i = 0; i < pair_count; ++i) {
        const std::uint32_t* w = pairs + std::size_t(PYR_TRACK_SLOT_WORDS) * i;
        const Pair pair{w[0], w[1], w[2]};
        // Free slots (a first word of 0) come from a GPU's table; labels are 1..K.
        if (pair.previous == 0 || pair.previous > previous_count || pair.label == 0 || pair.label > count) continue;
        if (by_previous_[pair.previous] == 0) continue;
        const std::uint32_t smaller = std::min(segments[pair.label - 1].pixel_count, previous_size_[pair.previous]);
        if (8 * std::uint64_t(pair.pixels) < smaller) continue;
        const std::uint32_t age = tracks_[by_previous_[pair.previous] - 1].age;
        pairs_.push_back({pair, std::uint64_t(pair.pixels) * std::min(age, kMaxAgeWeight)});
    }
    std::sort(pairs_.begin(), pairs_.end(), [](const WeightedPair& a, const WeightedPair& b) {
        if (a.weight != b.weight) return a.weight > b.weight;
        if (a.pixels != b.pixels) return a.pixels > b.pixels;
        return a.previous != b.previous ? a.previous < b.previous : a.label < b.label;
    });
    matched_.assign(count + 1, 0);
    overlap_.assign(count + 1, 0);
    track_taken_.assign(tracks_.size(), 0);
    for (const WeightedPair& pair : pairs_) {
        const std::uint32_t track = by_previous_[pair.previous] - 1;
        if (matched_[pair.label] != 0 || track_taken_[track] != 0) continue;
        matched_[pair.label] = track + 1;
        overlap_[pair.label] = pair.pixels;
        track_taken_[track] = 1;
        out[pair.label - 1].how = TrackMatch::overlap;
    }

    // Step 2: the camera's motion, the overlap-weighted mean shift of the segments matched by overlap that the
    // image's border cuts in neither frame.
    double t[3] = {0, 0, 0};
    {
        double numerator[3] = {0, 0, 0};
        double denominator = 0;
        for (std::uint32_t k = 1; k <= count; ++k) {
            if (matched_[k] == 0) continue;
            const Track& track = tracks_[matched_[k] - 1];
            const SegmentStats& s = segments[k - 1];
            if (!track.has_centroid || !has_centroid(s) || track.on_border || on_border(s)) continue;
            const double m = double(overlap_[k]);
            for (int c = 0; c < 3; ++c) numerator[c] += m * (s.centroid[std::size_t(c)] - track.centroid[c]);
            denominator += m;
        }
        if (denominator > 0) {
            for (int c = 0; c < 3; ++c) t[c] = numerator[c] / denominator;
        }
    }

    // Step 3: by position, greedily: the pairs within the distance and with sizes within a factor of 4, the nearest
    // first.
    const double reach = params.track_max_distance_mm / params.unit_mm;
    const double reach2 = reach * reach;
    const auto track_count = std::uint32_t(tracks_.size());
    candidates_.clear();
    for (std::uint32_t k = 1; k <= count; ++k) {
        const SegmentStats& s = segments[k - 1];
        if (matched_[k] != 0 || !has_centroid(s)) continue;
        for (std::uint32_t i = 0; i < track_count; ++i) {
            const Track& track = tracks_[i];
            if (track_taken_[i] != 0 || !track.has_centroid || !sizes_agree(s.pixel_count, track.pixels)) continue;
            const double d2 = distance2(s.centroid.data(), track.centroid, t);
            if (d2 <= reach2) candidates_.push_back(Candidate{d2, track.id, k, i});
        }
    }
    std::sort(candidates_.begin(), candidates_.end(), [](const Candidate& a, const Candidate& b) {
        if (a.distance2 != b.distance2) return a.distance2 < b.distance2;
        return a.id != b.id ? a.id < b.id : a.label < b.label;
    });
    for (const Candidate& c : candidates_) {
        if (matched_[c.label] != 0 || track_taken_[c.track] != 0) continue;
        matched_[c.label] = c.track + 1;
        track_taken_[c.track] = 1;
        out[c.label - 1].how = TrackMatch::position;
    }

    // Steps 4 and 5: new tracks, then every track brought up to this frame.
    for (std::uint32_t k = 1; k <= count; ++k) {
        SegmentTrack& o = out[k - 1];
        o.label = k;
        const SegmentStats& s = segments[k - 1];
        if (matched_[k] == 0) {
            Track fresh;
            fresh.id = next_id_++;
            fresh.first_frame = f;
            tracks_.push_back(fresh);
            track_taken_.push_back(1);
            matched_[k] = std::uint32_t(tracks_.size());
            o.how = TrackMatch::new_track;
            o.hidden_frames = 0;
        } else {
            const Track& track = tracks_[matched_[k] - 1];
            o.hidden_frames = f - track.last_seen - 1;
        }
        Track& track = tracks_[matched_[k] - 1];
        track.last_seen = f;
        track.age += 1;
        track.pixels = s.pixel_count;
        track.label = k;
        track.has_centroid = has_centroid(s);
        track.on_border = on_border(s);
        for (int c = 0; c < 3; ++c) track.centroid[c] = track.has_centroid ? s.centroid[std::size_t(c)] : 0.0;
        o.id = track.id;
        o.first_frame = track.first_frame;
        o.age = track.age;
    }
    for (std::uint32_t i = 0; i < track_count; ++i) {
        if (track_taken_[i] != 0) continue;
        Track& track = tracks_[i];
        track.label = 0;
        if (track.has_centroid) {
            for (int c = 0; c < 3; ++c) track.centroid[c] += t[c];
        }
    }
    const auto hold = std::uint32_t(params.track_hold_frames);
    std::erase_if(tracks_, [&](const Track& track) { return f - track.last_seen > hold; });
    by_previous_.assign(count + 1, 0);
    previous_size_.assign(count + 1, 0);
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
        if (tracks_[i].label != 0) by_previous_[tracks_[i].label] = std::uint32_t(i + 1);
    }
    for (std::uint32_t k = 1; k <= count; ++k) previous_size_[k] = segments[k - 1].pixel_count;
    ++frame_;
}

}  // namespace pyrseg::core
