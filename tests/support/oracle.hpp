#pragma once
// Glue between the library and the independent oracle (tests/reference): parameter mapping and byte-exact
// comparison that names the first differing pixel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "reference/reference.hpp"

namespace pyrseg::test {

// Every output a backend can give, so that conformance compares all of them.
inline Outputs everything() {
    Outputs o;
    o.raw_labels = true;
    o.fillable_mask = true;
    o.normals = true;
    o.segment_stats = true;
    o.segment_graph = true;
    return o;
}

inline pyrseg_ref::Params to_reference(const Params& p) {
    pyrseg_ref::Params r;
    r.ct = p.ct;
    r.dt = p.dt;
    r.unit_mm = p.unit_mm;
    r.bridge_levels = p.bridge_levels.value_or(kDefaultBridgeLevels);
    r.unjoinable_gap = p.unjoinable_gap.value_or(kDefaultUnjoinableGap);
    r.bg_explicit = p.bridge_levels.has_value() || p.unjoinable_gap.has_value();
    r.label_edges = p.label_edges;
    r.edge_rounds = p.edge_rounds;
    r.edge_max_depth_step = p.edge_max_depth_step;
    r.compact = p.compact;
    r.normal_radius = p.normal_radius;
    r.metric = p.metric == Metric::robust ? pyrseg_ref::Metric::robust : pyrseg_ref::Metric::paper;
    r.normal_window = p.normal_window;
    r.curvature_stride = p.curvature_stride;
    r.dt_per_m2 = p.dt_per_m2;
    r.ct_growth_per_m2 = p.ct_growth_per_m2;
    r.merge = p.merge;
    r.merge_reach = p.merge_reach;
    r.merge_tolerance_mm = p.merge_tolerance_mm;
    r.merge_tolerance_per_m2 = p.merge_tolerance_per_m2;
    r.merge_min_crossings = p.merge_min_crossings;
    r.merge_max_bad_share = p.merge_max_bad_share;
    r.color_edge_threshold = p.color_edge_threshold;
    r.color_edge_stride = p.color_edge_stride;
    r.color_edge_curvature_share = p.color_edge_curvature_share;
    return r;
}

// Byte-for-byte equality; on failure, the first differing element with its pixel coordinates.
template <class T>
::testing::AssertionResult same_bytes(const char* what, const std::vector<T>& actual, const std::vector<T>& expected,
                                      int width, int channels = 1) {
    if (actual.size() != expected.size()) {
        return ::testing::AssertionFailure()
               << what << ": size " << actual.size() << " but the reference has " << expected.size();
    }
    if (actual.empty() || std::memcmp(actual.data(), expected.data(), actual.size() * sizeof(T)) == 0) {
        return ::testing::AssertionSuccess();
    }
    std::size_t differing = 0;
    std::size_t first = actual.size();
    for (std::size_t i = 0; i < actual.size(); ++i) {
        if (std::memcmp(&actual[i], &expected[i], sizeof(T)) != 0) {
            if (first == actual.size()) first = i;
            ++differing;
        }
    }
    const std::size_t pixel = first / std::size_t(channels);
    std::ostringstream s;
    s << what << ": " << differing << " element(s) differ; first at pixel (" << pixel % std::size_t(width) << ", "
      << pixel / std::size_t(width) << ") channel " << first % std::size_t(channels) << ": " << +actual[first]
      << " vs reference " << +expected[first];
    return ::testing::AssertionFailure() << s.str();
}

// The per-segment statistics field by field; on failure, the first differing segment and field.
inline ::testing::AssertionResult same_segments(const std::vector<SegmentStats>& actual,
                                                const std::vector<pyrseg_ref::Segment>& expected) {
    if (actual.size() != expected.size()) {
        return ::testing::AssertionFailure()
               << "segment statistics: " << actual.size() << " segments but the reference has " << expected.size();
    }
    for (std::size_t k = 0; k < actual.size(); ++k) {
        const SegmentStats& a = actual[k];
        const pyrseg_ref::Segment& e = expected[k];
        const auto differ = [&](const char* field, auto got, auto want) {
            return ::testing::AssertionFailure() << "segment statistics: segment " << k + 1 << " (label " << e.label
                                                 << ") " << field << " is " << got << ", reference " << want;
        };
        if (a.label != e.label) return differ("label", a.label, e.label);
        if (a.pixel_count != e.pixel_count) return differ("pixel_count", a.pixel_count, e.pixel_count);
        if (a.x_min != e.x_min || a.y_min != e.y_min || a.x_max != e.x_max || a.y_max != e.y_max) {
            std::ostringstream got;
            std::ostringstream want;
            got << a.x_min << "," << a.y_min << ".." << a.x_max << "," << a.y_max;
            want << e.x_min << "," << e.y_min << ".." << e.x_max << "," << e.y_max;
            return differ("bounding box", got.str(), want.str());
        }
        if (a.point_shift != e.point_shift) return differ("point_shift", a.point_shift, e.point_shift);
        if (a.fillable_count != e.fillable_count) return differ("fillable_count", a.fillable_count, e.fillable_count);
        for (std::size_t c = 0; c < 3; ++c) {
            if (a.point_sum[c] != e.point_sum[c]) return differ("point_sum", a.point_sum[c], e.point_sum[c]);
            if (a.normal_sum[c] != e.normal_sum[c]) return differ("normal_sum", a.normal_sum[c], e.normal_sum[c]);
        }
        for (std::size_t i = 0; i < 6; ++i) {
            const pyrseg_ref::Int128 got =
                static_cast<pyrseg_ref::Int128>(a.point_product_sum[i].high) * (pyrseg_ref::Int128(1) << 64) +
                static_cast<pyrseg_ref::Int128>(a.point_product_sum[i].low);
            if (got != e.product_sum[i]) {
                return differ("point_product_sum",
                              std::to_string(i) + ": high word " + std::to_string(a.point_product_sum[i].high),
                              "high word " + std::to_string(static_cast<std::int64_t>(e.product_sum[i] >> 64)) +
                                  ", low words differ by " +
                                  std::to_string(static_cast<std::int64_t>(
                                      static_cast<std::uint64_t>(got) - static_cast<std::uint64_t>(e.product_sum[i]))));
            }
        }
        if (a.z_fixed_min != e.z_fixed_min || a.z_fixed_max != e.z_fixed_max) {
            return differ("z range", std::to_string(a.z_fixed_min) + ".." + std::to_string(a.z_fixed_max),
                          std::to_string(e.z_fixed_min) + ".." + std::to_string(e.z_fixed_max));
        }
    }
    return ::testing::AssertionSuccess();
}

// The segment graph edge by edge; on failure, the first differing edge.
inline ::testing::AssertionResult same_graph(const std::vector<SegmentEdge>& actual,
                                             const std::vector<pyrseg_ref::Edge>& expected) {
    const auto text = [](auto e) {
        std::ostringstream s;
        s << "{" << e.a << ", " << e.b << "}: length " << e.length << ", flat " << e.flat << ", convex " << e.convex
          << ", concave " << e.concave << ", step " << e.step;
        return s.str();
    };
    for (std::size_t i = 0; i < std::max(actual.size(), expected.size()); ++i) {
        if (i == actual.size() || i == expected.size()) {
            return ::testing::AssertionFailure()
                   << "segment graph: " << actual.size() << " edges but the reference has " << expected.size()
                   << "; edge " << i << " is "
                   << (i == actual.size() ? "reference " + text(expected[i]) : "backend " + text(actual[i]));
        }
        const SegmentEdge& a = actual[i];
        const pyrseg_ref::Edge& e = expected[i];
        if (a.a != e.a || a.b != e.b || a.length != e.length || a.flat != e.flat || a.convex != e.convex ||
            a.concave != e.concave || a.step != e.step) {
            return ::testing::AssertionFailure()
                   << "segment graph: edge " << i << " is " << text(a) << ", reference " << text(e);
        }
    }
    return ::testing::AssertionSuccess();
}

// Skips the current test, with the backend's own reason, when the backend cannot run here.
inline bool skip_unavailable(const std::string& backend, std::string* reason) {
    for (const BackendInfo& b : list_backends()) {
        if (b.name == backend) {
            if (!b.available) *reason = backend + " unavailable: " + b.reason;
            return !b.available;
        }
    }
    *reason = "unknown backend " + backend;
    return true;
}

#define PYRSEG_SKIP_IF_UNAVAILABLE(backend)                                                         \
    do {                                                                                            \
        std::string skip_reason_;                                                                   \
        if (::pyrseg::test::skip_unavailable(backend, &skip_reason_)) GTEST_SKIP() << skip_reason_; \
    } while (0)

inline const std::vector<std::string>& all_backend_names() {
    static const std::vector<std::string> names = backend_names();
    return names;
}

// The backends that can run here: the suites are instantiated for these. Each unavailable one is reported once,
// as a skipped Availability test carrying the reason (tests/conformance/test_availability.cpp).
inline std::vector<std::string> available_backend_names() {
    std::vector<std::string> names;
    for (const BackendInfo& b : list_backends()) {
        if (b.available) names.push_back(b.name);
    }
    return names;
}

// The shared sample scans: $PYRSEG_DATA_DIR when set (a GPU machine has them in the prepared bundle, not beside
// the checkout: scripts/gpu-check.sh), else the folder the build was configured with.
inline std::string shared_data_dir() {
    const char* dir = std::getenv("PYRSEG_DATA_DIR");
    return dir != nullptr && *dir != '\0' ? std::string(dir) : std::string(PYRSEG_SHARED_DATA_DIR);
}

}  // namespace pyrseg::test
