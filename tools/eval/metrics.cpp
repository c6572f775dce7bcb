#include "tools/eval/metrics.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace pyrseg::eval {
namespace {

// n choose 2 without overflowing the intermediate product (exact while the result fits in 64 bits).
std::uint64_t pairs(std::uint64_t n) {
    return n % 2 == 0 ? (n / 2) * (n - 1) : n * ((n - 1) / 2);
}

// Dense indices for arbitrary uint32 labels, in order of first appearance.
class Dense {
public:
    std::uint32_t index(std::uint32_t label) {
        if (label == last_label_ && !counts_.empty()) return last_index_;
        const auto [it, added] = map_.try_emplace(label, static_cast<std::uint32_t>(counts_.size()));
        if (added) counts_.push_back(0);
        last_label_ = label;
        last_index_ = it->second;
        return it->second;
    }
    [[nodiscard]] std::size_t size() const { return counts_.size(); }
    [[nodiscard]] std::optional<std::uint32_t> find(std::uint32_t label) const {
        const auto it = map_.find(label);
        if (it == map_.end()) return std::nullopt;
        return it->second;
    }
    std::vector<std::uint64_t>& counts() { return counts_; }

private:
    std::unordered_map<std::uint32_t, std::uint32_t> map_;
    std::vector<std::uint64_t> counts_;
    std::uint32_t last_label_ = 0;
    std::uint32_t last_index_ = 0;
};

// The contingency table of (truth, predicted) over the pixels with truth != 0; predicted 0 is left out of the
// table (truth counts include those pixels).
struct Contingency {
    Dense truth;
    Dense predicted;                                         // non-zero labels only
    std::unordered_map<std::uint64_t, std::uint64_t> cells;  // (truth index << 32 | predicted index) -> pixels
    std::uint64_t pixels = 0;
    std::uint64_t labelled = 0;
};

Contingency tabulate(std::span<const std::uint32_t> truth, std::span<const std::uint32_t> predicted) {
    if (truth.size() != predicted.size()) throw std::invalid_argument("truth and prediction differ in size");
    Contingency c;
    // Runs of the same (truth, predicted) pair are counted locally and added to the table once.
    std::uint64_t run_key = 0;
    std::uint64_t run_length = 0;
    const auto flush = [&] {
        if (run_length != 0) c.cells[run_key] += run_length;
        run_length = 0;
    };
    for (std::size_t i = 0; i < truth.size(); ++i) {
        if (truth[i] == 0) continue;
        const std::uint32_t t = c.truth.index(truth[i]);
        ++c.truth.counts()[t];
        ++c.pixels;
        if (predicted[i] == 0) continue;
        const std::uint32_t p = c.predicted.index(predicted[i]);
        ++c.predicted.counts()[p];
        ++c.labelled;
        const std::uint64_t key = (std::uint64_t{t} << 32) | p;
        if (key != run_key) {
            flush();
            run_key = key;
        }
        ++run_length;
    }
    flush();
    return c;
}

double ari_of(Contingency& c) {
    if (c.pixels < 2) return 1.0;
    std::uint64_t index = 0;
    for (const auto& [key, n] : c.cells) index += pairs(n);
    std::uint64_t truth_pairs = 0;
    for (const std::uint64_t n : c.truth.counts()) truth_pairs += pairs(n);
    std::uint64_t predicted_pairs = 0;  // unlabelled pixels are singletons: no pairs
    for (const std::uint64_t n : c.predicted.counts()) predicted_pairs += pairs(n);
    const double total = static_cast<double>(pairs(c.pixels));
    const double expected = static_cast<double>(truth_pairs) * static_cast<double>(predicted_pairs) / total;
    const double maximum = 0.5 * (static_cast<double>(truth_pairs) + static_cast<double>(predicted_pairs));
    if (maximum == expected) return 1.0;
    return (static_cast<double>(index) - expected) / (maximum - expected);
}

}  // namespace

double adjusted_rand_index(std::span<const std::uint32_t> truth, std::span<const std::uint32_t> predicted) {
    Contingency c = tabulate(truth, predicted);
    return ari_of(c);
}

Scores score(std::span<const std::uint32_t> truth, std::span<const std::uint32_t> predicted,
             std::uint32_t min_object_pixels, double split_share,
             std::span<const std::array<std::uint32_t, 2>> flush_pairs) {
    Contingency c = tabulate(truth, predicted);
    Scores s;
    s.pixels = c.pixels;
    s.labelled = c.labelled;
    s.segments = static_cast<std::uint32_t>(c.predicted.size());
    s.ari = ari_of(c);

    const std::size_t objects = c.truth.size();
    const std::vector<std::uint64_t>& size = c.truth.counts();
    constexpr std::uint32_t kNone = 0xFFFFFFFFu;
    std::vector<std::uint64_t> labelled(objects, 0);
    std::vector<std::uint64_t> largest(objects, 0);
    std::vector<std::uint32_t> claimed_by(objects, kNone);
    for (const auto& [key, n] : c.cells) {
        const auto t = static_cast<std::size_t>(key >> 32);
        const auto p = static_cast<std::uint32_t>(key & 0xFFFFFFFFu);
        labelled[t] += n;
        if (n > largest[t]) largest[t] = n;
        if (2 * n > size[t]) claimed_by[t] = p;  // more than half: at most one segment per object
    }
    std::vector<std::uint32_t> claims(c.predicted.size(), 0);  // evaluated objects each segment claims
    for (std::size_t t = 0; t < objects; ++t) {
        if (size[t] < min_object_pixels) continue;
        ++s.objects;
        if (claimed_by[t] != kNone) ++claims[claimed_by[t]];
        if (labelled[t] == 0 || static_cast<double>(largest[t]) < split_share * static_cast<double>(labelled[t])) {
            ++s.split;
        }
    }
    for (std::size_t t = 0; t < objects; ++t) {
        if (size[t] >= min_object_pixels && claimed_by[t] != kNone && claims[claimed_by[t]] >= 2) ++s.merged;
    }

    // Flush groups over the truth indices (union-find, smallest index as the root), then the separable merges:
    // the objects whose claiming segment also claims an evaluated object of another group.
    std::vector<std::size_t> group(objects);
    for (std::size_t t = 0; t < objects; ++t) group[t] = t;
    const auto root = [&](std::size_t t) {
        while (group[t] != t) t = group[t] = group[group[t]];
        return t;
    };
    for (const auto& [a, b] : flush_pairs) {
        const auto ia = c.truth.find(a);
        const auto ib = c.truth.find(b);
        if (!ia || !ib) continue;
        const std::size_t ra = root(*ia);
        const std::size_t rb = root(*ib);
        group[std::max(ra, rb)] = std::min(ra, rb);
    }
    // Per segment: the group of the first evaluated object it claims, and whether it claims another group too.
    std::vector<std::size_t> first_group(c.predicted.size(), objects);
    std::vector<std::uint8_t> mixed(c.predicted.size(), 0);
    for (std::size_t t = 0; t < objects; ++t) {
        if (size[t] < min_object_pixels || claimed_by[t] == kNone) continue;
        const std::size_t g = root(t);
        std::size_t& first = first_group[claimed_by[t]];
        if (first == objects) {
            first = g;
        } else if (first != g) {
            mixed[claimed_by[t]] = 1;
        }
    }
    for (std::size_t t = 0; t < objects; ++t) {
        if (size[t] >= min_object_pixels && claimed_by[t] != kNone && mixed[claimed_by[t]] != 0) ++s.merged_separable;
    }
    return s;
}

}  // namespace pyrseg::eval
