// The tracks oracle, written from docs/algorithm.md section 11 (and section 10 for the centroid) only. Each double
// operation of steps 2 and 3 is its own statement, in the order the text gives, so no contraction or reassociation can
// change a rounding even without -ffp-contract=off.
#include "reference/reference_tracks.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace pyrseg_ref {
namespace {

struct Centroid {
    bool has = false;
    double c[3] = {0, 0, 0};
};

// Section 10 / 11: c_k = (double(S_k) * 2^-e) / double(fillable count) per coordinate; none without fillable pixels.
Centroid centroid_of(const Segment& s) {
    Centroid out;
    if (s.fillable_count == 0) return out;
    out.has = true;
    const double scale = std::ldexp(1.0, -s.point_shift);  // 2^-e, exact for e in -126..127
    const double count = static_cast<double>(s.fillable_count);
    for (int a = 0; a < 3; ++a) {
        const double scaled = static_cast<double>(s.point_sum[a]) * scale;
        out.c[a] = scaled / count;
    }
    return out;
}

// max(a, b) <= 4 min(a, b), exactly.
bool sizes_close(std::uint32_t a, std::uint32_t b) {
    const std::uint64_t hi = std::max(a, b);
    const std::uint64_t lo = std::min(a, b);
    return hi <= 4 * lo;
}

// Step 2: the segment's bounding box (inclusive, section 10) reaches column 0 or W - 1, or row 0 or H - 1.
bool touches_border(const Segment& s, int width, int height) {
    return s.x_min <= 0 || s.y_min <= 0 || s.x_max >= width - 1 || s.y_max >= height - 1;
}

}  // namespace

Tracker::Tracker(const TrackParams& params) : params_(params) {
    if (!std::isfinite(params.unit_mm) || !(params.unit_mm > 0.0)) {
        throw std::invalid_argument("TrackParams::unit_mm must be finite and > 0");
    }
    if (std::isnan(params.max_distance_mm) || params.max_distance_mm < 0.0) {
        throw std::invalid_argument("TrackParams::max_distance_mm must be >= 0");
    }
    if (params.hold_frames < 0) throw std::invalid_argument("TrackParams::hold_frames must be >= 0");
}

void Tracker::reset() {
    // "until reset_tracks()": a new stream, so frame numbers and ids start again (ids are unique within a stream).
    frame_ = 0;
    next_id_ = 1;
    has_previous_ = false;
    previous_width_ = 0;
    previous_height_ = 0;
    previous_.clear();
    tracks_.clear();
}

std::vector<Track> Tracker::next(const Output& out, int width, int height) {
    if (!out.ok) throw std::invalid_argument("Tracker::next: the Output is not ok");
    return next(out.labels, width, height, out.segments);
}

