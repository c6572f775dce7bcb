#pragma once
// Totals of a sweep's cells and the acceptance checks `pyrseg eval` reports per sensor model (docs/quality.md).
// Plain C++ on top of metrics.hpp.
#include <cstdint>
#include <optional>
#include <span>

#include "tools/eval/metrics.hpp"

namespace pyrseg::eval {

// The acceptance checks of the sensor sweep, per sensor model, pooled over the camera distances.
inline constexpr double kMaxMergeRatio = 0.2;     // pyramid merged <= 1/5 of CC merged at bridge widths 1 and 2
inline constexpr double kMinLabelledShare = 0.9;  // pyramid labels >= 90% of the ground-truth pixels (width 0)
inline constexpr int kCheckedBridgeWidths[2] = {1, 2};

// One method's scores summed over the frames of a cell (or of several cells).
struct Totals {
    std::uint64_t merged = 0, merged_separable = 0, split = 0, labelled = 0, pixels = 0, segments = 0;
    double ari_sum = 0;
    int frames = 0;
    void add(const Scores& s);
    void add(const Totals& t);
    [[nodiscard]] double ari() const;             // mean over the frames; NaN without frames
    [[nodiscard]] double labelled_share() const;  // labelled / pixels; NaN without pixels
};

// The frames of one sweep setting (a noise level or a sensor model at a distance) at one bridge width.
struct Cell {
    double noise_mm = 0;
    double distance_mm = 0;
    int bridge = 0;
    std::uint64_t objects = 0;  // evaluated objects, summed over the frames
    std::uint64_t sites = 0;    // bridges drawn (0 at width 0)
    Totals pyramid, cc, pcl;    // pcl: bridge width 0 only (no frames elsewhere, or without PCL)
};

// n / of; NaN when of is 0.
[[nodiscard]] double rate(std::uint64_t n, std::uint64_t of);

struct MergeAtWidth {
    int bridge = 0;
    bool present = false;  // the sweep had that width
    std::uint64_t objects = 0, pyramid = 0, cc = 0;
    std::uint64_t pyramid_separable = 0, cc_separable = 0;  // merges with objects that are not flush
    [[nodiscard]] double pyramid_rate() const { return rate(pyramid, objects); }
    [[nodiscard]] double cc_rate() const { return rate(cc, objects); }
    [[nodiscard]] double ratio() const { return rate(pyramid, cc); }  // pyramid / CC merged; NaN when CC merged none
    [[nodiscard]] double separable_ratio() const { return rate(pyramid_separable, cc_separable); }
};

// One sensor model's cells (every distance and bridge width), pooled over the distances.
struct SensorSummary {
    Totals pyramid0, cc0, pcl0;  // width 0
    MergeAtWidth merge[2];       // kCheckedBridgeWidths
    // nullopt: not measured (no PCL, no width 0, none of the checked widths).
    std::optional<bool> ari_at_least_pcl;  // pyramid ARI >= PCL ARI at width 0
    // Judged at the checked widths the sweep had where CC merged something.
    std::optional<bool> merges_fifth_of_cc;  // 5 * pyramid merged <= CC merged at each checked width present
    // The same for the separable merges (flush pairs aside): the merges a labelling of the mask can avoid.
    std::optional<bool> separable_merges_fifth_of_cc;
    std::optional<bool> labels_enough;  // pyramid labelled share >= kMinLabelledShare at width 0
};

[[nodiscard]] SensorSummary summarize(std::span<const Cell> cells);

}  // namespace pyrseg::eval
