#include "tools/eval/tracks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace pyrseg::eval {
namespace {

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t{a} << 32) | b;
}

}  // namespace

std::vector<int> min_cost_assignment(std::span<const double> cost, std::size_t rows, std::size_t cols) {
    if (cost.size() != rows * cols) throw std::invalid_argument("min_cost_assignment: cost is not rows x cols");
    std::vector<int> out(rows, -1);
    if (rows == 0 || cols == 0) return out;
    // The shorter side is assigned into the longer (e-maxx's formulation, 1-based, with potentials u and v).
    const bool transposed = rows > cols;
    const std::size_t n = transposed ? cols : rows, m = transposed ? rows : cols;
    const auto a = [&](std::size_t i, std::size_t j) { return transposed ? cost[j * cols + i] : cost[i * cols + j]; };
    constexpr double kInf = std::numeric_limits<double>::infinity();
    std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0), min_v(m + 1);
    std::vector<std::size_t> p(m + 1, 0), way(m + 1, 0);
    std::vector<char> used(m + 1);
    for (std::size_t i = 1; i <= n; ++i) {
        p[0] = i;
        std::size_t j0 = 0;
        std::fill(min_v.begin(), min_v.end(), kInf);
        std::fill(used.begin(), used.end(), 0);
        do {
            used[j0] = 1;
            const std::size_t i0 = p[j0];
            double delta = kInf;
            std::size_t j1 = 0;
            for (std::size_t j = 1; j <= m; ++j) {
                if (used[j] != 0) continue;
                const double reduced = a(i0 - 1, j - 1) - u[i0] - v[j];
                if (reduced < min_v[j]) {
                    min_v[j] = reduced;
                    way[j] = j0;
                }
                if (min_v[j] < delta) {
                    delta = min_v[j];
                    j1 = j;
                }
            }
            for (std::size_t j = 0; j <= m; ++j) {
                if (used[j] != 0) {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    min_v[j] -= delta;
                }
            }
            j0 = j1;
        } while (p[j0] != 0);
        do {
            const std::size_t j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
        } while (j0 != 0);
    }
    for (std::size_t j = 1; j <= m; ++j) {
        if (p[j] == 0) continue;
        if (transposed) {
            out[j - 1] = static_cast<int>(p[j] - 1);
        } else {
            out[p[j] - 1] = static_cast<int>(j - 1);
        }
    }
    return out;
}

FrameMatches match_frame(std::span<const std::uint32_t> truth, std::span<const std::uint32_t> ids,
                         std::uint32_t first_object_id, std::uint32_t min_pixels) {
    if (truth.size() != ids.size()) throw std::invalid_argument("match_frame: truth and ids differ in size");
    std::map<std::uint32_t, std::uint64_t> object_pixels;
    std::unordered_map<std::uint32_t, std::uint64_t> id_pixels, id_on_objects;
    std::unordered_map<std::uint64_t, std::uint64_t> shared;
    for (std::size_t i = 0; i < truth.size(); ++i) {
        const std::uint32_t t = truth[i], h = ids[i];
        const bool object = t >= first_object_id;
        if (object) ++object_pixels[t];
        if (h == 0) continue;
        ++id_pixels[h];
        if (object) {
            ++id_on_objects[h];
            ++shared[pair_key(t, h)];
        }
    }
    // The ids each object shares pixels with.
    std::map<std::uint32_t, std::vector<std::pair<std::uint32_t, std::uint64_t>>> candidates;
    for (const auto& [key, count] : shared) {
        candidates[static_cast<std::uint32_t>(key >> 32)].emplace_back(static_cast<std::uint32_t>(key), count);
    }
    FrameMatches out;
    std::vector<std::uint32_t> used;
    for (const auto& [t, n] : object_pixels) {
        if (n < min_pixels) continue;
        std::uint32_t best = 0;
        std::uint64_t best_count = 0;
        for (const auto& [h, c] : candidates[t]) {
            const std::uint64_t union_pixels = n + id_pixels[h] - c;
            if (2 * c < union_pixels) continue;  // IoU below 0.5
            if (std::find(used.begin(), used.end(), h) != used.end()) continue;
            if (c > best_count || (c == best_count && h < best)) {
                best = h;
                best_count = c;
            }
        }
        if (best != 0) used.push_back(best);
        out.objects.emplace_back(t, best);
    }
    for (const auto& [h, n] : id_pixels) {
        if (n >= min_pixels && 2 * id_on_objects[h] > n) used.push_back(h);
    }
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    out.detections = std::move(used);
    return out;
}