std::vector<Track> Tracker::next(const std::vector<std::uint32_t>& labels, int width, int height,
                                 const std::vector<Segment>& segments) {
    const std::size_t K = segments.size();
    if (width < 0 || height < 0) throw std::invalid_argument("Tracker::next: negative width or height");
    if (labels.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
        throw std::invalid_argument("Tracker::next: the labels' size is not width * height");
    }
    if (has_previous_ && (width != previous_width_ || height != previous_height_)) {
        throw std::invalid_argument("Tracker::next: the frame's size differs from the previous frame's");
    }
    for (std::uint32_t label : labels) {
        if (label > K) throw std::invalid_argument("Tracker::next: a label exceeds the segment count");
    }
    const std::uint32_t f = frame_;

    // This frame's n_k and c_k, indexed by k (index 0 unused).
    std::vector<std::uint32_t> n(K + 1, 0);
    std::vector<Centroid> c(K + 1);
    std::vector<bool> border(K + 1, false);
    for (std::size_t k = 1; k <= K; ++k) {
        n[k] = segments[k - 1].pixel_count;
        c[k] = centroid_of(segments[k - 1]);
        border[k] = touches_border(segments[k - 1], width, height);
    }

    // The tracks seen in the previous frame, by their label j there.
    std::map<std::uint32_t, std::uint32_t> id_of_label;
    if (has_previous_) {
        for (const auto& [id, s] : tracks_) {
            if (s.last_seen + 1 == f) id_of_label[s.label] = id;
        }
    }

    // Overlap counts m(j, k): one count per pixel with P(p) != 0 and O(p) != 0.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint64_t> m;
    if (has_previous_) {
        for (std::size_t p = 0; p < labels.size(); ++p) {
            if (previous_[p] != 0 && labels[p] != 0) ++m[{previous_[p], labels[p]}];
        }
    }

    // Step 1, by overlap weighted by age: a greedy assignment. The pairs with 8 m(j, k) >= min(n_k, n'_j) (n'_j the
    // pixel count of the track seen as j), in decreasing w = m(j, k) * min(a_j, 32) (a_j that track's age before
    // this frame), then decreasing m, then increasing j, then increasing k; a pair whose j and k are both still
    // unmatched matches. Only the pairs with a count are listed (a pair with m = 0 shares nothing).
    std::vector<std::tuple<std::uint64_t, std::uint64_t, std::uint32_t, std::uint32_t>> overlap_pairs;  // (w, m, j, k)
    for (const auto& [jk, count] : m) {
        const auto [j, k] = jk;
        const State& track = tracks_.at(id_of_label.at(j));
        const std::uint64_t smaller = std::min<std::uint64_t>(n[k], track.pixel_count);
        const std::uint64_t weight = count * std::min<std::uint64_t>(track.age, 32);
        if (8 * count >= smaller) overlap_pairs.emplace_back(weight, count, j, k);
    }
    std::sort(overlap_pairs.begin(), overlap_pairs.end(), [](const auto& a, const auto& b) {
        if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
        if (std::get<1>(a) != std::get<1>(b)) return std::get<1>(a) > std::get<1>(b);
        if (std::get<2>(a) != std::get<2>(b)) return std::get<2>(a) < std::get<2>(b);
        return std::get<3>(a) < std::get<3>(b);
    });
    std::vector<std::uint32_t> id_of(K + 1, 0);  // k -> its track's id, 0 while unmatched
    std::vector<TrackMatch> how(K + 1, TrackMatch::new_track);
    std::vector<std::uint64_t> overlap_of(K + 1, 0);  // m(j, k) of k's step-1 pair
    std::set<std::uint32_t> matched_ids;
    for (const auto& [weight, count, j, k] : overlap_pairs) {
        const std::uint32_t id = id_of_label.at(j);
        if (how[k] != TrackMatch::new_track || matched_ids.count(id) != 0) continue;
        id_of[k] = id;
        how[k] = TrackMatch::overlap;
        overlap_of[k] = count;
        matched_ids.insert(id);
    }

    // Step 2, the camera's motion t, summed in increasing k over the step-1 pairs where both centroids exist and
    // neither segment touches the border (the previous one as its track remembers, from the previous frame).
    double num[3] = {0, 0, 0};
    double den = 0.0;
    for (std::uint32_t k = 1; k <= K; ++k) {
        if (how[k] != TrackMatch::overlap) continue;
        const State& s = tracks_.at(id_of[k]);
        if (!c[k].has || !s.has_centroid) continue;
        if (border[k] || s.border) continue;
        const double w = static_cast<double>(overlap_of[k]);
        for (int a = 0; a < 3; ++a) {
            const double diff = c[k].c[a] - s.centroid[a];
            const double term = w * diff;
            num[a] = num[a] + term;
        }
        den = den + w;
    }
    double t[3] = {0, 0, 0};
    if (den > 0.0) {
        for (int a = 0; a < 3; ++a) t[a] = num[a] / den;
    }

    // Step 3, by position: a greedy assignment over the pairs meeting the distance and the size conditions, in
    // increasing d^2, then increasing id, then increasing k; a pair whose k and s are both still unmatched matches.
    const double D = params_.max_distance_mm / params_.unit_mm;
    const double D2 = D * D;
    auto d2_of = [&](std::uint32_t k, const State& s) {
        double d[3];
        for (int a = 0; a < 3; ++a) {
            const double predicted = s.centroid[a] + t[a];
            d[a] = c[k].c[a] - predicted;
        }
        const double xx = d[0] * d[0];
        const double yy = d[1] * d[1];
        const double zz = d[2] * d[2];
        const double xy = xx + yy;
        return xy + zz;
    };
    std::vector<std::uint32_t> position_segments;  // unmatched segments with a centroid, increasing k
    for (std::uint32_t k = 1; k <= K; ++k) {
        if (how[k] == TrackMatch::new_track && c[k].has) position_segments.push_back(k);
    }
    std::vector<std::uint32_t> position_tracks;  // unmatched tracks with a centroid, increasing id
    for (const auto& [id, s] : tracks_) {
        if (matched_ids.count(id) == 0 && s.has_centroid) position_tracks.push_back(id);
    }
    std::vector<std::tuple<double, std::uint32_t, std::uint32_t>> position_pairs;  // (d^2, id, k)
    for (std::uint32_t k : position_segments) {
        for (std::uint32_t id : position_tracks) {
            const State& s = tracks_.at(id);
            const double d2 = d2_of(k, s);
            if (d2 <= D2 && sizes_close(n[k], s.pixel_count)) position_pairs.emplace_back(d2, id, k);
        }
    }
    std::sort(position_pairs.begin(), position_pairs.end(), [](const auto& a, const auto& b) {
        if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) < std::get<0>(b);
        if (std::get<1>(a) != std::get<1>(b)) return std::get<1>(a) < std::get<1>(b);
        return std::get<2>(a) < std::get<2>(b);
    });
    for (const auto& [d2, id, k] : position_pairs) {
        if (how[k] != TrackMatch::new_track || matched_ids.count(id) != 0) continue;
        id_of[k] = id;
        how[k] = TrackMatch::position;
        matched_ids.insert(id);
    }

    // Step 4, new tracks in increasing k. Step 5, the update of the matched and new tracks.
    std::vector<Track> result(K);
    for (std::uint32_t k = 1; k <= K; ++k) {
        Track& r = result[k - 1];
        r.label = k;
        r.how = how[k];
        if (how[k] == TrackMatch::new_track) {
            const std::uint32_t id = next_id_++;
            State& s = tracks_[id];
            s.first_frame = f;
            s.age = 0;
            s.last_seen = f;  // so that hidden_frames below is 0
            id_of[k] = id;
        }
        State& s = tracks_.at(id_of[k]);
        r.id = id_of[k];
        r.first_frame = s.first_frame;
        r.hidden_frames = s.last_seen == f ? 0 : f - s.last_seen - 1;
        s.age = s.age + 1;
        s.last_seen = f;
        s.has_centroid = c[k].has;
        for (int a = 0; a < 3; ++a) s.centroid[a] = c[k].has ? c[k].c[a] : 0.0;
        s.pixel_count = n[k];
        s.border = border[k];
        s.label = k;
        r.age = s.age;
    }
    // Step 5, the tracks not matched: hidden, their centroid moved by t; dropped once f - last seen > hold_frames.
    // Ambiguity: the drop is read as part of this frame's update, after matching, so a track last seen in frame
    // f0 can still be matched in frame f0 + hold_frames + 1 (hidden hold_frames frames) and is gone after it.
    for (auto it = tracks_.begin(); it != tracks_.end();) {
        State& s = it->second;
        if (s.last_seen == f) {
            ++it;
            continue;
        }
        if (s.has_centroid) {
            for (int a = 0; a < 3; ++a) s.centroid[a] = s.centroid[a] + t[a];
        }
        if (static_cast<std::int64_t>(f) - static_cast<std::int64_t>(s.last_seen) > params_.hold_frames) {
            it = tracks_.erase(it);
        } else {
            ++it;
        }
    }

    previous_ = labels;
    previous_width_ = width;
    previous_height_ = height;
    has_previous_ = true;
    ++frame_;
    return result;
}

}  // namespace pyrseg_ref
