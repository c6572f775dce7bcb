#include "tools/eval/tabletop_scores.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "tools/eval/tabletop_truth.hpp"

namespace pyrseg::eval {

std::uint32_t TabletopScores::whole() const {
    return std::uint32_t(std::count_if(objects.begin(), objects.end(), [](const auto& o) { return o.whole; }));
}
std::uint32_t TabletopScores::in_parts() const {
    return std::uint32_t(std::count_if(objects.begin(), objects.end(), [](const auto& o) { return o.in_parts; }));
}
std::uint32_t TabletopScores::merged_with_table() const {
    return std::uint32_t(
        std::count_if(objects.begin(), objects.end(), [](const auto& o) { return o.merged_with_table; }));
}
double TabletopScores::mean_best_iou() const {
    if (objects.empty()) return 0;
    double sum = 0;
    for (const TabletopObjectScore& o : objects) sum += o.best_iou;
    return sum / double(objects.size());
}
double TabletopScores::unlabelled_share() const {
    std::uint64_t pixels = 0;
    std::uint64_t unlabelled = 0;
    for (const TabletopObjectScore& o : objects) {
        pixels += o.pixels;
        unlabelled += o.unlabelled;
    }
    return pixels == 0 ? 0 : double(unlabelled) / double(pixels);
}

TabletopScores score_tabletop(std::span<const std::uint32_t> truth, std::span<const std::uint32_t> predicted) {
    if (truth.size() != predicted.size()) {
        throw std::invalid_argument("tabletop scores: the truth and the segmentation have different pixel counts");
    }
    std::unordered_map<std::uint32_t, std::uint64_t> segment_pixels;          // over the whole frame
    std::map<std::uint32_t, std::map<std::uint32_t, std::uint64_t>> overlap;  // truth id -> segment -> pixels
    std::map<std::uint32_t, std::uint64_t> truth_pixels;
    for (std::size_t i = 0; i < truth.size(); ++i) {
        if (predicted[i] != 0) ++segment_pixels[predicted[i]];
        if (truth[i] == kTruthNone) continue;
        ++truth_pixels[truth[i]];
        ++overlap[truth[i]][predicted[i]];
    }
    TabletopScores out;
    if (const auto table = overlap.find(kTruthTable); table != overlap.end()) {
        out.table_pixels = truth_pixels[kTruthTable];
        std::uint64_t best = 0;
        for (const auto& [segment, pixels] : table->second) {
            if (segment != 0 && pixels > best) {
                best = pixels;
                out.table_label = segment;
            }
        }
        out.table_share = double(best) / double(out.table_pixels);
    }
    for (const auto& [id, segments] : overlap) {
        if (id == kTruthTable) continue;
        TabletopObjectScore o;
        o.truth_id = id;
        o.pixels = truth_pixels[id];
        std::uint64_t inside_union = 0;    // pixels of the segments at least 80% inside, within the object
        std::uint64_t inside_outside = 0;  // their pixels outside it
        for (const auto& [segment, pixels] : segments) {
            if (segment == 0) {
                o.unlabelled = pixels;
                continue;
            }
            const std::uint64_t size = segment_pixels[segment];
            const double iou = double(pixels) / double(o.pixels + size - pixels);
            o.best_iou = std::max(o.best_iou, iou);
            if (double(pixels) >= kInsideShare * double(size)) {
                ++o.parts;
                inside_union += pixels;
                inside_outside += size - pixels;
            }
            if (segment == out.table_label && double(pixels) >= kTableMergeShare * double(o.pixels)) {
                o.merged_with_table = true;
            }
        }
        o.whole = o.best_iou >= kWholeIou;
        o.in_parts = inside_union > 0 && double(inside_union) / double(o.pixels + inside_outside) >= kWholeIou;
        out.objects.push_back(o);
    }
    return out;
}

}  // namespace pyrseg::eval