void TrackScores::add(const TrackScores& o) {
    sequences += o.sequences;
    frames += o.frames;
    objects += o.objects;
    object_frames += o.object_frames;
    matched += o.matched;
    detections += o.detections;
    switches += o.switches;
    switches_in_view += o.switches_in_view;
    fragmentations += o.fragmentations;
    idtp += o.idtp;
    worst_object_rate = std::max(worst_object_rate, o.worst_object_rate);
}

double TrackScores::switches_per_100() const {
    return object_frames == 0 ? std::nan("") : 100.0 * double(switches_in_view) / double(object_frames);
}

double TrackScores::idf1() const {
    // 2 IDTP + IDFP + IDFN = object frames + detections.
    const std::uint64_t denominator = object_frames + detections;
    return denominator == 0 ? std::nan("") : 2.0 * double(idtp) / double(denominator);
}

double TrackScores::matched_share() const {
    return object_frames == 0 ? std::nan("") : double(matched) / double(object_frames);
}

double TrackScores::identity_share() const {
    return matched == 0 ? std::nan("") : double(idtp) / double(matched);
}

TrackScores score_tracks(std::span<const FrameMatches> frames, std::vector<SwitchEvent>* in_view_switches) {
    TrackScores s;
    s.sequences = 1;
    s.frames = frames.size();
    // Each object's frames in view: (frame, id or 0).
    std::map<std::uint32_t, std::vector<std::pair<std::size_t, std::uint32_t>>> seen;
    std::map<std::uint64_t, std::uint64_t> together;  // (object, id) -> frames matched
    for (std::size_t f = 0; f < frames.size(); ++f) {
        s.detections += frames[f].detections.size();
        for (const auto& [t, h] : frames[f].objects) {
            seen[t].emplace_back(f, h);
            if (h != 0) ++together[pair_key(t, h)];
        }
    }
    for (const auto& [t, track] : seen) {
        ++s.objects;
        s.object_frames += track.size();
        std::uint32_t last_id = 0;
        bool stayed = true;  // in view in every frame since the last match
        std::uint64_t in_view = 0;
        std::size_t first_matched = track.size(), last_matched = 0;
        for (std::size_t k = 0; k < track.size(); ++k) {
            const auto [f, h] = track[k];
            if (k > 0 && f != track[k - 1].first + 1) stayed = false;
            if (h == 0) continue;
            ++s.matched;
            first_matched = std::min(first_matched, k);
            last_matched = k;
            if (last_id != 0 && h != last_id) {
                ++s.switches;
                if (stayed) {
                    ++in_view;
                    if (in_view_switches != nullptr) in_view_switches->push_back({f, t, h});
                }
            }
            last_id = h;
            stayed = true;
        }
        s.switches_in_view += in_view;
        if (track.size() >= kWorstObjectFrames) {
            s.worst_object_rate = std::max(s.worst_object_rate, 100.0 * double(in_view) / double(track.size()));
        }
        for (std::size_t k = first_matched + 1; k <= last_matched && first_matched < track.size(); ++k) {
            if (track[k - 1].second != 0 && track[k].second == 0) ++s.fragmentations;
        }
    }
    // IDTP: the one-to-one assignment of objects to ids with the most frames matched together.
    std::vector<std::uint32_t> objects, ids;
    for (const auto& [key, count] : together) {
        objects.push_back(static_cast<std::uint32_t>(key >> 32));
        ids.push_back(static_cast<std::uint32_t>(key));
    }
    std::sort(objects.begin(), objects.end());
    objects.erase(std::unique(objects.begin(), objects.end()), objects.end());
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    std::vector<double> cost(objects.size() * ids.size(), 0.0);
    const auto index = [](const std::vector<std::uint32_t>& v, std::uint32_t x) {
        return static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), x) - v.begin());
    };
    for (const auto& [key, count] : together) {
        const std::size_t r = index(objects, static_cast<std::uint32_t>(key >> 32));
        const std::size_t c = index(ids, static_cast<std::uint32_t>(key));
        cost[r * ids.size() + c] = -double(count);
    }
    const std::vector<int> assigned = min_cost_assignment(cost, objects.size(), ids.size());
    for (std::size_t r = 0; r < objects.size(); ++r) {
        if (assigned[r] < 0) continue;
        s.idtp += static_cast<std::uint64_t>(-cost[r * ids.size() + static_cast<std::size_t>(assigned[r])]);
    }
    return s;
}

