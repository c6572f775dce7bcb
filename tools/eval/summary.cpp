#include "tools/eval/summary.hpp"

#include <cmath>

namespace pyrseg::eval {

void Totals::add(const Scores& s) {
    merged += s.merged;
    merged_separable += s.merged_separable;
    split += s.split;
    labelled += s.labelled;
    pixels += s.pixels;
    segments += s.segments;
    ari_sum += s.ari;
    ++frames;
}

void Totals::add(const Totals& t) {
    merged += t.merged;
    merged_separable += t.merged_separable;
    split += t.split;
    labelled += t.labelled;
    pixels += t.pixels;
    segments += t.segments;
    ari_sum += t.ari_sum;
    frames += t.frames;
}

double Totals::ari() const {
    return frames == 0 ? std::nan("") : ari_sum / frames;
}

double Totals::labelled_share() const {
    return rate(labelled, pixels);
}

double rate(std::uint64_t n, std::uint64_t of) {
    return of == 0 ? std::nan("") : double(n) / double(of);
}

SensorSummary summarize(std::span<const Cell> cells) {
    SensorSummary s;
    for (int w = 0; w < 2; ++w) s.merge[w].bridge = kCheckedBridgeWidths[w];
    for (const Cell& c : cells) {
        if (c.bridge == 0) {
            s.pyramid0.add(c.pyramid);
            s.cc0.add(c.cc);
            s.pcl0.add(c.pcl);
        }
        for (MergeAtWidth& m : s.merge) {
            if (c.bridge != m.bridge) continue;
            m.present = true;
            m.objects += c.objects;
            m.pyramid += c.pyramid.merged;
            m.cc += c.cc.merged;
            m.pyramid_separable += c.pyramid.merged_separable;
            m.cc_separable += c.cc.merged_separable;
        }
    }
    if (s.pyramid0.frames > 0 && s.pcl0.frames > 0) s.ari_at_least_pcl = s.pyramid0.ari() >= s.pcl0.ari();
    for (const MergeAtWidth& m : s.merge) {
        if (!m.present || m.cc == 0) continue;  // CC merged nothing: the bridges did not test the pyramid
        const bool ok = double(m.pyramid) <= kMaxMergeRatio * double(m.cc);
        s.merges_fifth_of_cc = s.merges_fifth_of_cc.value_or(true) && ok;
    }
    for (const MergeAtWidth& m : s.merge) {
        if (!m.present || m.cc_separable == 0) continue;
        const bool ok = double(m.pyramid_separable) <= kMaxMergeRatio * double(m.cc_separable);
        s.separable_merges_fifth_of_cc = s.separable_merges_fifth_of_cc.value_or(true) && ok;
    }
    if (s.pyramid0.pixels > 0) s.labels_enough = s.pyramid0.labelled_share() >= kMinLabelledShare;
    return s;
}

}  // namespace pyrseg::eval
