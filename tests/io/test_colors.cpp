// Label colours: 0 black, others vivid, distinct and stable.
#include <algorithm>
#include <set>

#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

double distance(const std::array<std::uint8_t, 3>& a, const std::array<std::uint8_t, 3>& b) {
    double d = 0;
    for (int c = 0; c < 3; ++c) {
        const double e = static_cast<double>(a[static_cast<std::size_t>(c)]) - b[static_cast<std::size_t>(c)];
        d += e * e;
    }
    return std::sqrt(d);
}

TEST(LabelColor, ZeroIsBlack) {
    EXPECT_EQ(label_color(0), (std::array<std::uint8_t, 3>{0, 0, 0}));
}

TEST(LabelColor, FirstLabelsAreDistinctAndVivid) {
    std::set<std::array<std::uint8_t, 3>> seen;
    for (std::uint32_t l = 1; l <= 64; ++l) {
        const auto c = label_color(l);
        EXPECT_TRUE(seen.insert(c).second) << "label " << l << " repeats a colour";
        const int hi = std::max({c[0], c[1], c[2]}), lo = std::min({c[0], c[1], c[2]});
        EXPECT_GE(hi - lo, 100) << "label " << l << " is greyish";
        EXPECT_GE(hi, 128) << "label " << l << " is too dark";
        for (std::uint32_t m = 1; m < l; ++m) {
            EXPECT_GE(distance(c, label_color(m)), 30.0) << "labels " << m << " and " << l << " look alike";
        }
        if (l > 1) {
            EXPECT_GE(distance(c, label_color(l - 1)), 150.0) << "neighbours " << l - 1 << ", " << l;
        }
    }
}

TEST(LabelColor, FixedAcrossRunsAndLargeLabels) {
    // Pinned values: a change here changes every picture pyrseg has produced.
    using Rgb = std::array<std::uint8_t, 3>;
    EXPECT_EQ(label_color(1), (Rgb{63, 174, 255}));
    EXPECT_EQ(label_color(2), (Rgb{255, 214, 1}));
    EXPECT_EQ(label_color(3), (Rgb{50, 0, 196}));
    EXPECT_EQ(label_color(1000), (Rgb{255, 94, 249}));
    std::set<std::array<std::uint8_t, 3>> seen;
    for (std::uint32_t l : {1000000u, 1000001u, 4294967295u, 4294967294u}) {
        const auto c = label_color(l);
        EXPECT_NE(c, (std::array<std::uint8_t, 3>{0, 0, 0}));
        seen.insert(c);
    }
    EXPECT_EQ(seen.size(), 4u);
}

TEST(LabelColor, ColorizeLabels) {
    const std::uint32_t labels[6] = {0, 1, 2, 2, 0, 7};
    const auto rgb = colorize_labels(labels, 3, 2);
    ASSERT_EQ(rgb.size(), 18u);
    for (std::size_t i = 0; i < 6; ++i) {
        const auto c = label_color(labels[i]);
        EXPECT_EQ(rgb[3 * i], c[0]);
        EXPECT_EQ(rgb[3 * i + 1], c[1]);
        EXPECT_EQ(rgb[3 * i + 2], c[2]);
    }
    ErrorCode code{};
    EXPECT_EQ(outcome([&] { colorize_labels(nullptr, 3, 2); }, nullptr, &code), "error");
    EXPECT_EQ(code, ErrorCode::invalid_argument);
    EXPECT_EQ(outcome([&] { colorize_labels(labels, -1, 2); }), "error");
}

}  // namespace
}  // namespace pyrseg::io::test