void OverlapMatcher::reset() {
    previous_.clear();
    next_id_ = 1;
}

void OverlapMatcher::track(std::span<const std::uint32_t> labels, std::vector<std::uint32_t>& ids) {
    if (!previous_.empty() && previous_.size() != labels.size()) {
        throw std::invalid_argument("OverlapMatcher: the frame's size changed");
    }
    std::map<std::uint32_t, std::uint64_t> label_pixels;  // by increasing label
    std::unordered_map<std::uint32_t, std::uint64_t> id_pixels;
    std::unordered_map<std::uint64_t, std::uint64_t> shared;  // (previous id, label)
    for (std::size_t i = 0; i < labels.size(); ++i) {
        const std::uint32_t k = labels[i];
        if (k != 0) ++label_pixels[k];
        if (previous_.empty()) continue;
        const std::uint32_t j = previous_[i];
        if (j != 0) ++id_pixels[j];
        if (j != 0 && k != 0) ++shared[pair_key(j, k)];
    }
    // The pairs that may match, and the labels and previous ids that take part in one.
    std::vector<std::uint32_t> rows, cols;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> eligible;  // (key, pixels shared)
    for (const auto& [key, c] : shared) {
        const auto j = static_cast<std::uint32_t>(key >> 32), k = static_cast<std::uint32_t>(key);
        const double iou = double(c) / double(label_pixels[k] + id_pixels[j] - c);
        if (iou < min_iou_) continue;
        eligible.emplace_back(key, c);
        rows.push_back(k);
        cols.push_back(j);
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    const auto index = [](const std::vector<std::uint32_t>& v, std::uint32_t x) {
        return static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), x) - v.begin());
    };
    std::vector<double> cost(rows.size() * cols.size(), 0.0);
    for (const auto& [key, c] : eligible) {
        cost[index(rows, static_cast<std::uint32_t>(key)) * cols.size() + index(cols, std::uint32_t(key >> 32))] =
            -double(c);
    }
    const std::vector<int> assigned = min_cost_assignment(cost, rows.size(), cols.size());
    std::unordered_map<std::uint32_t, std::uint32_t> id_of;
    for (std::size_t r = 0; r < rows.size(); ++r) {
        const int c = assigned[r];
        if (c >= 0 && cost[r * cols.size() + static_cast<std::size_t>(c)] < 0) {
            id_of[rows[r]] = cols[static_cast<std::size_t>(c)];
        }
    }
    for (const auto& [k, n] : label_pixels) {
        if (id_of.find(k) == id_of.end()) id_of[k] = next_id_++;
    }
    ids.resize(labels.size());
    for (std::size_t i = 0; i < labels.size(); ++i) ids[i] = labels[i] == 0 ? 0 : id_of[labels[i]];
    previous_ = ids;
}

}  // namespace pyrseg::eval
