// Tests of the oracle itself. Every expected value here was derived by hand from the algorithm contract and
// docs/algorithm.md (the derivations are sketched in the comments) and is written as a literal, never computed by the
// oracle, so a mistake in the oracle cannot hide behind itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>
#include <queue>
#include <string>
#include <vector>

#include "reference/reference.hpp"

namespace {

using pyrseg_ref::Output;
using pyrseg_ref::Params;

// A picture: one string per row, '#' fillable, anything else not.
std::vector<std::uint8_t> mask_of(const std::vector<std::string>& rows) {
    std::vector<std::uint8_t> out;
    for (const std::string& row : rows) {
        for (char c : row) out.push_back(c == '#' ? 1 : 0);
    }
    return out;
}

// Expected labels as a picture: '.' is 0, every other character is looked up in the legend.
std::vector<std::uint32_t> labels_of(const std::vector<std::string>& rows,
                                     const std::map<char, std::uint32_t>& legend) {
    std::vector<std::uint32_t> out;
    for (const std::string& row : rows) {
        for (char c : row) out.push_back(c == '.' ? 0u : legend.at(c));
    }
    return out;
}

std::string grid(const std::vector<std::uint32_t>& v, int width) {
    std::string s;
    for (std::size_t i = 0; i < v.size(); ++i) {
        s += std::to_string(v[i]);
        s += (static_cast<int>(i % static_cast<std::size_t>(width)) == width - 1) ? "\n" : " ";
    }
    return s;
}

#define EXPECT_LABELS(actual, expected, width) \
    EXPECT_EQ(actual, expected) << "actual:\n" << grid(actual, width) << "expected:\n" << grid(expected, width)

int width_of(const std::vector<std::string>& rows) {
    return static_cast<int>(rows.front().size());
}
int height_of(const std::vector<std::string>& rows) {
    return static_cast<int>(rows.size());
}

// Number of 4-connected components of a mask: only to show that plain connected-component labelling would merge.
int plain_components(const std::vector<std::uint8_t>& mask, int w, int h) {
    std::vector<std::uint8_t> seen(mask.size(), 0);
    int count = 0;
    for (std::size_t s = 0; s < mask.size(); ++s) {
        if (mask[s] == 0 || seen[s] != 0) continue;
        ++count;
        std::queue<std::size_t> todo;
        todo.push(s);
        seen[s] = 1;
        while (!todo.empty()) {
            const std::size_t t = todo.front();
            todo.pop();
            const int x = static_cast<int>(t % static_cast<std::size_t>(w));
            const int y = static_cast<int>(t / static_cast<std::size_t>(w));
            const int nx[4] = {x - 1, x + 1, x, x};
            const int ny[4] = {y, y, y - 1, y + 1};
            for (int k = 0; k < 4; ++k) {
                if (nx[k] < 0 || ny[k] < 0 || nx[k] >= w || ny[k] >= h) continue;
                const auto n = static_cast<std::size_t>(ny[k] * w + nx[k]);
                if (mask[n] != 0 && seen[n] == 0) {
                    seen[n] = 1;
                    todo.push(n);
                }
            }
        }
    }
    return count;
}

Output run_mask(const std::vector<std::string>& rows, const Params& p,
                const std::vector<std::uint8_t>* valid = nullptr) {
    const std::vector<std::uint8_t> mask = mask_of(rows);
    return pyrseg_ref::segment_mask(mask.data(), valid != nullptr ? valid->data() : nullptr, width_of(rows),
                                    height_of(rows), p);
}

Params explicit_bg(int b, int g) {
    Params p;
    p.bridge_levels = b;
    p.unjoinable_gap = g;
    p.bg_explicit = true;
    return p;
}

// Points (x, y, z) on a grid; z from a function of the pixel.
template <typename Fn>
std::vector<float> grid_points(int w, int h, Fn z_of) {
    std::vector<float> pts;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            pts.push_back(static_cast<float>(x));
            pts.push_back(static_cast<float>(y));
            pts.push_back(z_of(x, y));
        }
    }
    return pts;
}

std::vector<float> constant_normals(int count, float nx, float ny, float nz) {
    std::vector<float> n;
    for (int i = 0; i < count; ++i) {
        n.push_back(nx);
        n.push_back(ny);
        n.push_back(nz);
    }
    return n;
}

std::vector<float> normal_at(const std::vector<float>& normals, int w, int x, int y) {
    const auto i = static_cast<std::size_t>(3 * (y * w + x));
    return {normals[i], normals[i + 1], normals[i + 2]};
}

std::vector<float> q13(int qx, int qy, int qz) {
    return {static_cast<float>(qx) / 8192.0f, static_cast<float>(qy) / 8192.0f, static_cast<float>(qz) / 8192.0f};
}

// ---------------------------------------------------------------------------------------------------------------
// Small-image fallback: plain 4-connected components labelled 1 + smallest row-major index, no edge labelling.

TEST(ReferenceFallback, OneByOne) {
    const Params p;
    Output on = run_mask({"#"}, p);
    ASSERT_TRUE(on.ok) << on.error;
    EXPECT_EQ(on.raw_labels, (std::vector<std::uint32_t>{1}));
    EXPECT_EQ(on.labels, (std::vector<std::uint32_t>{1}));
    EXPECT_EQ(on.segment_count, 1u);

    Output off = run_mask({"."}, p);
    ASSERT_TRUE(off.ok) << off.error;
    EXPECT_EQ(off.labels, (std::vector<std::uint32_t>{0}));
    EXPECT_EQ(off.segment_count, 0u);

    // Through the metric: a lone pixel has no valid 8-neighbour (k = 0), so it is never fillable.
    const float pt[3] = {0.0f, 0.0f, 1000.0f};
    const float nrm[3] = {0.0f, 0.0f, -1.0f};
    Output seg = pyrseg_ref::segment(pt, nrm, 1, 1, p);
    ASSERT_TRUE(seg.ok) << seg.error;
    EXPECT_EQ(seg.fillable, (std::vector<std::uint8_t>{0}));
    EXPECT_EQ(seg.labels, (std::vector<std::uint32_t>{0}));
    EXPECT_EQ(seg.segment_count, 0u);
}

TEST(ReferenceFallback, OneBySevenAndSevenByOne) {
    const Params p;
    // 1 x 7 (a column): components {0}, {2, 3}, {6} -> raw 1, 3, 7.
    Output col = run_mask({"#", ".", "#", "#", ".", ".", "#"}, p);
    ASSERT_TRUE(col.ok) << col.error;
    EXPECT_EQ(col.raw_labels, (std::vector<std::uint32_t>{1, 0, 3, 3, 0, 0, 7}));
    EXPECT_EQ(col.labels, (std::vector<std::uint32_t>{1, 0, 2, 2, 0, 0, 3}));
    EXPECT_EQ(col.segment_count, 3u);

    // 7 x 1 (a row): components {0, 1}, {3}, {5, 6} -> raw 1, 4, 6.
    Output row = run_mask({"##.#.##"}, p);
    ASSERT_TRUE(row.ok) << row.error;
    EXPECT_EQ(row.raw_labels, (std::vector<std::uint32_t>{1, 1, 0, 4, 0, 6, 6}));
    EXPECT_EQ(row.labels, (std::vector<std::uint32_t>{1, 1, 0, 2, 0, 3, 3}));

    // Through the metric with given normals: every pixel of a flat row/column has a valid neighbour -> one segment.
    const std::vector<float> pts = grid_points(1, 7, [](int, int) { return 500.0f; });
    const std::vector<float> nrm = constant_normals(7, 0.0f, 0.0f, -1.0f);
    Output seg = pyrseg_ref::segment(pts.data(), nrm.data(), 1, 7, p);
    ASSERT_TRUE(seg.ok) << seg.error;
    EXPECT_EQ(seg.raw_labels, (std::vector<std::uint32_t>(7, 1)));
    const std::vector<float> pts_row = grid_points(7, 1, [](int, int) { return 500.0f; });
    Output seg_row = pyrseg_ref::segment(pts_row.data(), nrm.data(), 7, 1, p);
    ASSERT_TRUE(seg_row.ok) << seg_row.error;
    EXPECT_EQ(seg_row.raw_labels, (std::vector<std::uint32_t>(7, 1)));
}

TEST(ReferenceFallback, EightByEightHasNoEdgeLabelling) {
    // N = 4, so U = 4 - 2 - 2 = 0 < 1 with the defaults: the fallback. Components and their smallest indices:
    // {0,1,8,9} -> 0; {4,12,20} -> 4; {24,25,26,34,42} -> 24; {38,39,46} -> 38; {56}; {63}.
    const std::vector<std::string> mask = {
        "##..#...",  //
        "##..#...",  //
        "....#...",  //
        "###.....",  //
        "..#...##",  //
        "..#...#.",  //
        "........",  //
        "#......#",  //
    };
    Params p;
    ASSERT_TRUE(p.label_edges);
    Output out = run_mask(mask, p);
    ASSERT_TRUE(out.ok) << out.error;
    const std::vector<std::string> raw_pic = {
        "aa..b...",  //
        "aa..b...",  //
        "....b...",  //
        "ccc.....",  //
        "..c...dd",  //
        "..c...d.",  //
        "........",  //
        "e......f",  //
    };
    EXPECT_LABELS(out.raw_labels, labels_of(raw_pic, {{'a', 1}, {'b', 5}, {'c', 25}, {'d', 39}, {'e', 57}, {'f', 64}}),
                  8);
    EXPECT_LABELS(out.labels, labels_of(raw_pic, {{'a', 1}, {'b', 2}, {'c', 3}, {'d', 4}, {'e', 5}, {'f', 6}}), 8);
    EXPECT_EQ(out.segment_count, 6u);

    p.compact = false;
    Output raw = run_mask(mask, p);
    EXPECT_EQ(raw.labels, out.raw_labels);
}

TEST(ReferenceFallback, ExplicitParametersThatDoNotFitAreRejected) {
    const std::vector<std::string> mask(8, std::string(8, '#'));
    Output bad = run_mask(mask, explicit_bg(2, 2));  // U = 0
    EXPECT_FALSE(bad.ok);
    EXPECT_FALSE(bad.error.empty());
    EXPECT_TRUE(bad.labels.empty());

    // b = g = 1 fit an 8x8 image (U = 2). All fillable -> the 1x1 level is fillable -> label 1 everywhere.
    Output good = run_mask(mask, explicit_bg(1, 1));
    ASSERT_TRUE(good.ok) << good.error;
    EXPECT_EQ(good.raw_labels, (std::vector<std::uint32_t>(64, 1)));

    // Huge b and g must not overflow N - b - g.
    Output huge = run_mask(mask, explicit_bg(std::numeric_limits<int>::max(), std::numeric_limits<int>::max()));
    EXPECT_FALSE(huge.ok);
}

// ---------------------------------------------------------------------------------------------------------------
// Pyramid shape: sizes, missing children.

TEST(ReferencePyramid, NineByNineMissingChildrenFilledByStepSix) {
    // N = 5 (U = 1, no fallback). Level 4 is 5x5 but its last column/row has a missing child, so only 4x4 texels
    // are fillable; level 3 (3x3): 2x2; level 2 (2x2): only (0,0) -> new label offset_2 + 1 = 2; level 1 not fillable.
    // Level 5 pixels x = 8 or y = 8 have non-fillable parents (label 0) and get label 2 in step 6 (rows, then the
    // last row by the column sweep).
    const std::vector<std::string> mask(9, std::string(9, '#'));
    Output out = run_mask(mask, Params{});
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.raw_labels, (std::vector<std::uint32_t>(81, 2)));
    EXPECT_EQ(out.labels, (std::vector<std::uint32_t>(81, 1)));
    EXPECT_EQ(out.segment_count, 1u);
}

TEST(ReferencePyramid, NineByOneHasNoLabelsAtAll) {
    // max(W, H) = 9 -> N = 5, U = 1: no fallback. With H = 1 every texel of level 4 has missing children (row 1),
    // so no coarser level has a fillable texel, no label is ever created and step 6 has nothing to spread.
    Output out = run_mask({"#########"}, Params{});
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.raw_labels, (std::vector<std::uint32_t>(9, 0)));
    EXPECT_EQ(out.segment_count, 0u);
    EXPECT_EQ(out.fillable, (std::vector<std::uint8_t>(9, 1)));
}

// ---------------------------------------------------------------------------------------------------------------
// Bridges.

// 24 x 16, b = 2, g = 1: N = 6, M = 4, U = 3. Levels: 6: 24x16, 5: 12x8, 4: 6x4, 3: 3x2, 2: 2x1, 1: 1x1.
// offsets: 0, 1, 3, 9, 33, 129. Old labels: <= offset_4 = 9.
TEST(ReferenceBridges, OneAndTwoPixelBridgesDoNotMerge) {
    // Two 8x8 squares (level-3 texels (0,0) -> label 4 and (2,0) -> label 6, both old) joined by a 1-px bridge (row 1)
    // and a 2-px bridge (rows 4-5). The 2-px bridge appears on level 5 as texels (4..7, 2) with label 0 after step 3;
    // step 4 gives that component min(4, 6) = 4. The 1-px bridge exists only at level 6 and is filled by the row
    // sweep from the left square (label 4).
    const std::vector<std::string> mask = {
        "########........########",  //
        "########################",  //
        "########........########",  //
        "########........########",  //
        "########################",  //
        "########################",  //
        "########........########",  //
        "########........########",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
    };
    ASSERT_EQ(width_of(mask), 24);
    ASSERT_EQ(plain_components(mask_of(mask), 24, 16), 1);  // plain CCL would merge the two squares

    Params p = explicit_bg(2, 1);
    p.label_edges = false;
    Output out = run_mask(mask, p);
    ASSERT_TRUE(out.ok) << out.error;
    const std::vector<std::string> expected = {
        "aaaaaaaa........bbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaa........bbbbbbbb",  //
        "aaaaaaaa........bbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaa........bbbbbbbb",  //
        "aaaaaaaa........bbbbbbbb",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
    };
    EXPECT_LABELS(out.raw_labels, labels_of(expected, {{'a', 4}, {'b', 6}}), 24);
    EXPECT_LABELS(out.labels, labels_of(expected, {{'a', 1}, {'b', 2}}), 24);
    EXPECT_EQ(out.segment_count, 2u);

    // With edge labelling: each valid non-fillable pixel takes the smallest labelled fillable 4-neighbour.
    p.label_edges = true;
    Output edges = run_mask(mask, p);
    ASSERT_TRUE(edges.ok) << edges.error;
    const std::vector<std::string> expected_edges = {
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaaaaaaaaabbbbbbbb",  //
        "aaaaaaaaa......bbbbbbbbb",  //
        "aaaaaaaa........bbbbbbbb",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
    };
    EXPECT_LABELS(edges.raw_labels, labels_of(expected_edges, {{'a', 4}, {'b', 6}}), 24);
    EXPECT_EQ(edges.segment_count, 2u);
}

// Same geometry as above. A (x 16..23, y 0..7) is level-3 texel (2,0): label 6. B (x 0..7, y 8..15) is level-3 texel
// (0,1): label 3 + 3 + 0 + 1 = 7. Y (x 8..11, y 4..7) is level-4 texel (2,1): young label 9 + 6 + 2 + 1 = 18.
// Level-5 bridges: Y->A texels (6,3), (7,3) (pixels x 12..15, y 6..7); Y->B texel (4,4) (pixels x 8..9, y 8..9).
TEST(ReferenceBridges, YoungRegionJoinsTheSmallerOldRegion) {
    Params p = explicit_bg(2, 1);
    p.label_edges = false;
    const std::map<char, std::uint32_t> raw = {{'A', 6}, {'B', 7}, {'Y', 18}};

    const std::vector<std::string> both = {
        "................########",  //
        "................########",  //
        "................########",  //
        "................########",  //
        "........####....########",  //
        "........####....########",  //
        "........################",  //
        "........################",  //
        "##########..............",  //
        "##########..............",  //
        "########................",  //
        "########................",  //
        "########................",  //
        "########................",  //
        "########................",  //
        "########................",  //
    };
    Output out = run_mask(both, p);
    ASSERT_TRUE(out.ok) << out.error;
    // The non-anchored component {Y, both bridges} touches anchors 6 and 7: min(18, 6, 7) = 6. A and B stay apart.
    const std::vector<std::string> expected_both = {
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "........AAAA....AAAAAAAA",  //
        "........AAAA....AAAAAAAA",  //
        "........AAAAAAAAAAAAAAAA",  //
        "........AAAAAAAAAAAAAAAA",  //
        "BBBBBBBBAA..............",  //
        "BBBBBBBBAA..............",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
    };
    EXPECT_LABELS(out.raw_labels, labels_of(expected_both, raw), 24);
    EXPECT_EQ(out.segment_count, 2u);

    // Without the Y->A bridge, Y touches only B.
    std::vector<std::string> only_b = both;
    only_b[6] = "........####....########";
    only_b[7] = "........####....########";
    Output ob = run_mask(only_b, p);
    ASSERT_TRUE(ob.ok) << ob.error;
    const std::vector<std::string> expected_only_b = {
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "........BBBB....AAAAAAAA",  //
        "........BBBB....AAAAAAAA",  //
        "........BBBB....AAAAAAAA",  //
        "........BBBB....AAAAAAAA",  //
        "BBBBBBBBBB..............",  //
        "BBBBBBBBBB..............",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
    };
    EXPECT_LABELS(ob.raw_labels, labels_of(expected_only_b, raw), 24);
}

TEST(ReferenceBridges, WideBridgeMergesAtLevelM) {
    // A 4-px bridge (x 8..15, y 0..3) is seen on level 4 (= M) as texels (2,0), (3,0) with new labels 12, 13. Step 2
    // joins the whole level-4 component to min(4, 6, 12, 13) = 4 before anything is anchored: one segment.
    Params p = explicit_bg(2, 1);
    p.label_edges = false;
    const std::vector<std::string> mask = {
        "########################",  //
        "########################",  //
        "########################",  //
        "########################",  //
        "########........########",  //
        "########........########",  //
        "########........########",  //
        "########........########",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
        "........................",  //
    };
    Output out = run_mask(mask, p);
    ASSERT_TRUE(out.ok) << out.error;
    std::vector<std::string> expected = mask;
    for (std::string& row : expected) {
        for (char& c : row) c = c == '#' ? 'a' : '.';
    }
    EXPECT_LABELS(out.raw_labels, labels_of(expected, {{'a', 4}}), 24);
    EXPECT_EQ(out.segment_count, 1u);
}

TEST(ReferenceCompaction, IncreasingRawOrderNotScanOrder) {
    // Y without bridges keeps its young label 18. In scan order Y (first pixel (8,4)) comes before B (first pixel
    // (0,8)), but compaction follows the raw values 6 < 7 < 18. The isolated 2x2 block at (20..21, 12..13) is
    // fillable on level 5 only, with no labelled texel anywhere near: it stays 0.
    Params p = explicit_bg(2, 1);
    p.label_edges = false;
    const std::vector<std::string> mask = {
        "................########",  //
        "................########",  //
        "................########",  //
        "................########",  //
        "........####....########",  //
        "........####....########",  //
        "........####....########",  //
        "........####....########",  //
        "########................",  //
        "########................",  //
        "########................",  //
        "########................",  //
        "########............##..",  //
        "########............##..",  //
        "########................",  //
        "########................",  //
    };
    const std::vector<std::string> expected = {
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "................AAAAAAAA",  //
        "........YYYY....AAAAAAAA",  //
        "........YYYY....AAAAAAAA",  //
        "........YYYY....AAAAAAAA",  //
        "........YYYY....AAAAAAAA",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
        "BBBBBBBB................",  //
    };
    Output out = run_mask(mask, p);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_LABELS(out.raw_labels, labels_of(expected, {{'A', 6}, {'B', 7}, {'Y', 18}}), 24);
    EXPECT_LABELS(out.labels, labels_of(expected, {{'A', 1}, {'B', 2}, {'Y', 3}}), 24);
    EXPECT_EQ(out.segment_count, 3u);
    EXPECT_EQ(out.fillable, mask_of(mask));

    p.compact = false;
    Output raw = run_mask(mask, p);
    ASSERT_TRUE(raw.ok) << raw.error;
    EXPECT_EQ(raw.labels, raw.raw_labels);
    EXPECT_LABELS(raw.labels, labels_of(expected, {{'A', 6}, {'B', 7}, {'Y', 18}}), 24);
    EXPECT_EQ(raw.segment_count, 3u);
}

// ---------------------------------------------------------------------------------------------------------------
// Step 6 schedule. 8 x 8 with b = g = 1 (explicit): N = 4, M = 3, U = 2; offsets 0, 1, 5, 21. The only full aligned
// 2x2 blocks are (0..1, 0..1) -> level-3 texel (0,0) -> label 6 and (6..7, 6..7) -> texel (3,3) -> label 21.

const std::vector<std::string> kScheduleMask = {
    "####.#..",  //
    "##.##...",  //
    "#....#..",  //
    "#.##.#..",  //
    "..#..#..",  //
    "###..###",  //
    ".....###",  //
    "...#####",  //
};

TEST(ReferenceStep6, RowsThenColumnsOnce) {
    // Rows: row 0 left-to-right takes x2, x3 from 6; row 6 right-to-left takes x5 from 21; row 7 right-to-left takes
    // x5, x4, x3 one after the other (each update visible to the next pixel). Columns then: column 0 top-to-bottom
    // takes y2, y3 from 6; column 3 takes (3,1) from (3,0); column 5 bottom-to-top takes y5..y2 from 21; columns 6, 7
    // take y5. Not reached: (4,1) (would need a second row pass), (5,0), (2..3, 3), (2,4), (0..2, 5).
    Params p = explicit_bg(1, 1);
    p.label_edges = false;
    Output out = run_mask(kScheduleMask, p);
    ASSERT_TRUE(out.ok) << out.error;
    const std::vector<std::string> expected = {
        "aaaa....",  //
        "aa.a....",  //
        "a....b..",  //
        "a....b..",  //
        ".....b..",  //
        ".....bbb",  //
        ".....bbb",  //
        "...bbbbb",  //
    };
    EXPECT_LABELS(out.raw_labels, labels_of(expected, {{'a', 6}, {'b', 21}}), 8);
    EXPECT_LABELS(out.labels, labels_of(expected, {{'a', 1}, {'b', 2}}), 8);
}

TEST(ReferenceStep6, EdgeLabellingReadsStateAfterColumns) {
    Params p = explicit_bg(1, 1);
    Output out = run_mask(kScheduleMask, p);
    ASSERT_TRUE(out.ok) << out.error;
    // E.g. (4,0): left 6, others fillable-unlabelled -> 6. (5,1): only (5,2) = 21 labelled -> 21. (2,2): its only
    // fillable neighbour (2,3) is unlabelled -> 0. (1,4): fillable neighbours unlabelled -> 0.
    const std::vector<std::string> expected = {
        "aaaaa...",  //
        "aaaa.b..",  //
        "aa.abbb.",  //
        "aa..bbb.",  //
        "a...bbbb",  //
        "....bbbb",  //
        "...bbbbb",  //
        "..bbbbbb",  //
    };
    EXPECT_LABELS(out.raw_labels, labels_of(expected, {{'a', 6}, {'b', 21}}), 8);
}

TEST(ReferenceStep6, EdgeLabellingTakesSmallestNeighbourAndSkipsInvalid) {
    // b = g = 1 on 8x8. Seeds: P (4..5, 0..1) -> texel (2,0) -> 8; Q (0..1, 2..3) -> texel (0,1) -> 10;
    // R (4..5, 4..5) -> texel (2,2) -> 16. Column x = 3 (y 0..3) takes 8 (rows, then column). (2,2) sees Q = 10 on its
    // left and 8 on its right -> 8. (2,3) is invalid -> stays 0. (1,0) only touches edge pixels -> 0 (no spreading).
    // (7,7) is fillable but unreachable -> 0, and so is its neighbour (7,6).
    const std::vector<std::string> mask = {
        "...###..",  //
        "...###..",  //
        "##.#....",  //
        "##.#....",  //
        "....##..",  //
        "....##..",  //
        "........",  //
        ".......#",  //
    };
    std::vector<std::uint8_t> valid(64, 1);
    valid[3 * 8 + 2] = 0;
    Params p = explicit_bg(1, 1);
    Output out = run_mask(mask, p, &valid);
    ASSERT_TRUE(out.ok) << out.error;
    const std::vector<std::string> expected = {
        "..ppppp.",  //
        "qqppppp.",  //
        "qqpppp..",  //
        "qq.ppr..",  //
        "qq.prrr.",  //
        "...rrrr.",  //
        "....rr..",  //
        "........",  //
    };
    EXPECT_LABELS(out.raw_labels, labels_of(expected, {{'p', 8}, {'q', 10}, {'r', 16}}), 8);
    EXPECT_LABELS(out.labels, labels_of(expected, {{'p', 1}, {'q', 2}, {'r', 3}}), 8);
    EXPECT_EQ(out.segment_count, 3u);
}

// ---------------------------------------------------------------------------------------------------------------
// Edge rounds (docs/algorithm.md section 5 step 6c, `edge_rounds` E): round 1 is the contract's step; in round k >= 2
// a valid, non-fillable, unlabelled pixel takes the smallest label among its 4-neighbours that are labelled and
// fillable or were labelled in rounds 1..k-1 (a Jacobi step). Pictures: '#' fillable, '-' valid and not fillable,
// 'x' invalid.

std::vector<std::uint8_t> valid_of(const std::vector<std::string>& rows) {
    std::vector<std::uint8_t> out;
    for (const std::string& row : rows) {
        for (char c : row) out.push_back(c == 'x' ? 0 : 1);
    }
    return out;
}

Output run_edges(const std::vector<std::string>& rows, int edge_rounds, bool label_edges = true) {
    Params p;  // 16x16 with the default b = g = 2: N = 5, M = 3, U = 1 (old is <= offset_2 = 1: nothing here)
    p.edge_rounds = edge_rounds;
    p.label_edges = label_edges;
    const std::vector<std::uint8_t> valid = valid_of(rows);
    return run_mask(rows, p, &valid);
}

// The 4x4 block (0..3, 0..3) is level-3 texel (0,0): new label offset_3 + 0 + 1 = 5 + 1 = 6 (level 2 needs 8x8).
// Row 1 goes on with valid non-fillable pixels x = 4..11, an invalid one at x = 12 and valid ones again at 13..15.
// Row 3 goes on with valid x = 4, 5, a fillable pixel at x = 6 that no fill reaches (its left neighbour is not
// fillable, its level-4 parent (3,1) has invalid children in row 2) and valid ones at 7..15. Everything else outside
// the block is invalid, so the labels can only run along rows 1 and 3.
const std::vector<std::string> kCorridors = {
    "####xxxxxxxxxxxx",  //
    "####--------x---",  //
    "####xxxxxxxxxxxx",  //
    "####--#---------",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
    "xxxxxxxxxxxxxxxx",  //
};

// The expected raw labels of kCorridors: the block (6), the first `row1` pixels of row 1 after it and the first
// `row3` pixels of row 3 after it.
std::vector<std::uint32_t> corridor_labels(int row1, int row3) {
    std::vector<std::uint32_t> out(256, 0);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) out[static_cast<std::size_t>(y * 16 + x)] = 6;
    }
    for (int x = 4; x < 4 + row1; ++x) out[static_cast<std::size_t>(16 + x)] = 6;
    for (int x = 4; x < 4 + row3; ++x) out[static_cast<std::size_t>(48 + x)] = 6;
    return out;
}

TEST(ReferenceEdgeRounds, EachRoundReachesOneStepFurther) {
    // Round k labels pixel x = 3 + k of row 1 (its left neighbour was labelled in round k - 1, or is fillable for
    // k = 1), so E rounds label exactly x = 4..3+E. The invalid (12,1) is never labelled and cuts 13..15 off: even
    // 63 rounds reach only 4..11. In row 3, (4,3) and (5,3) take 6 in rounds 1 and 2; (6,3) is fillable, so no round
    // labels it, and unlabelled it passes nothing on: (7..15, 3) stay 0.
    for (const int e : {1, 2, 5}) {
        Output out = run_edges(kCorridors, e);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_LABELS(out.raw_labels, corridor_labels(e, e < 2 ? e : 2), 16) << "E = " << e;
        EXPECT_EQ(out.segment_count, 1u);
        EXPECT_EQ(out.fillable, mask_of(kCorridors));  // the rounds never touch the mask
    }
    Output all = run_edges(kCorridors, 63);
    ASSERT_TRUE(all.ok) << all.error;
    EXPECT_LABELS(all.raw_labels, corridor_labels(8, 2), 16);
    std::vector<std::uint32_t> compacted = corridor_labels(8, 2);
    for (std::uint32_t& l : compacted) l = l != 0 ? 1u : 0u;  // 6 -> 1
    EXPECT_LABELS(all.labels, compacted, 16);
    // label_edges off: no round at all, whatever E.
    Output off = run_edges(kCorridors, 5, false);
    ASSERT_TRUE(off.ok) << off.error;
    EXPECT_LABELS(off.raw_labels, corridor_labels(0, 0), 16);
}

TEST(ReferenceEdgeRounds, TwoSegmentsShareABandByFirstArrivalThenSmallestLabel) {
    // C: the block (0..3, 8..11) is level-3 texel (0,2): offset_3 + 8 + 0 + 1 = 14. A: the 8x8 block (8..15, 8..15)
    // makes level-2 texel (1,1) fillable: offset_2 + 2 + 1 + 1 = 5, which its level-3 (and finer) children copy. So
    // the right-hand segment has the smaller label.
    // Row 9: the fillable (4,9) takes 14 in step 6a (left to right); the band between is x = 5, 6, 7.
    //   Round 1: (5,9) <- 14, (7,9) <- 5. Round 2: (6,9) sees 14 on its left and 5 on its right, both from round 1:
    //   the smaller, 5 (the one on the right, so not the first one visited).
    // Row 11: the band is x = 4..7. Round 1: (4,11) <- 14, (7,11) <- 5. Round 2: (5,11) <- 14 (its right neighbour
    //   is still unlabelled after round 1), (6,11) <- 5. Round 3 would bring 5 to (5,11), but a labelled pixel never
    //   changes: it keeps 14, for any E >= 2.
    // Row 10 between the blocks, rows 0..7 and the rest of rows 12..15 are invalid.
    const std::vector<std::string> rows = {
        "xxxxxxxxxxxxxxxx",  //
        "xxxxxxxxxxxxxxxx",  //
        "xxxxxxxxxxxxxxxx",  //
        "xxxxxxxxxxxxxxxx",  //
        "xxxxxxxxxxxxxxxx",  //
        "xxxxxxxxxxxxxxxx",  //
        "xxxxxxxxxxxxxxxx",  //
        "xxxxxxxxxxxxxxxx",  //
        "####xxxx########",  //
        "#####---########",  //
        "####xxxx########",  //
        "####----########",  //
        "xxxxxxxx########",  //
        "xxxxxxxx########",  //
        "xxxxxxxx########",  //
        "xxxxxxxx########",  //
    };
    const std::vector<std::string> blank(8, "................");
    std::vector<std::string> one = blank;
    for (const char* row : {"cccc....aaaaaaaa", "cccccc.aaaaaaaaa", "cccc....aaaaaaaa", "ccccc..aaaaaaaaa",
                            "........aaaaaaaa", "........aaaaaaaa", "........aaaaaaaa", "........aaaaaaaa"}) {
        one.emplace_back(row);
    }
    std::vector<std::string> more = blank;
    for (const char* row : {"cccc....aaaaaaaa", "ccccccaaaaaaaaaa", "cccc....aaaaaaaa", "ccccccaaaaaaaaaa",
                            "........aaaaaaaa", "........aaaaaaaa", "........aaaaaaaa", "........aaaaaaaa"}) {
        more.emplace_back(row);
    }
    Output out1 = run_edges(rows, 1);
    ASSERT_TRUE(out1.ok) << out1.error;
    EXPECT_LABELS(out1.raw_labels, labels_of(one, {{'a', 5}, {'c', 14}}), 16);
    for (const int e : {2, 3, 63}) {
        Output out = run_edges(rows, e);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_LABELS(out.raw_labels, labels_of(more, {{'a', 5}, {'c', 14}}), 16) << "E = " << e;
        EXPECT_LABELS(out.labels, labels_of(more, {{'a', 1}, {'c', 2}}), 16) << "E = " << e;
        EXPECT_EQ(out.segment_count, 2u);
    }
}

TEST(ReferenceEdgeRounds, RangeIsOneToSixtyThree) {
    const std::vector<std::uint8_t> mask(256, 1);
    const std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    for (const int e : {0, 64, -1}) {
        Params p;
        p.edge_rounds = e;
        Output a = pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p);
        EXPECT_FALSE(a.ok) << e;
        EXPECT_NE(a.error.find("edge_rounds"), std::string::npos) << a.error;
        EXPECT_FALSE(pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p).ok) << e;
    }
    for (const int e : {1, 63}) {
        Params p;
        p.edge_rounds = e;
        EXPECT_TRUE(pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p).ok) << e;
        EXPECT_TRUE(pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p).ok) << e;
    }
}

// ---------------------------------------------------------------------------------------------------------------
// edge_max_depth_step c (docs/algorithm.md section 5 step 6c): in rounds k >= 2 a neighbour q counts for pixel p only
// when also |z_p - z_q| <= s * z_p, s = (float)c, each of the two operations one float32 rounding. Round 1 is the
// contract's step, without the test.
//
// The scenes: 16 x 16, every row the same depth profile z(x), x and y the pixel's coordinates, given normals (0,0,-1),
// the paper metric with its defaults (dt = 10 mm). Every pixel has a vertical neighbour at its own depth (dd = 0), so
// it is fillable iff its horizontal neighbours lie within 10 of it. The profile:
//   x:  0..4   5   6   7     8     9     10..15
//   z:  F      G   A   1000  1015  1000  1000
// F is the far surface, A the first pixel of the near side's band. With |F - G| <= 10 and |G - A| > 10: x = 0..4 and
// 10..15 are fillable, x = 5..9 are not (5 and 6 see |G - A|, 7, 8 and 9 see 15) but valid. The pyramid is that of
// ReferenceEndToEnd.TwoPlanesWithDepthStep: level 3 (4x4) has column 0 (x 0..3) -> 6 and column 3 (x 12..15) -> 9
// after step 2 (level 2 has nothing: x = 5..9 cut both of its columns); level 4 column 5 (x 10..11) has no labelled
// parent and takes 9 in step 4; (4, y) takes 6 in step 6a. So after 6b: x = 0..4 carry 6 (the far side, the smaller
// label), x = 10..15 carry 9 (near), the band x = 5..9 is 0. Every row behaves the same (its vertical neighbours are
// labelled in the same round as the pixel), so each expected picture is one row.

std::vector<float> depth_step_points(float f, float g, float a) {
    return grid_points(16, 16, [=](int x, int) {
        if (x <= 4) return f;
        if (x == 5) return g;
        if (x == 6) return a;
        return x == 8 ? 1015.0f : 1000.0f;
    });
}

Output run_depth_step(float f, float g, float a, int edge_rounds, double c) {
    const std::vector<float> pts = depth_step_points(f, g, a);
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    Params p;
    p.edge_rounds = edge_rounds;
    p.edge_max_depth_step = c;
    return pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
}

// One row repeated 16 times: 'f' the far side's 6, 'n' the near side's 9, '.' 0.
std::vector<std::uint32_t> step_rows(const std::string& row) {
    return labels_of(std::vector<std::string>(16, row), {{'f', 6}, {'n', 9}});
}

// The expected mask: x = 5..9 not fillable.
std::vector<std::uint8_t> step_mask() {
    return mask_of(std::vector<std::string>(16, "#####-----######"));
}

TEST(ReferenceEdgeDepthStep, FarLabelCrossesTheStepWithoutTheTestNotWithIt) {
    // F = G = 2000, A = 1015: the far band is x = 5, the near band x = 6..9 (A = 1015, then 1000, 1015, 1000).
    // Without the test (c = 0): round 1 gives x = 5 the 6 of (4, y) and x = 9 the 9 of (10, y); round 2 gives x = 6
    // the 6 of x = 5 and x = 8 the 9 of x = 9; round 3 gives x = 7 the smaller of 6 (x = 6) and 9 (x = 8): 6. The
    // far surface's label takes x = 6 and 7 of the near side's band.
    // c = 1 (s = 1) is no test here either: |1015 - 2000| = 985 <= 1015.
    // With c = 0.02 (s * z_p = 20 at z 1000, 20.3 at 1015): round 2 refuses 6 to x = 6 (|1015 - 2000| = 985 > 20.3)
    // and x = 7 is not labelled yet, so x = 6 stays 0; x = 8 takes 9 (|1015 - 1000| = 15). Round 3: x = 7 takes 9
    // from x = 8 (15 <= 20), x = 6 is still refused the 6. Round 4: x = 6 takes 9 from x = 7 (15 <= 20.3). The near
    // side's label fills its band; the far side keeps its own band pixel x = 5.
    struct Case {
        double c;
        int e;
        const char* row;
    };
    const std::vector<Case> cases = {
        {0.0, 1, "ffffff...nnnnnnn"},  {0.0, 2, "fffffff.nnnnnnnn"},   {0.0, 3, "ffffffffnnnnnnnn"},
        {0.0, 63, "ffffffffnnnnnnnn"}, {1.0, 2, "fffffff.nnnnnnnn"},   {1.0, 63, "ffffffffnnnnnnnn"},
        {0.02, 1, "ffffff...nnnnnnn"}, {0.02, 2, "ffffff..nnnnnnnn"},  {0.02, 3, "ffffff.nnnnnnnnn"},
        {0.02, 4, "ffffffnnnnnnnnnn"}, {0.02, 63, "ffffffnnnnnnnnnn"},
    };
    for (const Case& k : cases) {
        const Output out = run_depth_step(2000.0f, 2000.0f, 1015.0f, k.e, k.c);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_EQ(out.fillable, step_mask()) << "c = " << k.c << ", E = " << k.e;
        EXPECT_LABELS(out.raw_labels, step_rows(k.row), 16) << "c = " << k.c << ", E = " << k.e;
        EXPECT_EQ(out.segment_count, 2u);
    }
    // Compacted: 6 -> 1, 9 -> 2.
    const Output out = run_depth_step(2000.0f, 2000.0f, 1015.0f, 10, 0.02);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_LABELS(out.labels, labels_of(std::vector<std::string>(16, "1111112222222222"), {{'1', 1}, {'2', 2}}), 16);
    // label_edges off: no round, whatever c.
    const std::vector<float> pts = depth_step_points(2000.0f, 2000.0f, 1015.0f);
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    Params off;
    off.label_edges = false;
    off.edge_rounds = 10;
    off.edge_max_depth_step = 0.02;
    const Output none = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, off);
    ASSERT_TRUE(none.ok) << none.error;
    EXPECT_LABELS(none.raw_labels, step_rows("fffff.....nnnnnn"), 16);
}

TEST(ReferenceEdgeDepthStep, RoundOneHasNoDepthTest) {
    // F = 2000, G = 2008, A = 1015: (4, y) is still fillable (it sees 0 and 8 <= 10), x = 5 is not (|2008 - 1015|).
    // c = 0.002: s * z_p = 4.016 at 2008 and 2.03 at 1015, so every depth difference here fails the test, the 8
    // between x = 5 and its fillable neighbour x = 4 included. Round 1 still gives x = 5 the 6 of x = 4 (and x = 9
    // the 9 of x = 10, at the same depth); rounds 2.. refuse everything: x = 6 (|1015 - 2008|), x = 8 (|1015 - 1000|
    // = 15 > 2.03), and x = 7 never has a labelled neighbour.
    for (const int e : {1, 2, 5}) {
        const Output out = run_depth_step(2000.0f, 2008.0f, 1015.0f, e, 0.002);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_EQ(out.fillable, step_mask());
        EXPECT_LABELS(out.raw_labels, step_rows("ffffff...nnnnnnn"), 16) << "E = " << e;
    }
    // Without the test the same scene spreads as usual: x = 6 takes 6 and x = 8 takes 9 in round 2, x = 7 the smaller
    // 6 in round 3.
    const Output untested = run_depth_step(2000.0f, 2008.0f, 1015.0f, 5, 0.0);
    ASSERT_TRUE(untested.ok) << untested.error;
    EXPECT_LABELS(untested.raw_labels, step_rows("ffffffffnnnnnnnn"), 16);
}

TEST(ReferenceEdgeDepthStep, BoundaryCountsAndTheLimitIsSTimesTheOwnDepth) {
    // E = 2, F = G, A = 1015: after round 2, x = 6 carries 6 iff the test passes for p = x = 6 (z_p = 1015) and
    // q = x = 5 (z_q = F); x = 8 takes 9 in round 2 (|1015 - 1000| = 15 passes every c below), x = 7 stays 0.
    // c = 0.5: s * z_p = 507.5, exact.
    struct Case {
        float f;
        double c;
        bool passes;
        const char* why;
    };
    const std::vector<Case> cases = {
        {1522.5f, 0.5, true, "|dz| = 507.5 == s * z_p: counts (<=)"},
        {1523.0f, 0.5, false, "|dz| = 508 > 507.5"},
        {1600.0f, 0.5, false, "|dz| = 585 > s * z_p = 507.5 (though <= s * z_q = 800)"},
        {507.5f, 0.5, true, "the far side nearer: |dz| = 507.5 == s * z_p (though > s * z_q = 253.75)"},
        {507.0f, 0.5, false, "|dz| = 508 > 507.5"},
    };
    for (const Case& k : cases) {
        const Output out = run_depth_step(k.f, k.f, 1015.0f, 2, k.c);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_EQ(out.fillable, step_mask()) << k.why;
        EXPECT_LABELS(out.raw_labels, step_rows(k.passes ? "fffffff.nnnnnnnn" : "ffffff..nnnnnnnn"), 16) << k.why;
    }
}

TEST(ReferenceEdgeDepthStep, LimitIsOneFloat32Product) {
    // c = 0.02: s = (float)0.02 = 0.0199999995529651641845703125. s * 1000 = 19.99999955... rounds to the float32
    // 20 (half an ulp of 20 is 2^-20 = 9.5e-7), so |1000 - 1020| = 20 counts; the product kept in double (19.9999996)
    // would refuse it. F = G = 1020, A = 1000 (x = 5 and 6 see 20 > 10: not fillable). E = 2.
    const Output at = run_depth_step(1020.0f, 1020.0f, 1000.0f, 2, 0.02);
    ASSERT_TRUE(at.ok) << at.error;
    EXPECT_EQ(at.fillable, step_mask());
    EXPECT_LABELS(at.raw_labels, step_rows("fffffff.nnnnnnnn"), 16);
    // One float step more (|dz| = 20.00006) is refused.
    const float above = std::nextafter(1020.0f, 2000.0f);
    const Output over = run_depth_step(above, above, 1000.0f, 2, 0.02);
    ASSERT_TRUE(over.ok) << over.error;
    EXPECT_LABELS(over.raw_labels, step_rows("ffffff..nnnnnnnn"), 16);

    // s is c rounded to float32 first: c = 0.3, s = 0.300000011920928955078125, z_p = A = 402. s * 402 =
    // 120.6000047922... rounds to the float32 120.600006103515625, while c * z_p rounded once (0.3 * 402 = 120.6) gives
    // 120.59999847412109375, one ulp (2^-17) below. F = G = 281.4f = 281.399993896484375: |402 - F| =
    // 120.600006103515625 (exact) counts with s, not with c. (s * z_q = 84.4 would refuse it too.)
    const Output rounded = run_depth_step(281.4f, 281.4f, 402.0f, 2, 0.3);
    ASSERT_TRUE(rounded.ok) << rounded.error;
    EXPECT_EQ(rounded.fillable, step_mask());
    EXPECT_LABELS(rounded.raw_labels, step_rows("fffffff.nnnnnnnn"), 16);
    const float below = std::nextafter(281.4f, 0.0f);  // |dz| = 120.60003662109375 > the limit: refused
    const Output beyond = run_depth_step(below, below, 402.0f, 2, 0.3);
    ASSERT_TRUE(beyond.ok) << beyond.error;
    EXPECT_LABELS(beyond.raw_labels, step_rows("ffffff..nnnnnnnn"), 16);
}

TEST(ReferenceEdgeDepthStep, RangeIsZeroOrOneMillionthToOne) {
    const std::vector<std::uint8_t> mask(256, 1);
    const std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // Refused by every entry point (edge_rounds 1, so the mask is not refused for its missing depths), naming it.
    for (const double c :
         {-1e-3, -1.0, nan, inf, -inf, 0.5e-6, std::nextafter(1e-6, 0.0), 1.5, std::nextafter(1.0, 2.0)}) {
        Params p;
        p.edge_max_depth_step = c;
        const Output a = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
        const Output b = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p);
        const Output m = pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p);
        for (const Output* o : {&a, &b, &m}) {
            EXPECT_FALSE(o->ok) << c;
            EXPECT_NE(o->error.find("edge_max_depth_step"), std::string::npos) << c << ": " << o->error;
        }
    }
    for (const double c : {0.0, -0.0, 1e-6, 0.02, 1.0}) {
        for (const int e : {1, 63}) {
            Params p;
            p.edge_max_depth_step = c;
            p.edge_rounds = e;
            EXPECT_TRUE(pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p).ok) << c << ", E = " << e;
            EXPECT_TRUE(pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p).ok) << c << ", E = " << e;
        }
    }
}

TEST(ReferenceEdgeDepthStep, MaskIsRefusedWhenTheTestWouldBeUsed) {
    // A mask has no depths: refused when label_edges is on, E >= 2 and c > 0; accepted otherwise.
    const std::vector<std::uint8_t> mask(256, 1);
    const auto run = [&](bool label_edges, int e, double c) {
        Params p;
        p.label_edges = label_edges;
        p.edge_rounds = e;
        p.edge_max_depth_step = c;
        return pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p);
    };
    for (const int e : {2, 63}) {
        for (const double c : {1e-6, 0.02, 1.0}) {
            const Output refused = run(true, e, c);
            EXPECT_FALSE(refused.ok) << "E = " << e << ", c = " << c;
            EXPECT_NE(refused.error.find("edge_max_depth_step"), std::string::npos) << refused.error;
            EXPECT_TRUE(run(false, e, c).ok) << "label_edges off, E = " << e << ", c = " << c;
        }
        EXPECT_TRUE(run(true, e, 0.0).ok) << "c = 0, E = " << e;
        EXPECT_TRUE(run(true, e, -0.0).ok) << "c = -0, E = " << e;
    }
    EXPECT_TRUE(run(true, 1, 0.02).ok) << "E = 1";
    EXPECT_TRUE(run(true, 1, 1.0).ok) << "E = 1";
    // An accepted mask is labelled as before: all fillable, one segment.
    const Output ok = run(true, 1, 0.02);
    EXPECT_EQ(ok.raw_labels, (std::vector<std::uint32_t>(256, 1)));
}

// ---------------------------------------------------------------------------------------------------------------
// Parameters.

TEST(ReferenceParams, Rejection) {
    const std::vector<std::uint8_t> mask(256, 1);
    const std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto rejected = [&](const Params& p) {
        Output a = pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p);
        Output b = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
        Output c = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p);
        return !a.ok && !a.error.empty() && !b.ok && !b.error.empty() && !c.ok && !c.error.empty();
    };
    auto with = [](auto change) {
        Params p;
        change(p);
        return p;
    };
    EXPECT_FALSE(rejected(Params{}));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.ct = nan; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.ct = inf; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.ct = -0.01; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.dt = nan; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.dt = -1.0; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.dt = -inf; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.unit_mm = 0.0; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.unit_mm = -1.0; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.unit_mm = inf; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.unit_mm = nan; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.bridge_levels = 0; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.unjoinable_gap = 0; })));
    EXPECT_TRUE(rejected(with([&](Params& p) { p.bridge_levels = -3; })));
    EXPECT_FALSE(rejected(with([&](Params& p) { p.dt = inf; })));
    EXPECT_FALSE(rejected(with([&](Params& p) { p.ct = 0.0; })));
    EXPECT_FALSE(rejected(with([&](Params& p) { p.ct = 10.0; })));
    EXPECT_FALSE(rejected(with([&](Params& p) { p.dt = 0.0; })));

    // normal_radius matters only when normals are estimated.
    Params r0;
    r0.normal_radius = 0;
    EXPECT_TRUE(pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, r0).ok);
    EXPECT_FALSE(pyrseg_ref::segment(pts.data(), nullptr, 16, 16, r0).ok);
    EXPECT_TRUE(pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, r0).ok);

    // Sizes.
    const Params p;
    EXPECT_FALSE(pyrseg_ref::segment_mask(mask.data(), nullptr, 0, 16, p).ok);
    EXPECT_FALSE(pyrseg_ref::segment_mask(mask.data(), nullptr, 16, -1, p).ok);
    EXPECT_FALSE(pyrseg_ref::segment(pts.data(), nrm.data(), 0, 0, p).ok);
    EXPECT_TRUE(pyrseg_ref::estimate_normals(pts.data(), 16, 16, 0).empty());
}

TEST(ReferenceParams, TooLargeIsRejectedBeforeReadingInput) {
    // 65536^2 = 2^32 pixels do not fit 32-bit labels; the inputs are null, so any read or allocation would show.
    const Params p;
    Output a = pyrseg_ref::segment_mask(nullptr, nullptr, 65536, 65536, p);
    EXPECT_FALSE(a.ok);
    EXPECT_FALSE(a.error.empty());
    Output b = pyrseg_ref::segment(nullptr, nullptr, 65536, 65536, p);
    EXPECT_FALSE(b.ok);
    Output c =
        pyrseg_ref::segment(nullptr, nullptr, std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), p);
    EXPECT_FALSE(c.ok);
}

// ---------------------------------------------------------------------------------------------------------------
// Metric: validity, curvature, depth.

TEST(ReferenceMetric, InvalidPointsAndNormals) {
    // 4x4 frontal plane (fallback path). Making pixel (1,1) invalid in any way clears B there; every other pixel still
    // has valid neighbours with the same normal and depth, so stays fillable, and they form one component (raw 1).
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    struct Case {
        const char* what;
        int comp;  // 0..2: point x, y, z; 3..5: normal x, y, z
        float value;
    };
    const std::vector<Case> cases = {
        {"x NaN", 0, nan},  {"x +inf", 0, inf}, {"y -inf", 1, -inf},  {"z NaN", 2, nan},
        {"z +inf", 2, inf}, {"z 0", 2, 0.0f},   {"z -0", 2, -0.0f},   {"z negative", 2, -5.0f},
        {"nx NaN", 3, nan}, {"ny inf", 4, inf}, {"nz -inf", 5, -inf},
    };
    const std::vector<std::uint8_t> expected_b = {1, 1, 1, 1, 1, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    const std::vector<std::uint32_t> expected_raw = {1, 1, 1, 1, 1, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    for (const Case& c : cases) {
        std::vector<float> pts = grid_points(4, 4, [](int, int) { return 1000.0f; });
        std::vector<float> nrm = constant_normals(16, 0.0f, 0.0f, -1.0f);
        if (c.comp < 3) {
            pts[3 * 5 + static_cast<std::size_t>(c.comp)] = c.value;
        } else {
            nrm[3 * 5 + static_cast<std::size_t>(c.comp - 3)] = c.value;
        }
        Output out = pyrseg_ref::segment(pts.data(), nrm.data(), 4, 4, Params{});
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_EQ(out.fillable, expected_b) << c.what;
        EXPECT_EQ(out.raw_labels, expected_raw) << c.what;
    }
    // A zero normal, with either sign of zero, is invalid.
    for (float zero : {0.0f, -0.0f}) {
        std::vector<float> pts = grid_points(4, 4, [](int, int) { return 1000.0f; });
        std::vector<float> nrm = constant_normals(16, 0.0f, 0.0f, -1.0f);
        nrm[15] = zero;
        nrm[16] = zero;
        nrm[17] = zero;
        Output out = pyrseg_ref::segment(pts.data(), nrm.data(), 4, 4, Params{});
        EXPECT_EQ(out.fillable, expected_b);
    }
}

TEST(ReferenceMetric, SubnormalDepthIsValid) {
    // All z = the smallest subnormal: valid (z > 0), equal depths, equal normals -> all fillable, one component.
    const float tiny = std::numeric_limits<float>::denorm_min();
    const std::vector<float> pts = grid_points(4, 4, [&](int, int) { return tiny; });
    const std::vector<float> nrm = constant_normals(16, 0.0f, 0.0f, -1.0f);
    Output out = pyrseg_ref::segment(pts.data(), nrm.data(), 4, 4, Params{});
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.fillable, (std::vector<std::uint8_t>(16, 1)));
    EXPECT_EQ(out.raw_labels, (std::vector<std::uint32_t>(16, 1)));
}

TEST(ReferenceMetric, ValidButNotFillableGetsEdgeLabelInvalidDoesNot) {
    // 16x16 frontal plane, defaults (N = 5, M = 3, U = 1). Pixel (5,5) has normal (0,0,0): invalid; its neighbours
    // keep k = 7 and stay fillable. Pixel (10,10) has normal (denorm_min, 0, 0): valid, but quantizes to (0,0,0), so
    // it and its 8 neighbours fail the curvature test (mean dot <= 7/8 < cos(0.25)).
    // Level 2 texels (1,0) -> 3 and (0,1) -> 4 are fillable; everything fillable is one component at level 3 -> 3.
    // Step 6 fills the pixels under non-fillable coarse texels; edge labelling gives the 3x3 ring 3 but not its
    // centre (10,10) (all its 4-neighbours are non-fillable) and not the invalid (5,5).
    std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    const std::size_t a = 5 * 16 + 5;
    nrm[3 * a] = 0.0f;
    nrm[3 * a + 1] = 0.0f;
    nrm[3 * a + 2] = 0.0f;
    const std::size_t c = 10 * 16 + 10;
    nrm[3 * c] = std::numeric_limits<float>::denorm_min();
    nrm[3 * c + 1] = 0.0f;
    nrm[3 * c + 2] = 0.0f;
    Output out = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, Params{});
    ASSERT_TRUE(out.ok) << out.error;
    std::vector<std::uint8_t> expected_b(256, 1);
    expected_b[a] = 0;
    for (int y = 9; y <= 11; ++y) {
        for (int x = 9; x <= 11; ++x) expected_b[static_cast<std::size_t>(y * 16 + x)] = 0;
    }
    EXPECT_EQ(out.fillable, expected_b);
    std::vector<std::uint32_t> expected_raw(256, 3);
    expected_raw[a] = 0;
    expected_raw[c] = 0;
    EXPECT_LABELS(out.raw_labels, expected_raw, 16);
    EXPECT_EQ(out.segment_count, 1u);
    EXPECT_EQ(out.normals, nrm);  // given normals are copied as they are
}

// Two pixels side by side (2x1, fallback path): each has exactly one valid neighbour (k = 1).
std::vector<std::uint8_t> pair_fillable(const float* n0, const float* n1, const Params& p) {
    const float pts[6] = {0.0f, 0.0f, 1000.0f, 1.0f, 0.0f, 1000.0f};
    const float nrm[6] = {n0[0], n0[1], n0[2], n1[0], n1[1], n1[2]};
    Output out = pyrseg_ref::segment(pts, nrm, 2, 1, p);
    EXPECT_TRUE(out.ok) << out.error;
    return out.fillable;
}

TEST(ReferenceMetric, CurvatureAtAndAbovePiNeverAnEdge) {
    // (1,1,1) and (-1,-1,-1): S = -3 * 2^26. ct >= pi -> Tc = -2^28 -> k*Tc = -2^28 <= S: fillable. Just below pi,
    // Tc = floor(cos(ct) * 2^26) = -2^26 > S: edge.
    const float up[3] = {1.0f, 1.0f, 1.0f};
    const float down[3] = {-1.0f, -1.0f, -1.0f};
    const std::vector<std::uint8_t> both = {1, 1};
    const std::vector<std::uint8_t> none = {0, 0};
    Params p;
    p.ct = std::numbers::pi;
    EXPECT_EQ(pair_fillable(up, down, p), both);
    p.ct = 100.0;
    EXPECT_EQ(pair_fillable(up, down, p), both);
    p.ct = std::nextafter(std::numbers::pi, 0.0);
    EXPECT_EQ(pair_fillable(up, down, p), none);
    p.ct = 3.1;
    EXPECT_EQ(pair_fillable(up, down, p), none);
}

TEST(ReferenceMetric, CurvatureThresholdAndHalfEvenQuantization) {
    const float front[3] = {0.0f, 0.0f, -1.0f};
    const float tilted[3] = {0.0f, 0.1f, -0.995f};  // q = (0, 819, -8151): dot with (0,0,-8192) = 8151 * 8192 < 2^26
    Params p;
    p.ct = 0.0;  // Tc = 2^26
    EXPECT_EQ(pair_fillable(front, front, p), (std::vector<std::uint8_t>{1, 1}));
    EXPECT_EQ(pair_fillable(front, tilted, p), (std::vector<std::uint8_t>{0, 0}));
    p.ct = 0.25;  // Tc = 65022611 <= 66772992
    EXPECT_EQ(pair_fillable(front, tilted, p), (std::vector<std::uint8_t>{1, 1}));

    // ct = sqrt(3) * 2^-13: cos(ct) * 2^26 = 2^26 - 1.5 (to well below an ulp), so Tc = 2^26 - 2.
    // n = (2.5 / 8192, 0, -1) quantizes to (2, 0, -8192) with round half to even (3 with half away from zero);
    // with m = (-1 / 8192, 0, -1) -> (-1, 0, -8192) the dot is 2^26 - 2 (fillable) rather than 2^26 - 3 (edge).
    p.ct = std::sqrt(3.0) / 8192.0;
    const float half[3] = {2.5f / 8192.0f, 0.0f, -1.0f};
    const float minus_one[3] = {-1.0f / 8192.0f, 0.0f, -1.0f};
    EXPECT_EQ(pair_fillable(half, minus_one, p), (std::vector<std::uint8_t>{1, 1}));
    const float three_half[3] = {3.5f / 8192.0f, 0.0f, -1.0f};  // -> 4: dot 2^26 - 4 < Tc
    EXPECT_EQ(pair_fillable(three_half, minus_one, p), (std::vector<std::uint8_t>{0, 0}));
    // Components outside [-1, 1] are clamped: (2, 0, -3) -> (8192, 0, -8192), dot with itself 2^27 >= 2^26.
    const float big[3] = {2.0f, 0.0f, -3.0f};
    p.ct = 0.0;
    EXPECT_EQ(pair_fillable(big, big, p), (std::vector<std::uint8_t>{1, 1}));
}

std::vector<std::uint8_t> row_fillable(const std::vector<float>& z, const Params& p) {
    const int w = static_cast<int>(z.size());
    const std::vector<float> pts = grid_points(w, 1, [&](int x, int) { return z[static_cast<std::size_t>(x)]; });
    const std::vector<float> nrm = constant_normals(w, 0.0f, 0.0f, -1.0f);
    Output out = pyrseg_ref::segment(pts.data(), nrm.data(), w, 1, p);
    EXPECT_TRUE(out.ok) << out.error;
    return out.fillable;
}

TEST(ReferenceMetric, DepthThreshold) {
    Params p;  // dt = 10 mm, unit 1 mm
    // The middle pixel sees |dz| = 0 and 10 -> d = 10 <= 10; the ends see one neighbour -> d = 0.
    EXPECT_EQ(row_fillable({1000.0f, 1000.0f, 1010.0f}, p), (std::vector<std::uint8_t>{1, 1, 1}));
    EXPECT_EQ(row_fillable({1000.0f, 1000.0f, 1010.5f}, p), (std::vector<std::uint8_t>{1, 0, 1}));
    p.dt = 0.0;
    EXPECT_EQ(row_fillable({1000.0f, 1000.0f, 1010.0f}, p), (std::vector<std::uint8_t>{1, 0, 1}));
    p.dt = std::numeric_limits<double>::infinity();
    EXPECT_EQ(row_fillable({1000.0f, 1000.0f, 1.0e30f}, p), (std::vector<std::uint8_t>{1, 1, 1}));

    // Metres: dt_units = (float)(10 / 1000) = 0.00999999977...; 1.01f - 1.0f = 0.0099999905 passes, 1.0101f fails.
    Params m;
    m.unit_mm = 1000.0;
    EXPECT_EQ(row_fillable({1.0f, 1.0f, 1.01f}, m), (std::vector<std::uint8_t>{1, 1, 1}));
    EXPECT_EQ(row_fillable({1.0f, 1.0f, 1.0101f}, m), (std::vector<std::uint8_t>{1, 0, 1}));
}

TEST(ReferenceMetric, DepthIsMaxMinusMinOfDifferences) {
    // A spike: the centre sees |dz| = 50 to all 8 neighbours -> d = 0 -> fillable; each neighbour sees 0 and 50.
    const std::vector<float> pts =
        grid_points(3, 3, [](int x, int y) { return (x == 1 && y == 1) ? 1050.0f : 1000.0f; });
    const std::vector<float> nrm = constant_normals(9, 0.0f, 0.0f, -1.0f);
    Output out = pyrseg_ref::segment(pts.data(), nrm.data(), 3, 3, Params{});
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.fillable, (std::vector<std::uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0}));
}

// ---------------------------------------------------------------------------------------------------------------
// End to end through the metric.

TEST(ReferenceEndToEnd, TwoPlanesWithDepthStep) {
    // 16x16, z = 1000 for x < 8 and 1100 for x >= 8, given normals (0,0,-1). Columns 7 and 8 see |dz| = 0 and 100:
    // edges. Level 4 fillable columns X 0..2 and 5..7; level 3: X 0 and 3 -> new labels 6, 10, 14, 18 and 9, 13,
    // 17, 21; step 2 -> 6 and 9. Level 4 X = 2 and X = 5 get 0 from their parents and 6 / 9 in step 4. Level 5
    // column 6 and 9 get their labels in step 6 (rows), columns 7 and 8 by edge labelling.
    const std::vector<float> pts = grid_points(16, 16, [](int x, int) { return x < 8 ? 1000.0f : 1100.0f; });
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    Output out = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, Params{});
    ASSERT_TRUE(out.ok) << out.error;
    std::vector<std::uint8_t> expected_b;
    std::vector<std::uint32_t> expected_raw;
    std::vector<std::uint32_t> expected;
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
            expected_b.push_back((x == 7 || x == 8) ? 0 : 1);
            expected_raw.push_back(x < 8 ? 6u : 9u);
            expected.push_back(x < 8 ? 1u : 2u);
        }
    }
    EXPECT_EQ(out.fillable, expected_b);
    EXPECT_LABELS(out.raw_labels, expected_raw, 16);
    EXPECT_LABELS(out.labels, expected, 16);
    EXPECT_EQ(out.segment_count, 2u);

    // dt = +inf removes the step: everything fillable, the 1x1 level is fillable, label 1 everywhere.
    Params p;
    p.dt = std::numeric_limits<double>::infinity();
    Output flat = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
    ASSERT_TRUE(flat.ok) << flat.error;
    EXPECT_EQ(flat.raw_labels, (std::vector<std::uint32_t>(256, 1)));
}

TEST(ReferenceEndToEnd, FrontalPlaneWithEstimatedNormals) {
    // Every tangent is along +x / +y, so every normal is (0,0,-1) after orientation (borders one-sided, same result).
    const std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    Output out = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, Params{});
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.normals, constant_normals(256, 0.0f, 0.0f, -1.0f));
    EXPECT_EQ(out.fillable, (std::vector<std::uint8_t>(256, 1)));
    EXPECT_EQ(out.raw_labels, (std::vector<std::uint32_t>(256, 1)));
    EXPECT_EQ(out.segment_count, 1u);
}

// ---------------------------------------------------------------------------------------------------------------
// Normals pass (docs/algorithm.md section 8).

TEST(ReferenceNormals, TiltedPlaneEveryPixelIncludingBorders) {
    // z = 10 + x. Centre: u = (2,0,2), v = (0,2,0); borders: u = (1,0,1) or v = (0,1,0). F gives U = (2^14, 0, 2^14),
    // V = (0, 2^14, 0) either way; C = (-2^28, 0, 2^28) -> D = (-2^14, 0, 2^14), len = 23170, q = (-5793, 0, 5793);
    // q . F(P) > 0 (z dominates) -> flipped.
    const std::vector<float> pts = grid_points(3, 3, [](int x, int) { return 10.0f + static_cast<float>(x); });
    const std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    ASSERT_EQ(n.size(), 27u);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 3; ++x) EXPECT_EQ(normal_at(n, 3, x, y), q13(5793, 0, -5793)) << x << "," << y;
    }
}

TEST(ReferenceNormals, SkewedPlane) {
    // z = 8 + x/2 + y/4, centre (1,1): u = (2, 0, 1) -> U = (16384, 0, 8192); v = (0, 2, 0.5) -> V = (0, 16384, 4096).
    // C = (-2^27, -2^26, 2^28) -> D = (-8192, -4096, 16384), len = 18770, q = (-3575, -1788, 7151) -> flipped.
    const std::vector<float> pts = grid_points(
        3, 3, [](int x, int y) { return 8.0f + 0.5f * static_cast<float>(x) + 0.25f * static_cast<float>(y); });
    const std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    EXPECT_EQ(normal_at(n, 3, 1, 1), q13(3575, 1788, -7151));
}

TEST(ReferenceNormals, CurvedSurfaceOneSidedAtBorders) {
    // z = 10 + x^2 (10, 11, 14). x = 0: u = P1 - P0 = (1,0,1) -> (5793, 0, -5793). x = 1: u = P2 - P0 = (2,0,4) ->
    // U = (8192, 0, 16384), D = (-16384, 0, 8192), len = 18317 -> (7327, 0, -3664). x = 2: u = P2 - P1 = (1,0,3) ->
    // U = (8192, 0, 24576), D = (-24576, 0, 8192), len = 25905 -> (7772, 0, -2591).
    const std::vector<float> pts = grid_points(3, 3, [](int x, int) { return 10.0f + static_cast<float>(x * x); });
    const std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    for (int y = 0; y < 3; ++y) {
        EXPECT_EQ(normal_at(n, 3, 0, y), q13(5793, 0, -5793)) << y;
        EXPECT_EQ(normal_at(n, 3, 1, y), q13(7327, 0, -3664)) << y;
        EXPECT_EQ(normal_at(n, 3, 2, y), q13(7772, 0, -2591)) << y;
    }
}

TEST(ReferenceNormals, InvalidNeighbourFallsBackToOneSided) {
    // Same surface; the right neighbour of the centre has z < 0, so u = P - L = (1, 0, 1) -> (5793, 0, -5793).
    std::vector<float> pts = grid_points(3, 3, [](int x, int) { return 10.0f + static_cast<float>(x * x); });
    pts[3 * (1 * 3 + 2) + 2] = -14.0f;
    const std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    EXPECT_EQ(normal_at(n, 3, 1, 1), q13(5793, 0, -5793));
    EXPECT_EQ(normal_at(n, 3, 2, 1), q13(0, 0, 0));  // not point-valid itself
}

TEST(ReferenceNormals, RadiusTwo) {
    // z = 10 + x^2 on 5x5, r = 2. (0,2): u = P2 - P0 = (2,0,4) -> (7327, 0, -3664). (1,2): x - 2 < 0, so
    // u = P3 - P1 = (2,0,8) -> U = (4096, 0, 16384), D = (-16384, 0, 4096), len = 16888 -> (7948, 0, -1987).
    // (2,2): u = P4 - P0 = (4,0,16) -> same U -> (7948, 0, -1987). (4,2): u = P4 - P2 = (2,0,12) ->
    // U = (4096, 0, 24576), D = (-24576, 0, 4096), len = 24914 -> (8081, 0, -1347).
    const std::vector<float> pts = grid_points(5, 5, [](int x, int) { return 10.0f + static_cast<float>(x * x); });
    const std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 5, 5, 2);
    EXPECT_EQ(normal_at(n, 5, 0, 2), q13(7327, 0, -3664));
    EXPECT_EQ(normal_at(n, 5, 1, 2), q13(7948, 0, -1987));
    EXPECT_EQ(normal_at(n, 5, 2, 2), q13(7948, 0, -1987));
    EXPECT_EQ(normal_at(n, 5, 4, 2), q13(8081, 0, -1347));
}

TEST(ReferenceNormals, NonDyadicTangentsTruncateTowardZero) {
    // Centre of 3x3 with L, T at z = 10 and R, D at z = 10.3f, 10.1f: u = (2, 0, 0.30000019), v = (0, 2, 0.10000038)
    // (exact float subtractions). F: 0.30000019 * 2^13 = 2457.6 -> 2457, 0.10000038 * 2^13 = 819.2 -> 819.
    // C = (-2457 * 2^14, -819 * 2^14, 2^28) -> D = (-2457, -819, 16384), len = 16587, q = (-1213, -404, 8092) ->
    // flipped. With R, D at 9.7f, 9.9f the tangent components are negative and their magnitudes are truncated the same
    // way (sign-magnitude, toward zero; an arithmetic shift would give 1214 and 405).
    auto centre = [](float zr, float zd) {
        std::vector<float> pts = grid_points(3, 3, [](int, int) { return 10.0f; });
        pts[3 * 4 + 2] = 10.15f;
        pts[3 * 5 + 2] = zr;  // (2,1)
        pts[3 * 7 + 2] = zd;  // (1,2)
        return normal_at(pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1), 3, 1, 1);
    };
    EXPECT_EQ(centre(10.3f, 10.1f), q13(1213, 404, -8092));
    EXPECT_EQ(centre(9.7f, 9.9f), q13(-1213, -404, -8092));
}

TEST(ReferenceNormals, MissingNeighboursGiveNoNormal) {
    // Only the centre is valid: no tangent at all.
    std::vector<float> pts = grid_points(
        3, 3, [](int x, int y) { return (x == 1 && y == 1) ? 10.0f : std::numeric_limits<float>::quiet_NaN(); });
    std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    EXPECT_EQ(n, std::vector<float>(27, 0.0f));

    // Horizontal neighbours but no vertical ones (a single row).
    pts = grid_points(3, 1, [](int, int) { return 10.0f; });
    n = pyrseg_ref::estimate_normals(pts.data(), 3, 1, 1);
    EXPECT_EQ(n, std::vector<float>(9, 0.0f));

    // Vertical neighbours of the centre invalid (z = 0), horizontal ones fine.
    pts = grid_points(3, 3, [](int x, int) { return x == 1 ? 0.0f : 10.0f; });
    pts[3 * 4 + 2] = 10.0f;
    n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    EXPECT_EQ(normal_at(n, 3, 1, 1), q13(0, 0, 0));

    // Collinear tangents: u = (1,0,0), v = (2,0,0) -> C = 0 -> no normal.
    const std::vector<float> line = {0.0f, 0.0f, 10.0f, 1.0f, 0.0f, 10.0f, 2.0f, 0.0f, 10.0f, 3.0f, 1.0f, 10.0f};
    n = pyrseg_ref::estimate_normals(line.data(), 2, 2, 1);
    EXPECT_EQ(normal_at(n, 2, 0, 0), q13(0, 0, 0));
}

TEST(ReferenceNormals, OrientationTowardTheCamera) {
    // Frontal plane: C = (0, 0, 2^28) -> q = (0, 0, 8192), q . F(P) > 0 -> flipped to (0, 0, -8192).
    std::vector<float> pts = grid_points(3, 3, [](int, int) { return 10.0f; });
    std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    EXPECT_EQ(normal_at(n, 3, 1, 1), q13(0, 0, -8192));
    // Mirrored grid (x = -column): u = (-2, 0, 0) -> C = (0, 0, -2^28) -> already toward the camera, not flipped.
    for (std::size_t i = 0; i < 9; ++i) pts[3 * i] = -pts[3 * i];
    n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    EXPECT_EQ(normal_at(n, 3, 1, 1), q13(0, 0, -8192));
}

TEST(ReferenceNormals, ShiftPastThirtyOneAndZeroDotNotFlipped) {
    // P = (x * 2^30, y * 2^30, 10 + x). Centre: u = (2^31, 0, 2): z shift 9 + 30 = 39 > 31 -> 0, so U = (2^14, 0, 0);
    // V = (0, 2^14, 0); q = (0, 0, 8192). F(P) = F(2^30, 2^30, 11) = (2^14, 2^14, 0) (z shift 36): q . F(P) = 0, not
    // > 0, so no flip.
    const std::vector<float> pts = [] {
        std::vector<float> v;
        for (int y = 0; y < 3; ++y) {
            for (int x = 0; x < 3; ++x) {
                v.push_back(static_cast<float>(x) * 1073741824.0f);
                v.push_back(static_cast<float>(y) * 1073741824.0f);
                v.push_back(10.0f + static_cast<float>(x));
            }
        }
        return v;
    }();
    const std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 3, 3, 1);
    EXPECT_EQ(normal_at(n, 3, 1, 1), q13(0, 0, 8192));
}

TEST(ReferenceNormals, SmallCrossProductIsShiftedLeft) {
    // 2x2, pixel (0,0) at (0,0,10): u = (1, 1, 2^-14) -> U = (16384, 16384, 1); v = (1+2^-14, 1+2^-14, 2^-14) ->
    // V = (16385, 16385, 1). C = (-1, 1, 0): s = 0 -> D = (-16384, 16384, 0), len = 23170, q = (-5793, 5793, 0).
    // F(P) = (0, 0, 20480): q . F(P) = 0 -> not flipped.
    // (Without the left shift len would be 1 and q = (-8192, 8192, 0).)
    const float e = 1.0f / 16384.0f;
    const std::vector<float> pts = {0.0f,     0.0f,     10.0f,     1.0f, 1.0f, 10.0f + e,
                                    1.0f + e, 1.0f + e, 10.0f + e, 1.0f, 1.0f, 10.0f};
    const std::vector<float> n = pyrseg_ref::estimate_normals(pts.data(), 2, 2, 1);
    EXPECT_EQ(normal_at(n, 2, 0, 0), q13(-5793, 5793, 0));
}

// ---------------------------------------------------------------------------------------------------------------
// Robust normals (docs/algorithm.md section 8b). unit_mm = 1 unless said: e = 4 (2^4 >= 16), so G(v) = 16 v for the
// integer millimetre coordinates used here, Zi = 16 z and J = z (|dz| <= z/16 keeps a pixel in the window). For
// grid_points x = column and y = row, so G(x + r) - G(x - r) = 32 r. Each case writes its sums U and V by hand; the
// rest is the 15-bit normalisation of U and V and steps 2..5 of section 8 (C, D, len, q, orientation).

std::vector<float> robust_normals(const std::vector<float>& pts, int w, int h, int r, int window,
                                  double unit_mm = 1.0) {
    return pyrseg_ref::estimate_robust_normals(pts.data(), w, h, r, window, unit_mm);
}

Params robust_params() {
    Params p;
    p.metric = pyrseg_ref::Metric::robust;
    return p;
}

TEST(ReferenceRobustNormals, PlaneTiltedAboutOneAxisEveryPixel) {
    // z = 1000 + x, r = 1, R = 1. Every window pixel with a horizontal tangent adds (32, 0, 32), with a vertical one
    // (0, 32, 0); a 9x9 centre has 9 of each: U = (288, 0, 288) -> U' = (18432, 0, 18432), V' = (0, 18432, 0).
    // C = (-18432^2, 0, 18432^2) -> D = (-20736, 0, 20736), len = 29325, q = (-5793, 0, 5793), q . F(P) > 0 -> flipped.
    // A border pixel has fewer tangents, but U stays a multiple of (1, 0, 1) and V of (0, 1, 0): the same normal.
    const std::vector<float> pts = grid_points(9, 9, [](int x, int) { return 1000.0f + static_cast<float>(x); });
    const std::vector<float> n = robust_normals(pts, 9, 9, 1, 1);
    ASSERT_EQ(n.size(), 243u);
    for (int y = 0; y < 9; ++y) {
        for (int x = 0; x < 9; ++x) EXPECT_EQ(normal_at(n, 9, x, y), q13(5793, 0, -5793)) << x << "," << y;
    }

    // z = 1000 + 2y: U = (288, 0, 0) -> (18432, 0, 0), V = (0, 288, 576) -> (0, 9216, 18432). C = (0, -18432^2,
    // 18432 * 9216) -> D = (0, -20736, 10368), len = 23183, q = (0, -7327, 3664) -> flipped.
    const std::vector<float> pts_y =
        grid_points(9, 9, [](int, int y) { return 1000.0f + 2.0f * static_cast<float>(y); });
    const std::vector<float> ny = robust_normals(pts_y, 9, 9, 1, 1);
    for (int y = 0; y < 9; ++y) {
        for (int x = 0; x < 9; ++x) EXPECT_EQ(normal_at(ny, 9, x, y), q13(0, 7327, -3664)) << x << "," << y;
    }
}

TEST(ReferenceRobustNormals, WindowOverImageBorders) {
    // r = 2, R = 1 on z = 1000 + x: a horizontal tangent needs 2 <= x <= 6, a vertical one 2 <= y <= 6 (no one-sided
    // fallback). Columns 0 and 8 (windows x 0..1 and 7..8) and rows 0 and 8 reach none -> no normal; every other
    // pixel reaches one and gets the plane's normal, corners (1,1) and (7,7) included.
    const std::vector<float> pts = grid_points(9, 9, [](int x, int) { return 1000.0f + static_cast<float>(x); });
    const std::vector<float> n = robust_normals(pts, 9, 9, 2, 1);
    for (int y = 0; y < 9; ++y) {
        for (int x = 0; x < 9; ++x) {
            const bool none = x == 0 || x == 8 || y == 0 || y == 8;
            EXPECT_EQ(normal_at(n, 9, x, y), none ? q13(0, 0, 0) : q13(5793, 0, -5793)) << x << "," << y;
        }
    }

    // z = 1000 + x^2 on 5x5, r = 1. Horizontal tangents at x = 1, 2, 3: (32, 0, 64), (32, 0, 128), (32, 0, 192).
    // R = 7 covers the whole image from every pixel (|dz| <= 16 <= z/16): U = 5 rows * (96, 0, 384) = (480, 0, 1920),
    // V = 15 * (0, 32, 0) = (0, 480, 0) -> U' = (7680, 0, 30720), V' = (0, 30720, 0), C = (-943718400, 0, 235929600)
    // -> D = (-28800, 0, 7200), len = 29686, q = (-7948, 0, 1987) -> flipped, the same at every pixel.
    const std::vector<float> curved = grid_points(5, 5, [](int x, int) { return 1000.0f + static_cast<float>(x * x); });
    const std::vector<float> whole = robust_normals(curved, 5, 5, 1, 7);
    for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 5; ++x) EXPECT_EQ(normal_at(whole, 5, x, y), q13(7948, 0, -1987)) << x << "," << y;
    }
    // R = 1 at the corner (0,0): window (0..1) x (0..1); horizontal tangents at (1,0), (1,1): U = (64, 0, 128);
    // vertical ones at (0,1), (1,1): V = (0, 64, 0) -> U' = (8192, 0, 16384), V' = (0, 16384, 0) ->
    // D = (-16384, 0, 8192), len = 18317, q = (-7327, 0, 3664) -> flipped.
    const std::vector<float> small = robust_normals(curved, 5, 5, 1, 1);
    EXPECT_EQ(normal_at(small, 5, 0, 0), q13(7327, 0, -3664));

    // Arguments outside the ranges give an empty result.
    EXPECT_TRUE(robust_normals(curved, 5, 5, 0, 1).empty());
    EXPECT_TRUE(robust_normals(curved, 5, 5, 1, 0).empty());
    EXPECT_TRUE(robust_normals(curved, 5, 5, 1, 8).empty());
    EXPECT_TRUE(robust_normals(curved, 5, 5, 1, 1, 0.0).empty());
    EXPECT_TRUE(pyrseg_ref::estimate_robust_normals(curved.data(), 0, 5, 1, 1, 1.0).empty());
}

TEST(ReferenceRobustNormals, WindowMembershipIsInclusiveAtJ) {
    // 9x9 frontal z = 1000 with one outlier at (5,4); pixel (4,4), r = 1, R = 1: Zi = 16000, J = 16000 >> 4 = 1000.
    // The tangents crossing the outlier (of (4,4) horizontally: +16 dz; of (5,3) and (5,5) vertically: +-16 dz, which
    // cancel) count either way; the outlier's own tangents (32, 0, 0) and (0, 32, 0) only when |G(z) - Zi| <= J.
    // z = 1062.5 -> G = 17000, |G - Zi| = 1000 = J: in. U = 9 * (32, 0, 0) + (0, 0, 1000) = (288, 0, 1000),
    // V = (0, 288, 0) -> U' = (9216, 0, 32000), V' = (0, 18432, 0), D = (-18000, 0, 5184), len = 18731 ->
    // q = (7872, 0, -2267) after the flip.
    // z = 1062.5625 -> G = 17001: out. U = (256, 0, 1001), V = (0, 256, 0) -> U' = (8192, 0, 32032),
    // V' = (0, 16384, 0), D = (-32032, 0, 8192), len = 33062 -> q = (7937, 0, -2030) after the flip.
    auto centre = [](float outlier) {
        std::vector<float> pts = grid_points(9, 9, [](int, int) { return 1000.0f; });
        pts[3 * (4 * 9 + 5) + 2] = outlier;
        return normal_at(robust_normals(pts, 9, 9, 1, 1), 9, 4, 4);
    };
    EXPECT_EQ(centre(1062.5f), q13(7872, 0, -2267));
    EXPECT_EQ(centre(1062.5625f), q13(7937, 0, -2030));
}

TEST(ReferenceRobustNormals, DepthStepKeepsTheOtherSideOutOfTheWindow) {
    // 16x9: z = 1000 for x <= 7 (frontal) and z = 2000 + 8y for x >= 8 (tilted about the x axis); r = 1, R = 1.
    // Far from the step each side has its own plane's normal:
    //   (2,4) and (5,4) (window x 4..6, its tangents reach x 3..7): U = (288, 0, 0), V = (0, 288, 0) -> (0, 0, -8192);
    //   (12,4): Zi = 32512, J = 2032, t_v = (0, 32, 256): U = (288, 0, 0), V = (0, 288, 2304) -> U' = (18432, 0, 0),
    //   V' = (0, 2304, 18432), D = (0, -20736, 2592), len = 20897 -> (0, 8129, -1016) after the flip.
    // (7,4), next to the step: column 8 is out of its window (|G(z) - 16000| >= 16000 > J = 1000), so the right
    // plane's tilt about x never enters V and q_y = 0 (with column 8 in, V would gain 3 * (0, 32, 256)). Column 7's
    // own horizontal tangents do cross the step (the text tests only the window pixels' depths):
    //   U = 6 * (32, 0, 0) + 16 * (0, 0, 1024 + 1032 + 1040) = (192, 0, 49536), V = 6 * (0, 32, 0) = (0, 192, 0)
    //   -> U' = (96, 0, 24768), V' = (0, 24576, 0), D = (-18576, 0, 72), len = 18576, q = (-8192, 0, 32);
    //   F(P) = (224, 128, 32000): q . F(P) = -8192 * 224 + 32 * 32000 < 0, not flipped.
    const std::vector<float> pts =
        grid_points(16, 9, [](int x, int y) { return x <= 7 ? 1000.0f : 2000.0f + 8.0f * static_cast<float>(y); });
    const std::vector<float> n = robust_normals(pts, 16, 9, 1, 1);
    EXPECT_EQ(normal_at(n, 16, 2, 4), q13(0, 0, -8192));
    EXPECT_EQ(normal_at(n, 16, 5, 4), q13(0, 0, -8192));
    EXPECT_EQ(normal_at(n, 16, 12, 4), q13(0, 8129, -1016));
    EXPECT_EQ(normal_at(n, 16, 7, 4), q13(-8192, 0, 32));
}

TEST(ReferenceRobustNormals, FixedPointRoundsHalfToEven) {
    // 5x3, x_i = 2.5 i / 16 mm, y = row, z = 1000 + i/16. G(x_i) = rint(2.5 i) = 0, 2, 5, 8, 10 (half to even; half
    // away from zero or truncation would give 3 or 7). Pixel (2,1), r = 1, R = 1: horizontal tangents at x = 1, 2, 3
    // per row: (5, 0, 2), (6, 0, 2), (5, 0, 2); vertical ones only on row 1: (0, 32, 0). U = 3 * (16, 0, 6) =
    // (48, 0, 18), V = (0, 96, 0) -> U' = (24576, 0, 9216), V' = (0, 24576, 0), D = (-6912, 0, 18432), len = 19685
    // -> q = (-2876, 0, 7671) -> flipped. (With U = (45, 0, 18) it would be (3042, 0, -7606).)
    std::vector<float> pts;
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 5; ++x) {
            pts.push_back(2.5f * static_cast<float>(x) / 16.0f);
            pts.push_back(static_cast<float>(y));
            pts.push_back(1000.0f + static_cast<float>(x) / 16.0f);
        }
    }
    EXPECT_EQ(normal_at(robust_normals(pts, 5, 3, 1, 1), 5, 2, 1), q13(2876, 0, -7671));
}

TEST(ReferenceRobustNormals, FixedPointSaturatesAtTwoToThe22) {
    // Millimetres (e = 4): z = 300000 + x -> 16 z > 2^22, every G(z) = 2^22, the tangents lose their z: frontal.
    // z = 260000 + x -> G(z) = 4160000 + 16 x < 2^22: the tilted plane's (5793, 0, -5793).
    auto centre = [](float z0, float step, double unit_mm) {
        std::vector<float> pts;
        for (int y = 0; y < 9; ++y) {
            for (int x = 0; x < 9; ++x) {
                pts.push_back(static_cast<float>(x) * step);
                pts.push_back(static_cast<float>(y) * step);
                pts.push_back(z0 + static_cast<float>(x) * step);
            }
        }
        return normal_at(robust_normals(pts, 9, 9, 1, 1, unit_mm), 9, 4, 4);
    };
    EXPECT_EQ(centre(300000.0f, 1.0f, 1.0), q13(0, 0, -8192));
    EXPECT_EQ(centre(260000.0f, 1.0f, 1.0), q13(5793, 0, -5793));
    // Metres: e = 14 (2^13 < 16000 <= 2^14), steps of 1/1024 m -> 16 in G. 260 m -> 4259840 > 2^22: saturated;
    // 250 m -> 4096000 + 16 x: not.
    EXPECT_EQ(centre(260.0f, 1.0f / 1024.0f, 1000.0), q13(0, 0, -8192));
    EXPECT_EQ(centre(250.0f, 1.0f / 1024.0f, 1000.0), q13(5793, 0, -5793));
}

// ---------------------------------------------------------------------------------------------------------------
// Robust metric (docs/algorithm.md section 2b). ct = 0.25 (the default): c0 * 2^26 = 2086252.06..., A = 2086252.125
// as a float, so L = 2086252 while Bc = 0, 2^26 - L = 65022612 and 4 * (2^26 - L) = 260090448.
// The curvature term of a pixel (x, y) looks only at the pairs a = (x + s*dx, y + s*dy), b = (x - s*dx, y - s*dy) on
// the axes (1, 0), (0, 1), (1, 1), (1, -1) whose two pixels exist and are valid (kp of them) and passes iff kp >= 1
// and S = sum qn_a . qn_b >= kp * (2^26 - L). So in a W x 1 row only the horizontal pair can exist, and only for
// s <= x <= W - 1 - s: at stride 1 the two end pixels have kp = 0 and are never fillable.

// Pixels in a row (W x 1) with given normals, robust metric (stride as p says).
std::vector<std::uint8_t> robust_row(const std::vector<float>& z, const std::vector<std::vector<float>>& normals,
                                     Params p) {
    p.metric = pyrseg_ref::Metric::robust;
    const int w = static_cast<int>(z.size());
    const std::vector<float> pts = grid_points(w, 1, [&](int x, int) { return z[static_cast<std::size_t>(x)]; });
    std::vector<float> nrm;
    for (const std::vector<float>& n : normals) nrm.insert(nrm.end(), n.begin(), n.end());
    Output out = pyrseg_ref::segment(pts.data(), nrm.data(), w, 1, p);
    EXPECT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.normals, nrm);  // given normals are what the metric uses
    return out.fillable;
}

// A w x h image at z = 1000 with the given normals (row-major, one per pixel), robust metric: the fillable mask.
std::vector<std::uint8_t> robust_grid(int w, int h, const std::vector<std::vector<float>>& normals, Params p) {
    p.metric = pyrseg_ref::Metric::robust;
    const std::vector<float> pts = grid_points(w, h, [](int, int) { return 1000.0f; });
    std::vector<float> nrm;
    for (const std::vector<float>& n : normals) nrm.insert(nrm.end(), n.begin(), n.end());
    Output out = pyrseg_ref::segment(pts.data(), nrm.data(), w, h, p);
    EXPECT_TRUE(out.ok) << out.error;
    return out.fillable;
}

Params stride1() {
    Params p = robust_params();
    p.curvature_stride = 1;
    return p;
}

const std::vector<float> kFront = {0.0f, 0.0f, -1.0f};
const std::vector<float> kBack = {0.0f, 0.0f, 1.0f};
const std::vector<float> kNone = {0.0f, 0.0f, 0.0f};  // makes the pixel invalid

// Distance of a coordinate (0..15) from the band 4..11.
int band_distance(int v) {
    return v < 4 ? 4 - v : (v > 11 ? v - 11 : 0);
}

TEST(ReferenceRobustMetric, TiltedPlaneEndToEnd) {
    // 16x16, z = 1000 + x, robust defaults (r = 1 here, R = 3, s = 4): every normal is (5793, 0, -5793) (see the
    // normals tests), so every pair has qn_a . qn_b = 2 * 5793^2 = 67117698 > 2^26 - L; d = 1 - 0 or 0 <= 10
    // everywhere. A pixel has a horizontal pair iff 4 <= x <= 11, a vertical one iff 4 <= y <= 11, and the diagonal
    // ones only when it has both: fillable iff x or y is in 4..11 (a plus); the four 4x4 corners have kp = 0.
    // Pyramid (N = 5, M = 3, U = 1): level 4 (8x8) is fillable iff tx or ty is in 2..5, level 3 (4x4) iff tx or ty
    // is in 1..2 (a plus of 12 texels), level 2 has a corner texel under each of its texels: nothing. So every level-3
    // texel gets a new label, and the fill at level 3 gives the plus the smallest, that of texel (1,0):
    // offset_3 + 0 * 4 + 1 + 1 = 5 + 2 = 7 (not old: old is <= offset_2 = 1). Levels 4 and 5 copy it.
    // Edge labelling (one round by default) gives 7 to the corner pixels next to the plus (x = 3 or 12, or y = 3 or
    // 12); the other 3x3 of each corner stay 0.
    const std::vector<float> pts = grid_points(16, 16, [](int x, int) { return 1000.0f + static_cast<float>(x); });
    Params p = robust_params();
    Output out = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p);
    ASSERT_TRUE(out.ok) << out.error;
    std::vector<float> expected_normals;
    for (int i = 0; i < 256; ++i) {
        const std::vector<float> n = q13(5793, 0, -5793);
        expected_normals.insert(expected_normals.end(), n.begin(), n.end());
    }
    EXPECT_EQ(out.normals, expected_normals);
    // segment() estimated them with section 8b and the parameters' r, R and unit_mm.
    EXPECT_EQ(out.normals, pyrseg_ref::estimate_robust_normals(pts.data(), 16, 16, 1, 3, 1.0));
    std::vector<std::uint8_t> plus(256, 0);
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
            plus[static_cast<std::size_t>(y * 16 + x)] = (band_distance(x) == 0 || band_distance(y) == 0) ? 1 : 0;
        }
    }
    EXPECT_EQ(out.fillable, plus);
    const std::vector<std::string> one_round = {
        "...7777777777...",  //
        "...7777777777...",  //
        "...7777777777...",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "7777777777777777",  //
        "...7777777777...",  //
        "...7777777777...",  //
        "...7777777777...",  //
    };
    EXPECT_LABELS(out.raw_labels, labels_of(one_round, {{'7', 7}}), 16);
    EXPECT_EQ(out.segment_count, 1u);

    // With E edge rounds a corner pixel is labelled iff it is at most E steps from the plus, i.e. iff
    // min(band_distance(x), band_distance(y)) <= E (round k labels the pixels at that distance k). E = 3 leaves the
    // four image corners; E = 4 labels everything.
    p.edge_rounds = 3;
    Output three = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p);
    ASSERT_TRUE(three.ok) << three.error;
    std::vector<std::uint32_t> expected_three(256, 7);
    for (const std::size_t corner : {0u, 15u, 240u, 255u}) expected_three[corner] = 0;
    EXPECT_LABELS(three.raw_labels, expected_three, 16);
    EXPECT_EQ(three.fillable, plus);  // the rounds do not touch the mask
    p.edge_rounds = 4;
    Output four = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p);
    ASSERT_TRUE(four.ok) << four.error;
    EXPECT_LABELS(four.raw_labels, std::vector<std::uint32_t>(256, 7), 16);
}

TEST(ReferenceRobustMetric, CreaseSeenAtStrideFourNotAtStrideOne) {
    // 32x12, z = 1000 + |x - 16| (two 45-degree planes meeting at x = 16), r = 1, R = 3, dt = 10, ct = 0.6:
    // c0 * 2^26 = 11721528.46..., A = 11721528 as a float -> L = 11721528, 4 * (2^26 - L) = 221549344.
    // Normals (the same in every row: U stays a multiple of one row's tangent sum, V of (0, 1, 0)):
    //   x <= 12: (-5793, 0, -5793); x >= 20: (5793, 0, -5793) (windows on one plane only).
    //   (16,y): per window row the tangents are 3 * (32, 0, -32) + (32, 0, 0) + 3 * (32, 0, 32) = (224, 0, 0):
    //   frontal (0, 0, -8192).
    //   (15,y): per row 4 * (32, 0, -32) + (32, 0, 0) + 2 * (32, 0, 32) = (224, 0, -64); U = (1568, 0, -448),
    //   V = (0, 1568, 0) -> U' = (25088, 0, -7168), V' = (0, 25088, 0), D = (5488, 0, 19208), len = 19976
    //   -> (-2251, 0, -7877); (17,y) mirrored: (2251, 0, -7877).
    // Stride 4 at (16,6), kp = 4: horizontal (20,6).(12,6) = -5793^2 + 5793^2 = 0, vertical (16,10).(16,2) = 2^26,
    // diagonals (20,10).(12,2) = 0 and (20,2).(12,10) = 0: S = 67108864 < 221549344 -> not fillable (mean 1 - cos
    // 0.75). Stride 1, kp = 4: horizontal and both diagonals (17,.).(15,.) = 7877^2 - 2251^2 = 56980128, vertical
    // 2^26: S = 3 * 56980128 + 67108864 = 238049248 >= 221549344 -> fillable (mean 1 - cos 0.113: the window blurs
    // the crease over the neighbours). d = 1 - 0 <= 10 either way.
    // (4,6) sees only left-plane normals at both strides (S = 4 * 67117698): fillable.
    // (With the default ct = 0.25 the crease pixel would be an edge at both strides: 238049248 < 260090448.)
    const std::vector<float> pts =
        grid_points(32, 12, [](int x, int) { return 1000.0f + static_cast<float>(x > 16 ? x - 16 : 16 - x); });
    Params p = robust_params();
    p.normal_window = 3;
    p.ct = 0.6;
    Output s4 = pyrseg_ref::segment(pts.data(), nullptr, 32, 12, p);
    ASSERT_TRUE(s4.ok) << s4.error;
    EXPECT_EQ(normal_at(s4.normals, 32, 16, 6), q13(0, 0, -8192));
    EXPECT_EQ(normal_at(s4.normals, 32, 15, 6), q13(-2251, 0, -7877));
    EXPECT_EQ(normal_at(s4.normals, 32, 17, 6), q13(2251, 0, -7877));
    EXPECT_EQ(normal_at(s4.normals, 32, 12, 6), q13(-5793, 0, -5793));
    EXPECT_EQ(normal_at(s4.normals, 32, 20, 6), q13(5793, 0, -5793));
    // The other ends of the stride-4 pairs.
    EXPECT_EQ(normal_at(s4.normals, 32, 16, 2), q13(0, 0, -8192));
    EXPECT_EQ(normal_at(s4.normals, 32, 16, 10), q13(0, 0, -8192));
    EXPECT_EQ(normal_at(s4.normals, 32, 12, 2), q13(-5793, 0, -5793));
    EXPECT_EQ(normal_at(s4.normals, 32, 12, 10), q13(-5793, 0, -5793));
    EXPECT_EQ(normal_at(s4.normals, 32, 20, 2), q13(5793, 0, -5793));
    EXPECT_EQ(normal_at(s4.normals, 32, 20, 10), q13(5793, 0, -5793));
    EXPECT_EQ(s4.fillable[6 * 32 + 16], 0);
    EXPECT_EQ(s4.fillable[6 * 32 + 4], 1);

    p.curvature_stride = 1;
    Output s1 = pyrseg_ref::segment(pts.data(), nullptr, 32, 12, p);
    ASSERT_TRUE(s1.ok) << s1.error;
    EXPECT_EQ(s1.normals, s4.normals);  // the stride does not touch the normals
    EXPECT_EQ(s1.fillable[6 * 32 + 16], 1);
    EXPECT_EQ(s1.fillable[6 * 32 + 4], 1);

    p.ct = 0.25;  // 238049248 < 260090448
    Output s1_default = pyrseg_ref::segment(pts.data(), nullptr, 32, 12, p);
    ASSERT_TRUE(s1_default.ok) << s1_default.error;
    EXPECT_EQ(s1_default.fillable[6 * 32 + 16], 0);
}

TEST(ReferenceRobustMetric, StrideLooksOnlyAtPixelsAtTheStride) {
    // 17x1 at z = 1000, all frontal but pixel 8, which faces away (0, 0, 1): a pair with it has S = -2^26 < 2^26 - L.
    // Stride 4: pixels 4..12 have a pair (x - 4, x + 4). Pixel 4 (pair 0, 8) and pixel 12 (pair 8, 16) fail; pixel 8
    // (pair 4, 12) passes: its own normal takes no part. Pixels 0..3 and 13..16 have no pair.
    // Stride 1: pixels 1..15 have a pair; pixel 7 (pair 6, 8) and pixel 9 (pair 8, 10) fail, pixel 8 (7, 9) passes.
    std::vector<std::vector<float>> nrm(17, kFront);
    nrm[8] = kBack;
    const std::vector<float> z(17, 1000.0f);
    Params p = robust_params();
    EXPECT_EQ(robust_row(z, nrm, p), (std::vector<std::uint8_t>{0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0}));
    p.curvature_stride = 1;
    EXPECT_EQ(robust_row(z, nrm, p), (std::vector<std::uint8_t>{0, 1, 1, 1, 1, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1, 1, 0}));

    // 5x5 flat frontal. Stride 2: a pixel has a horizontal pair iff x = 2, a vertical one iff y = 2, diagonal ones
    // only at the centre (4 pairs): fillable iff x = 2 or y = 2. Stride 3 reaches no pair (x - 3 >= 0 and x + 3 <= 4
    // is impossible): nothing fillable. Stride 1: a pair unless x and y are both 0 or 4: all but the 4 corners.
    const std::vector<std::vector<float>> flat(25, kFront);
    p.curvature_stride = 2;
    EXPECT_EQ(robust_grid(5, 5, flat, p), mask_of({"..#..", "..#..", "#####", "..#..", "..#.."}));
    p.curvature_stride = 3;
    EXPECT_EQ(robust_grid(5, 5, flat, p), std::vector<std::uint8_t>(25, 0));
    p.curvature_stride = 1;
    EXPECT_EQ(robust_grid(5, 5, flat, p), mask_of({".###.", "#####", "#####", "#####", ".###."}));
}

TEST(ReferenceRobustMetric, PairsAreOppositePixelsOnFourAxes) {
    // 3x3 at z = 1000, stride 1, the centre (1,1) has the 4 pairs (2,1)/(0,1), (1,2)/(1,0), (2,2)/(0,0) and
    // (2,0)/(0,2). All frontal: S = 4 * 2^26 -> fillable. One pixel facing away spoils exactly one pair:
    // S = 3 * 2^26 - 2^26 = 134217728 < 4 * (2^26 - L) = 260090448 -> the centre is an edge, whichever axis it is on.
    const auto centre_fillable = [](int x, int y, const std::vector<float>& n) {
        std::vector<std::vector<float>> nrm(9, kFront);
        nrm[static_cast<std::size_t>(y * 3 + x)] = n;
        return robust_grid(3, 3, nrm, stride1())[4];
    };
    EXPECT_EQ(centre_fillable(1, 1, kFront), 1);
    EXPECT_EQ(centre_fillable(2, 1, kBack), 0);  // (1, 0)
    EXPECT_EQ(centre_fillable(1, 2, kBack), 0);  // (0, 1)
    EXPECT_EQ(centre_fillable(0, 0, kBack), 0);  // (1, 1)
    EXPECT_EQ(centre_fillable(2, 0, kBack), 0);  // (1, -1)
    // The centre's own normal takes no part: facing away, it is still fillable (S = 4 * 2^26).
    EXPECT_EQ(centre_fillable(1, 1, kBack), 1);
    // An invalid end drops its pair: (2,0) invalid leaves kp = 3, S = 3 * 2^26 >= 3 * 65022612 -> fillable. (Were
    // the pair counted with a zero dot product, kp = 4 and 201326592 < 260090448: an edge.)
    EXPECT_EQ(centre_fillable(2, 0, kNone), 1);
    // Edge midpoints of the 3x3: (1,0) has only the pair (0,0)/(2,0), (0,1) only (0,0)/(0,2); corners have none.
    // With (0,0) facing away both midpoints next to it fail (S = -2^26) and the other two pass.
    std::vector<std::vector<float>> corner_back(9, kFront);
    corner_back[0] = kBack;
    EXPECT_EQ(robust_grid(3, 3, corner_back, stride1()), mask_of({"...", "..#", ".#."}));
}

TEST(ReferenceRobustMetric, CurvatureLimitIsFloorOfTAndInclusive) {
    // Three pixels in a row at stride 1: only the middle one has a pair (pixels 0 and 2, kp = 1), so it passes iff
    // qn_0 . qn_2 >= 2^26 - L; the ends have kp = 0 and are never fillable. The middle pixel's own normal takes no
    // part: it faces away throughout.
    // ct = acos(1 - 8191.75 / 2^26): A = (float)(c0 * 2^26) = 8191.75 -> L = 8191; normals (0,0,-1) and
    // (0,0,-8191/8192): S = 8192 * 8191 = 67100672 < 2^26 - 8191 = 67100673 -> edge. With 8192.25: L = 8192,
    // S = 2^26 - L: passes.
    Params p = stride1();
    const std::vector<float> almost = {0.0f, 0.0f, -8191.0f / 8192.0f};
    const std::vector<float> z(3, 1000.0f);
    const std::vector<std::uint8_t> none = {0, 0, 0};
    const std::vector<std::uint8_t> middle = {0, 1, 0};
    p.ct = std::acos(1.0 - 8191.75 / 67108864.0);
    EXPECT_EQ(robust_row(z, {kFront, kBack, almost}, p), none);
    p.ct = std::acos(1.0 - 8192.25 / 67108864.0);
    EXPECT_EQ(robust_row(z, {kFront, kBack, almost}, p), middle);

    // ct = pi/2: c0 = 1 - 6.1e-17 rounds to 2^26 as a float -> L = 2^26, the test is S >= 0.
    p.ct = std::numbers::pi / 2.0;
    const std::vector<float> side = {1.0f, 0.0f, 0.0f};
    const std::vector<float> side_back = {1.0f, 0.0f, 1.0f / 8192.0f};
    EXPECT_EQ(robust_row(z, {kFront, kBack, side}, p), middle);     // S = 0
    EXPECT_EQ(robust_row(z, {kFront, kBack, side_back}, p), none);  // S = -8192

    // The default stride 4 finds no pair in an 8x1 image (x - 4 >= 0 and x + 4 <= 7 is impossible): kp = 0 ->
    // nothing fillable. In 9x1 exactly pixel 4 has one (pixels 0 and 8).
    const Params d = robust_params();
    EXPECT_EQ(robust_row(std::vector<float>(8, 1000.0f), std::vector<std::vector<float>>(8, kFront), d),
              std::vector<std::uint8_t>(8, 0));
    EXPECT_EQ(robust_row(std::vector<float>(9, 1000.0f), std::vector<std::vector<float>>(9, kFront), d),
              (std::vector<std::uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0}));
}

TEST(ReferenceRobustMetric, CurvatureAtAndAbovePi) {
    // Three pixels, stride 1: the middle one's pair is (0, 2). ct >= pi: A = 2^28, Bc = 0 -> L = 2^28, the test is
    // S >= kp * (2^26 - 2^28) = -3 * kp * 2^26: always. Opposite unit normals (0,0,-1), (0,0,1): S = -2^26 -> passes.
    // Just below pi c0 = 2 as a double, so A = 2^27 -> L = 2^27: -2^26 >= 2^26 - 2^27 passes with equality.
    // ct = 3.1: A = 134159688 < 2^27 -> 2^26 - L = -67050824 > S -> edge.
    Params p = stride1();
    const std::vector<float> z(3, 1000.0f);
    const std::vector<std::uint8_t> middle = {0, 1, 0};
    const std::vector<std::uint8_t> none = {0, 0, 0};
    p.ct = std::numbers::pi;
    EXPECT_EQ(robust_row(z, {kFront, kFront, kBack}, p), middle);
    p.ct = 100.0;
    EXPECT_EQ(robust_row(z, {kFront, kFront, kBack}, p), middle);
    p.ct = std::nextafter(std::numbers::pi, 0.0);
    EXPECT_EQ(robust_row(z, {kFront, kFront, kBack}, p), middle);
    p.ct = 3.1;
    EXPECT_EQ(robust_row(z, {kFront, kFront, kBack}, p), none);

    // (0.70710677, 0, -0.70710677) quantizes to (5793, 0, -5793), |qn|^2 = 67117698 > 2^26, so the opposite pair has
    // S = -67117698 < -2^26: only L = 2^28 (ct >= pi) passes it whatever the normals; just below pi it is an edge.
    const std::vector<float> diag = {0.70710677f, 0.0f, -0.70710677f};
    const std::vector<float> diag_back = {-0.70710677f, 0.0f, 0.70710677f};
    p.ct = std::numbers::pi;
    EXPECT_EQ(robust_row(z, {diag, kFront, diag_back}, p), middle);
    p.ct = std::nextafter(std::numbers::pi, 0.0);
    EXPECT_EQ(robust_row(z, {diag, kFront, diag_back}, p), none);

    // The extreme: 3x3, stride 1, every pair of the centre made of (1,1,1) and (-1,-1,-1) (qn = +-(8192, 8192,
    // 8192), dot -3 * 2^26): S = 4 * -3 * 2^26 = -3 * 2^28 = kp * (2^26 - 2^28): passes with equality at ct = pi.
    // Just below pi: kp * (2^26 - 2^27) = -2^28 > S -> edge. The midpoints (0,1) (pair (0,0)/(0,2)) and (2,1)
    // (pair (2,0)/(2,2)) also pair up with down: they follow the centre. (1,0) (two downs) and (1,2) (two ups) pass
    // at any ct; corners have no pair.
    const std::vector<float> up = {1.0f, 1.0f, 1.0f};
    const std::vector<float> down = {-1.0f, -1.0f, -1.0f};
    const std::vector<std::vector<float>> opposed = {down, down, down, down, kFront, up, up, up, up};
    p.ct = std::numbers::pi;
    EXPECT_EQ(robust_grid(3, 3, opposed, p), mask_of({".#.", "###", ".#."}));
    p.ct = std::nextafter(std::numbers::pi, 0.0);
    EXPECT_EQ(robust_grid(3, 3, opposed, p), mask_of({".#.", "...", ".#."}));
}

TEST(ReferenceRobustMetric, DepthLimitGrowsWithDepthSquared) {
    // dt = 10 mm, dt_per_m2 = 1: Bd = (float)1e-6. z = 2000: z * z = 4e6, Bd * 4e6 rounds to 4, D = 14 exactly.
    // Three frontal pixels at stride 1: the middle one passes the curvature test (its pair, S = 2^26) and sees
    // dd = 0 and the step -> d = step; the ends have no pair (kp = 0) and are never fillable, whatever their depth.
    Params p = stride1();
    p.dt_per_m2 = 1.0;
    const std::vector<std::vector<float>> front(3, kFront);
    const std::vector<std::uint8_t> middle = {0, 1, 0};
    const std::vector<std::uint8_t> none = {0, 0, 0};
    EXPECT_EQ(robust_row({2000.0f, 2000.0f, 2012.0f}, front, p), middle);
    EXPECT_EQ(robust_row({2000.0f, 2000.0f, 2014.0f}, front, p), middle);  // d = 14 = D
    EXPECT_EQ(robust_row({2000.0f, 2000.0f, 2014.001f}, front, p), none);  // d = 14.000977 > D
    // At 1 m the growth is only 1 mm: D = 11.
    EXPECT_EQ(robust_row({1000.0f, 1000.0f, 1012.0f}, front, p), none);
    EXPECT_EQ(robust_row({1000.0f, 1000.0f, 1011.0f}, front, p), middle);
    // z * z = +inf (z = 1e20): D = 10 + inf = +inf, any finite d passes.
    EXPECT_EQ(robust_row({1e20f, 1e20f, 3e20f}, front, p), middle);
    // Without the growth D = dt_units = 10.
    p.dt_per_m2 = 0.0;
    EXPECT_EQ(robust_row({2000.0f, 2000.0f, 2012.0f}, front, p), none);
    EXPECT_EQ(robust_row({2000.0f, 2000.0f, 2010.0f}, front, p), middle);
    EXPECT_EQ(robust_row({1e20f, 1e20f, 3e20f}, front, p), none);

    // Metres: dt_units = (float)0.01, Bd = (float)1e-3; z = 2: D = 0.01 + 0.004 ~ 0.014 >= 2.012f - 2 ~ 0.012.
    Params m = stride1();
    m.unit_mm = 1000.0;
    m.dt_per_m2 = 1.0;
    EXPECT_EQ(robust_row({2.0f, 2.0f, 2.012f}, front, m), middle);
    m.dt_per_m2 = 0.0;
    EXPECT_EQ(robust_row({2.0f, 2.0f, 2.012f}, front, m), none);
}

TEST(ReferenceRobustMetric, CurvatureGrowthMakesANoisyFarSurfaceFillable) {
    // Normals tilted (+-1024, 0, -8128) / 8192 in the pattern + + - - + + - - along a row: at stride 1 every inner
    // pixel's pair (x - 1, x + 1) has opposite tilts, qn_a . qn_b = 8128^2 - 1024^2 = 65015808, so it passes iff
    // L >= 2^26 - 65015808 = 2093056 (the ends have no pair).
    // No growth: L = 2086252 -> edges. ct_growth_per_m2 = 0.01: Bc = (float)(((c0 * 2^26) * 0.01) * 1e-6) =
    // 0.0208625197...; z = 3000: t = A + Bc * 9e6 = 2274014.75 -> L = 2274014: fillable. The same surface at z = 500:
    // t = 2091467.75 -> L = 2091467 < 2093056: still edges.
    const std::vector<float> plus = {1024.0f / 8192.0f, 0.0f, -8128.0f / 8192.0f};
    const std::vector<float> minus = {-1024.0f / 8192.0f, 0.0f, -8128.0f / 8192.0f};
    const std::vector<std::vector<float>> noisy = {plus, plus, minus, minus, plus, plus, minus, minus};
    const std::vector<std::uint8_t> none(8, 0);
    const std::vector<std::uint8_t> inner = {0, 1, 1, 1, 1, 1, 1, 0};
    Params p = stride1();
    EXPECT_EQ(robust_row(std::vector<float>(8, 3000.0f), noisy, p), none);
    p.ct_growth_per_m2 = 0.01;
    EXPECT_EQ(robust_row(std::vector<float>(8, 3000.0f), noisy, p), inner);
    EXPECT_EQ(robust_row(std::vector<float>(8, 500.0f), noisy, p), none);
    // z * z = +inf: t = +inf -> L = 2^28, even opposite normals pass (S = -2^26 >= 2^26 - 2^28).
    const std::vector<float> far(3, 1e20f);
    EXPECT_EQ(robust_row(far, {kFront, kFront, kBack}, p), (std::vector<std::uint8_t>{0, 1, 0}));
    p.ct_growth_per_m2 = 0.0;
    EXPECT_EQ(robust_row(far, {kFront, kFront, kBack}, p), (std::vector<std::uint8_t>{0, 0, 0}));
}

TEST(ReferenceRobustMetric, ParameterErrors) {
    const std::vector<std::uint8_t> mask(256, 1);
    const std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // Rejected by every entry point, with a message naming the parameter.
    auto rejected_for = [&](const Params& p, const std::string& name) {
        Output a = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
        Output b = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p);
        Output c = pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p);
        for (const Output* o : {&a, &b, &c}) {
            if (o->ok || o->error.find(name) == std::string::npos) return false;
        }
        return true;
    };
    auto accepted = [&](const Params& p) {
        return pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p).ok &&
               pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p).ok &&
               pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p).ok;
    };
    auto with = [](Params p, auto change) {
        change(p);
        return p;
    };
    const Params paper;
    const Params robust = robust_params();
    EXPECT_TRUE(accepted(paper));
    EXPECT_TRUE(accepted(robust));

    // Paper: the four must keep their defaults.
    EXPECT_TRUE(rejected_for(with(paper, [](Params& p) { p.normal_window = 2; }), "normal_window"));
    EXPECT_TRUE(rejected_for(with(paper, [](Params& p) { p.curvature_stride = 1; }), "curvature_stride"));
    EXPECT_TRUE(rejected_for(with(paper, [](Params& p) { p.dt_per_m2 = 1.0; }), "dt_per_m2"));
    EXPECT_TRUE(rejected_for(with(paper, [](Params& p) { p.ct_growth_per_m2 = 0.5; }), "ct_growth_per_m2"));

    // Robust: ranges.
    EXPECT_TRUE(rejected_for(with(robust, [](Params& p) { p.normal_window = 0; }), "normal_window"));
    EXPECT_TRUE(rejected_for(with(robust, [](Params& p) { p.normal_window = 8; }), "normal_window"));
    EXPECT_TRUE(accepted(with(robust, [](Params& p) { p.normal_window = 1; })));
    EXPECT_TRUE(accepted(with(robust, [](Params& p) { p.normal_window = 7; })));
    EXPECT_TRUE(rejected_for(with(robust, [](Params& p) { p.curvature_stride = 0; }), "curvature_stride"));
    EXPECT_TRUE(rejected_for(with(robust, [](Params& p) { p.curvature_stride = 65; }), "curvature_stride"));
    EXPECT_TRUE(accepted(with(robust, [](Params& p) { p.curvature_stride = 1; })));
    EXPECT_TRUE(accepted(with(robust, [](Params& p) { p.curvature_stride = 64; })));
    for (double bad : {-1.0, nan, inf, -inf}) {
        EXPECT_TRUE(rejected_for(with(robust, [&](Params& p) { p.dt_per_m2 = bad; }), "dt_per_m2")) << bad;
        EXPECT_TRUE(rejected_for(with(robust, [&](Params& p) { p.ct_growth_per_m2 = bad; }), "ct_growth_per_m2"))
            << bad;
    }
    EXPECT_TRUE(accepted(with(robust, [](Params& p) { p.dt_per_m2 = 1e6; })));
    EXPECT_TRUE(accepted(with(robust, [](Params& p) { p.ct_growth_per_m2 = 1e6; })));
    // The section 2 checks still apply, and normal_radius still matters only when normals are estimated.
    EXPECT_FALSE(accepted(with(robust, [](Params& p) { p.ct = -1.0; })));
    const Params r0 = with(robust, [](Params& p) { p.normal_radius = 0; });
    EXPECT_TRUE(pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, r0).ok);
    EXPECT_FALSE(pyrseg_ref::segment(pts.data(), nullptr, 16, 16, r0).ok);
}

// ---------------------------------------------------------------------------------------------------------------
// Depth images (docs/algorithm.md section 1b).

using pyrseg_ref::DepthFormat;
using pyrseg_ref::DepthInput;
using pyrseg_ref::DepthPoints;

constexpr std::uint32_t kNoData = 0x7fc00000u;

std::uint32_t bits(float f) {
    return std::bit_cast<std::uint32_t>(f);
}

float from_bits(std::uint32_t b) {
    return std::bit_cast<float>(b);
}

DepthInput depth_of(const void* samples, DepthFormat format, int w, int h, double m) {
    DepthInput in;
    in.samples = samples;
    in.format = format;
    in.width = w;
    in.height = h;
    in.metres_per_unit = m;
    in.fx = 1.0;
    in.fy = 1.0;
    in.cx = 0.0;
    in.cy = 0.0;
    return in;
}

// Pixel (u, v) of the points is (x, y, z), compared by bits.
::testing::AssertionResult point_is(const DepthPoints& p, int w, int u, int v, float x, float y, float z) {
    const auto i = static_cast<std::size_t>(3 * (v * w + u));
    if (p.points.size() < i + 3) return ::testing::AssertionFailure() << "no point " << u << "," << v;
    const std::uint32_t got[3] = {bits(p.points[i]), bits(p.points[i + 1]), bits(p.points[i + 2])};
    const std::uint32_t want[3] = {bits(x), bits(y), bits(z)};
    for (int c = 0; c < 3; ++c) {
        if (got[c] != want[c]) {
            return ::testing::AssertionFailure() << "pixel " << u << "," << v << " component " << c << ": got "
                                                 << p.points[i + c] << " (0x" << std::hex << got[c] << "), want "
                                                 << (c == 0   ? x
                                                     : c == 1 ? y
                                                              : z)
                                                 << " (0x" << want[c] << ")";
        }
    }
    return ::testing::AssertionSuccess();
}

::testing::AssertionResult no_data(const DepthPoints& p, int w, int u, int v) {
    return point_is(p, w, u, v, from_bits(kNoData), from_bits(kNoData), from_bits(kNoData));
}

TEST(ReferenceDepth, U16ZeroIsMissingAndZIsDTimesS) {
    // fx = fy = 1, cx = cy = 0: ku[u] = u, kv[v] = v exactly.
    const std::vector<std::uint16_t> d = {0, 1234, 65535, 1000, 0, 7};
    const DepthInput in = depth_of(d.data(), DepthFormat::u16, 3, 2, 0.001);
    // m = 0.001, unit_mm = 1: 0.001 * 1000 rounds to 1.0 in double, s = 1.0f, so z = d and x = z * u, y = z * v.
    DepthPoints p = pyrseg_ref::depth_to_points(in, 1.0);
    ASSERT_TRUE(p.ok) << p.error;
    ASSERT_EQ(p.points.size(), 18u);
    EXPECT_TRUE(no_data(p, 3, 0, 0));
    EXPECT_TRUE(point_is(p, 3, 1, 0, 1234.0f, 0.0f, 1234.0f));
    EXPECT_TRUE(point_is(p, 3, 2, 0, 131070.0f, 0.0f, 65535.0f));
    EXPECT_TRUE(point_is(p, 3, 0, 1, 0.0f, 1000.0f, 1000.0f));
    EXPECT_TRUE(no_data(p, 3, 1, 1));
    EXPECT_TRUE(point_is(p, 3, 2, 1, 14.0f, 7.0f, 7.0f));

    // unit_mm = 1000: s = (float)(1.0 / 1000) = 0.001f = 1.00000004749745e-3. z = 1000 * s = 1.0000000475 -> 1.0f;
    // z = 1234 * s = 1.2340000586 -> 0x3f9df3b7, one ulp above 1.234f (0x3f9df3b6), which computing d * m in
    // double would give.
    p = pyrseg_ref::depth_to_points(in, 1000.0);
    ASSERT_TRUE(p.ok) << p.error;
    const float s = 0.001f;
    EXPECT_EQ(bits(1234.0f * s), 0x3f9df3b7u);
    EXPECT_TRUE(no_data(p, 3, 0, 0));
    EXPECT_TRUE(point_is(p, 3, 1, 0, from_bits(0x3f9df3b7u), 0.0f, from_bits(0x3f9df3b7u)));
    EXPECT_TRUE(point_is(p, 3, 2, 0, (65535.0f * s) * 2.0f, 0.0f, 65535.0f * s));
    EXPECT_TRUE(point_is(p, 3, 0, 1, 0.0f, 1.0f, 1.0f));
    EXPECT_TRUE(no_data(p, 3, 1, 1));
    EXPECT_TRUE(point_is(p, 3, 2, 1, (7.0f * s) * 2.0f, 7.0f * s, 7.0f * s));
}

TEST(ReferenceDepth, F32MissingByBits) {
    // m = 1, unit_mm = 1000: s = (1 * 1000) / 1000 = 1. Missing: sign set (-1.5, -0, -inf, a negative NaN),
    // exponent 0 (+0 and subnormals) or 255 (infinities and NaNs). The smallest normal 2^-126 is data.
    const std::vector<std::uint32_t> d = {
        0x7fc00000u,  // quiet NaN
        0xffc00000u,  // negative quiet NaN
        0x7f800001u,  // signalling NaN
        0x7f800000u,  // +inf
        0xff800000u,  // -inf
        0xbfc00000u,  // -1.5
        0x80000000u,  // -0
        0x00000000u,  // +0
        0x00000001u,  // smallest subnormal
        0x007fffffu,  // largest subnormal
        0x00800000u,  // 2^-126, the smallest normal
        0x40200000u,  // 2.5
    };
    const DepthInput in = depth_of(d.data(), DepthFormat::f32, 12, 1, 1.0);
    DepthPoints p = pyrseg_ref::depth_to_points(in, 1000.0);
    ASSERT_TRUE(p.ok) << p.error;
    ASSERT_EQ(p.points.size(), 36u);
    for (int u = 0; u < 10; ++u) EXPECT_TRUE(no_data(p, 12, u, 0)) << u;
    // ku[10] = 10: x = 10 * 2^-126, exact and normal. kv[0] = +0: y = +0.
    EXPECT_TRUE(point_is(p, 12, 10, 0, std::ldexp(10.0f, -126), 0.0f, from_bits(0x00800000u)));
    EXPECT_TRUE(point_is(p, 12, 11, 0, 27.5f, 0.0f, 2.5f));

    // unit_mm = 1: s = 1000. z = 2.5 * 1000 = 2500, x = 11 * 2500.
    p = pyrseg_ref::depth_to_points(in, 1.0);
    ASSERT_TRUE(p.ok) << p.error;
    for (int u = 0; u < 10; ++u) EXPECT_TRUE(no_data(p, 12, u, 0)) << u;
    EXPECT_TRUE(point_is(p, 12, 11, 0, 27500.0f, 0.0f, 2500.0f));
    EXPECT_TRUE(
        point_is(p, 12, 10, 0, (from_bits(0x00800000u) * 1000.0f) * 10.0f, 0.0f, from_bits(0x00800000u) * 1000.0f));
}

TEST(ReferenceDepth, ProductOutsideTheNormalRangeIsMissing) {
    // u16 overflow. m = 1, unit_mm = 1000 * 2^-113: s = 1000 / (1000 * 2^-113) = 2^113 exactly. fx = 2^120, cx = 0:
    // ku[u] = u * 2^-120. d = 1: z = 2^113. d = 32767: z = 32767 * 2^113 < 2^128, exact, x = 32767 * 2^-7.
    // d = 32768: z = 2^128 overflows to +inf; d = 65535 likewise: no data.
    const std::vector<std::uint16_t> d16 = {1, 32767, 32768, 65535};
    DepthInput in = depth_of(d16.data(), DepthFormat::u16, 4, 1, 1.0);
    in.fx = std::ldexp(1.0, 120);
    DepthPoints p = pyrseg_ref::depth_to_points(in, std::ldexp(1000.0, -113));
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_TRUE(point_is(p, 4, 0, 0, 0.0f, 0.0f, std::ldexp(1.0f, 113)));
    EXPECT_TRUE(point_is(p, 4, 1, 0, 255.9921875f, 0.0f, std::ldexp(32767.0f, 113)));
    EXPECT_TRUE(no_data(p, 4, 2, 0));
    EXPECT_TRUE(no_data(p, 4, 3, 0));

    // f32 underflow. m = 0.5, unit_mm = 1000: s = 0.5. d = 2^-126: z = 2^-127, exponent 0: no data (even though
    // 2^-126 itself is data and the product is exact). d = 2^-125: z = 2^-126, data. d = 1.5 * 2^-126:
    // z = 3 * 2^-128, exact but subnormal: no data. d = 1: z = 0.5, x = 0.5 * 3.
    const std::vector<float> dlow = {std::ldexp(1.0f, -126), std::ldexp(1.0f, -125), std::ldexp(1.5f, -126), 1.0f};
    in = depth_of(dlow.data(), DepthFormat::f32, 4, 1, 0.5);
    p = pyrseg_ref::depth_to_points(in, 1000.0);
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_TRUE(no_data(p, 4, 0, 0));
    EXPECT_TRUE(point_is(p, 4, 1, 0, std::ldexp(1.0f, -126), 0.0f, std::ldexp(1.0f, -126)));
    EXPECT_TRUE(no_data(p, 4, 2, 0));
    EXPECT_TRUE(point_is(p, 4, 3, 0, 1.5f, 0.0f, 0.5f));

    // f32 overflow. m = 2, unit_mm = 1000: s = 2. FLT_MAX * 2 and 2^127 * 2 overflow: no data. d = 2^126:
    // z = 2^127, data. fx = 1, cx = 0: ku[2] = 2, so x = 2^128 overflows to +inf, and the text keeps it (only z's
    // exponent decides whether a pixel has data; only an exponent 0 changes x).
    const std::vector<float> dhigh = {std::numeric_limits<float>::max(), std::ldexp(1.0f, 127), std::ldexp(1.0f, 126),
                                      1.0f};
    in = depth_of(dhigh.data(), DepthFormat::f32, 4, 1, 2.0);
    p = pyrseg_ref::depth_to_points(in, 1000.0);
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_TRUE(no_data(p, 4, 0, 0));
    EXPECT_TRUE(no_data(p, 4, 1, 0));
    EXPECT_TRUE(point_is(p, 4, 2, 0, std::numeric_limits<float>::infinity(), 0.0f, std::ldexp(1.0f, 127)));
    EXPECT_TRUE(point_is(p, 4, 3, 0, 6.0f, 0.0f, 2.0f));
}

TEST(ReferenceDepth, XIsZTimesKuInFloat) {
    // cx = 2.3, fx = 0.7, cy = 0.5, fy = 0.7: ku[u] = (float)((u - 2.3) / 0.7), kv[0] = (float)(-0.5 / 0.7); d = 1717
    // everywhere, s = 1. The bits below were worked out with float32 multiplications of those constants.
    const std::vector<std::uint16_t> d(5, 1717);
    DepthInput in = depth_of(d.data(), DepthFormat::u16, 5, 1, 0.001);
    in.cx = 2.3;
    in.fx = 0.7;
    in.cy = 0.5;
    in.fy = 0.7;
    const DepthPoints p = pyrseg_ref::depth_to_points(in, 1.0);
    ASSERT_TRUE(p.ok) << p.error;
    const std::uint32_t expected_x[5] = {0xc5b04c93u, 0xc5474b6du, 0xc437f6dcu, 0x44d6a000u, 0x45824edcu};
    const float z = 1717.0f;
    const float y = z * static_cast<float>((0.0 - 0.5) / 0.7);
    for (int u = 0; u < 5; ++u) {
        const float ku = static_cast<float>((static_cast<double>(u) - 2.3) / 0.7);
        EXPECT_EQ(bits(z * ku), expected_x[u]) << u;
        EXPECT_TRUE(point_is(p, 5, u, 0, from_bits(expected_x[u]), y, z)) << u;
    }
    // The test tells the text's x from the alternatives: per-point double (u - cx) * z / fx at u = 0, 1, 2, 4, and
    // ku computed in float arithmetic at u = 2, 3 (at u = 3 the double constant is exactly 1, the float one is not).
    for (int u : {0, 1, 2, 4}) {
        const float per_point = static_cast<float>((static_cast<double>(u) - 2.3) * 1717.0 / 0.7);
        EXPECT_NE(bits(per_point), expected_x[u]) << u;
    }
    for (int u : {2, 3}) {
        const float in_float = z * ((static_cast<float>(u) - 2.3f) / 0.7f);
        EXPECT_NE(bits(in_float), expected_x[u]) << u;
    }
}

TEST(ReferenceDepth, SubnormalXAndYBecomeSignedZeros) {
    // f32, s = 1. fx = fy = 2^100, cx = 2, cy = 0: ku = {-2^-99, -2^-100, +0, 2^-100}, kv = {+0, 2^-100}, all exact.
    const std::vector<float> d = {
        std::ldexp(1.0f, -27), std::ldexp(1.0f, -30), 1.0f, std::ldexp(1.0f, -28), std::ldexp(1.0f, -20),
        std::ldexp(1.0f, -27), std::ldexp(1.0f, -26), 1.0f};
    DepthInput in = depth_of(d.data(), DepthFormat::f32, 4, 2, 1.0);
    in.fx = std::ldexp(1.0, 100);
    in.fy = std::ldexp(1.0, 100);
    in.cx = 2.0;
    const DepthPoints p = pyrseg_ref::depth_to_points(in, 1000.0);
    ASSERT_TRUE(p.ok) << p.error;
    const float neg0 = from_bits(0x80000000u);
    // Row 0, y = z * +0 = +0. x: -2^-126 (normal, kept), -2^-130 -> -0, +0 * 1 = +0, 2^-128 -> +0.
    EXPECT_TRUE(point_is(p, 4, 0, 0, from_bits(0x80800000u), 0.0f, d[0]));
    EXPECT_TRUE(point_is(p, 4, 1, 0, neg0, 0.0f, d[1]));
    EXPECT_TRUE(point_is(p, 4, 2, 0, 0.0f, 0.0f, 1.0f));
    EXPECT_TRUE(point_is(p, 4, 3, 0, 0.0f, 0.0f, d[3]));
    // Row 1. x: -2^-119 kept, -2^-127 -> -0, +0, 2^-100. y: 2^-120 kept, 2^-127 -> +0, 2^-126 kept, 2^-100.
    EXPECT_TRUE(point_is(p, 4, 0, 1, -std::ldexp(1.0f, -119), std::ldexp(1.0f, -120), d[4]));
    EXPECT_TRUE(point_is(p, 4, 1, 1, neg0, 0.0f, d[5]));
    EXPECT_TRUE(point_is(p, 4, 2, 1, 0.0f, std::ldexp(1.0f, -126), d[6]));
    EXPECT_TRUE(point_is(p, 4, 3, 1, std::ldexp(1.0f, -100), std::ldexp(1.0f, -100), 1.0f));
}

TEST(ReferenceDepth, RowStepAnyByteCount) {
    // u16, 3 x 3, rows 7 bytes apart (odd), from an odd address; the padding bytes 0xAB would read as 43947.
    // The buffer ends right after the last row's 6 bytes. d(u, v) = 100 * (v + 1) + u + 1, s = 1, ku = u, kv = v.
    std::vector<unsigned char> buf(1 + 2 * 7 + 6, 0xAB);
    for (int v = 0; v < 3; ++v) {
        for (int u = 0; u < 3; ++u) {
            const auto value = static_cast<std::uint16_t>(100 * (v + 1) + u + 1);
            std::memcpy(buf.data() + 1 + v * 7 + 2 * u, &value, sizeof value);
        }
    }
    DepthInput in = depth_of(buf.data() + 1, DepthFormat::u16, 3, 3, 0.001);
    in.row_step_bytes = 7;
    DepthPoints p = pyrseg_ref::depth_to_points(in, 1.0);
    ASSERT_TRUE(p.ok) << p.error;
    for (int v = 0; v < 3; ++v) {
        for (int u = 0; u < 3; ++u) {
            const auto z = static_cast<float>(100 * (v + 1) + u + 1);
            EXPECT_TRUE(point_is(p, 3, u, v, z * static_cast<float>(u), z * static_cast<float>(v), z));
        }
    }
    // Fewer bytes than a row holds is rejected; exactly a row's worth is the packed layout, as is 0.
    in.row_step_bytes = 5;
    p = pyrseg_ref::depth_to_points(in, 1.0);
    EXPECT_FALSE(p.ok);
    EXPECT_EQ(p.error.rfind("row_step_bytes ", 0), 0u) << p.error;
    const std::vector<std::uint16_t> packed = {1, 2, 3, 4, 5, 6};
    for (std::size_t step : {std::size_t{0}, std::size_t{6}}) {
        DepthInput tight = depth_of(packed.data(), DepthFormat::u16, 3, 2, 0.001);
        tight.row_step_bytes = step;
        p = pyrseg_ref::depth_to_points(tight, 1.0);
        ASSERT_TRUE(p.ok) << p.error;
        EXPECT_TRUE(point_is(p, 3, 2, 1, 12.0f, 6.0f, 6.0f)) << step;
    }

    // f32, 2 x 2, rows 11 bytes apart, from an odd address.
    std::vector<unsigned char> fbuf(1 + 11 + 8, 0xAB);
    const float fd[4] = {1.5f, 2.5f, 3.5f, 4.5f};
    for (int v = 0; v < 2; ++v) {
        std::memcpy(fbuf.data() + 1 + v * 11, fd + 2 * v, 2 * sizeof(float));
    }
    in = depth_of(fbuf.data() + 1, DepthFormat::f32, 2, 2, 1.0);
    in.row_step_bytes = 11;
    p = pyrseg_ref::depth_to_points(in, 1000.0);
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_TRUE(point_is(p, 2, 0, 0, 0.0f, 0.0f, 1.5f));
    EXPECT_TRUE(point_is(p, 2, 1, 0, 2.5f, 0.0f, 2.5f));
    EXPECT_TRUE(point_is(p, 2, 0, 1, 0.0f, 3.5f, 3.5f));
    EXPECT_TRUE(point_is(p, 2, 1, 1, 4.5f, 4.5f, 4.5f));
    in.row_step_bytes = 7;
    EXPECT_FALSE(pyrseg_ref::depth_to_points(in, 1000.0).ok);
}

TEST(ReferenceDepth, RejectedParameters) {
    const std::vector<std::uint16_t> d(4, 1000);
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto base = [&] {
        DepthInput in = depth_of(d.data(), DepthFormat::u16, 2, 2, 0.001);
        in.cx = 0.5;
        in.cy = 0.5;
        return in;
    };
    auto with = [&](auto change) {
        DepthInput in = base();
        change(in);
        return in;
    };
    // Rejected by depth_to_points and by segment_depth, with a message that starts with the parameter's name.
    auto rejected_for = [&](const DepthInput& in, double unit_mm, const std::string& name) {
        const DepthPoints p = pyrseg_ref::depth_to_points(in, unit_mm);
        Params params;
        params.unit_mm = unit_mm;
        const Output o = pyrseg_ref::segment_depth(in, in.width, in.height, params);
        return !p.ok && p.points.empty() && p.error.rfind(name + " ", 0) == 0 && !o.ok &&
               o.error.rfind(name + " ", 0) == 0;
    };
    auto accepted = [&](const DepthInput& in, double unit_mm) { return pyrseg_ref::depth_to_points(in, unit_mm).ok; };
    EXPECT_TRUE(accepted(base(), 1.0));
    for (double bad : {0.0, -0.0, -0.001, nan, inf, -inf}) {
        EXPECT_TRUE(rejected_for(with([&](DepthInput& in) { in.metres_per_unit = bad; }), 1.0, "metres_per_unit"))
            << bad;
        EXPECT_TRUE(rejected_for(with([&](DepthInput& in) { in.fx = bad; }), 1.0, "fx")) << bad;
        EXPECT_TRUE(rejected_for(with([&](DepthInput& in) { in.fy = bad; }), 1.0, "fy")) << bad;
    }
    EXPECT_TRUE(rejected_for(with([](DepthInput& in) { in.fy = -525.0; }), 1.0, "fy"));
    for (double bad : {nan, inf, -inf}) {
        EXPECT_TRUE(rejected_for(with([&](DepthInput& in) { in.cx = bad; }), 1.0, "cx")) << bad;
        EXPECT_TRUE(rejected_for(with([&](DepthInput& in) { in.cy = bad; }), 1.0, "cy")) << bad;
    }
    // Any finite cx, cy is fine, negative or far outside the image.
    EXPECT_TRUE(accepted(with([](DepthInput& in) { in.cx = -1e6; }), 1.0));
    EXPECT_TRUE(accepted(with([](DepthInput& in) { in.cy = 1e300; }), 1.0));
    // The order is m, fx, fy, cx, cy, s: with several bad, the first is named.
    EXPECT_TRUE(rejected_for(with([&](DepthInput& in) {
                                 in.fx = 0.0;
                                 in.cx = nan;
                             }),
                             1.0, "fx"));

    // The scale. m = 1e-42, unit_mm = 1: s = (float)1e-39, a subnormal. m = 1e-300: s = +0. m = 1, unit_mm = 1e-36:
    // s = (float)1e39 = +inf. m = 1e306: m * 1000 = +inf in double.
    EXPECT_TRUE(rejected_for(with([](DepthInput& in) { in.metres_per_unit = 1e-42; }), 1.0, "scale"));
    EXPECT_TRUE(rejected_for(with([](DepthInput& in) { in.metres_per_unit = 1e-300; }), 1.0, "scale"));
    EXPECT_TRUE(rejected_for(with([](DepthInput& in) { in.metres_per_unit = 1.0; }), 1e-36, "scale"));
    EXPECT_TRUE(rejected_for(with([](DepthInput& in) { in.metres_per_unit = 1e306; }), 1.0, "scale"));
    // m = 2^-126, unit_mm = 1000: s = 2^-126 exactly, the smallest normal: accepted. m = (1 - 2^-30) * 2^-126: the
    // double (m * 1000) / 1000 = m is below 2^-126 but rounds to the float 2^-126, and the text tests the float s:
    // accepted. m = (1 - 2^-22) * 2^-126 is the float 2^-126 - 2^-148 exactly, a subnormal: rejected.
    EXPECT_TRUE(accepted(with([](DepthInput& in) { in.metres_per_unit = std::ldexp(1.0, -126); }), 1000.0));
    EXPECT_TRUE(accepted(
        with([](DepthInput& in) { in.metres_per_unit = std::ldexp(1.0 - std::ldexp(1.0, -30), -126); }), 1000.0));
    EXPECT_TRUE(
        rejected_for(with([](DepthInput& in) { in.metres_per_unit = std::ldexp(1.0 - std::ldexp(1.0, -22), -126); }),
                     1000.0, "scale"));
    // A valid s: z = 1000 * 2^-126 is data.
    const DepthPoints tiny =
        pyrseg_ref::depth_to_points(with([](DepthInput& in) { in.metres_per_unit = std::ldexp(1.0, -126); }), 1000.0);
    ASSERT_TRUE(tiny.ok) << tiny.error;
    EXPECT_TRUE(point_is(tiny, 2, 1, 1, std::ldexp(500.0f, -126), std::ldexp(500.0f, -126), std::ldexp(1000.0f, -126)));

    // unit_mm, the sizes and the samples pointer.
    for (double bad : {0.0, -1.0, nan, inf}) EXPECT_TRUE(rejected_for(base(), bad, "unit_mm")) << bad;
    EXPECT_FALSE(pyrseg_ref::depth_to_points(with([](DepthInput& in) { in.width = 0; }), 1.0).ok);
    EXPECT_FALSE(pyrseg_ref::depth_to_points(with([](DepthInput& in) { in.height = -1; }), 1.0).ok);
    EXPECT_FALSE(pyrseg_ref::depth_to_points(with([](DepthInput& in) { in.samples = nullptr; }), 1.0).ok);
}

TEST(ReferenceDepth, SegmentDepthIsSegmentOfThePoints) {
    // 40 x 30 u16 depth: a frontal plane at 1500 units, a box at 1200 over x 10..29, y 6..23, two missing pixels.
    const int w = 40;
    const int h = 30;
    std::vector<std::uint16_t> d;
    for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
            const bool box = u >= 10 && u <= 29 && v >= 6 && v <= 23;
            const bool hole = v == 3 && (u == 3 || u == 4);
            d.push_back(static_cast<std::uint16_t>(hole ? 0 : box ? 1200 : 1500));
        }
    }
    DepthInput in = depth_of(d.data(), DepthFormat::u16, w, h, 0.001);
    in.fx = 40.0;
    in.fy = 40.0;
    in.cx = 19.5;
    in.cy = 14.5;
    Params metres;
    metres.unit_mm = 1000.0;
    // The merge (section 5b) reads the back-projected points, and keeps the box apart from the plane behind it.
    Params merge = metres;
    merge.merge = true;
    for (const Params& params : {Params{}, robust_params(), metres, merge}) {
        SCOPED_TRACE("unit_mm " + std::to_string(params.unit_mm) +
                     (params.metric == pyrseg_ref::Metric::robust ? " robust" : " paper") +
                     (params.merge ? " merge" : ""));
        const DepthPoints p = pyrseg_ref::depth_to_points(in, params.unit_mm);
        ASSERT_TRUE(p.ok) << p.error;
        EXPECT_TRUE(no_data(p, w, 3, 3));
        const Output want = pyrseg_ref::segment(p.points.data(), nullptr, w, h, params);
        const Output got = pyrseg_ref::segment_depth(in, w, h, params);
        ASSERT_TRUE(want.ok) << want.error;
        ASSERT_TRUE(got.ok) << got.error;
        EXPECT_LABELS(got.labels, want.labels, w);
        EXPECT_LABELS(got.raw_labels, want.raw_labels, w);
        EXPECT_EQ(got.fillable, want.fillable);
        EXPECT_EQ(got.normals, want.normals);
        EXPECT_EQ(got.segment_count, want.segment_count);
        // The box and the plane are separate segments (a 300 mm step, dt = 10 mm); the holes are not labelled. (With
        // the robust metric this box is too small: its normals are skewed within R + r = 4 pixels of each edge, and
        // the pairs 4 pixels either side leave only x 18..21 fillable, which level M's 4 x 4 cells do not cover.)
        if (params.metric == pyrseg_ref::Metric::robust) continue;
        const std::uint32_t plane = got.labels[0];
        const std::uint32_t box = got.labels[static_cast<std::size_t>(15 * w + 20)];
        EXPECT_NE(plane, 0u);
        EXPECT_NE(box, 0u);
        EXPECT_NE(plane, box);
        EXPECT_EQ(got.labels[static_cast<std::size_t>(3 * w + 3)], 0u);
    }
    // Sizes that differ from the depth image's, and errors of either step.
    EXPECT_FALSE(pyrseg_ref::segment_depth(in, w + 1, h, Params{}).ok);
    EXPECT_FALSE(pyrseg_ref::segment_depth(in, w, h - 1, Params{}).ok);
    DepthInput bad = in;
    bad.fx = 0.0;
    const Output o = pyrseg_ref::segment_depth(bad, w, h, Params{});
    EXPECT_FALSE(o.ok);
    EXPECT_EQ(o.error.rfind("fx ", 0), 0u) << o.error;
    Params bad_params;
    bad_params.ct = -1.0;
    EXPECT_FALSE(pyrseg_ref::segment_depth(in, w, h, bad_params).ok);
    bad_params = Params{};
    bad_params.normal_radius = 0;
    EXPECT_FALSE(pyrseg_ref::segment_depth(in, w, h, bad_params).ok);
}

// ---------------------------------------------------------------------------------------------------------------
// The merge (docs/algorithm.md section 5b, step 6d).

// The merge on, with the tolerance these tests' numbers are worked out for (1.5 mm, whatever the default).
Params merged(Params p = Params{}) {
    p.merge = true;
    p.merge_tolerance_mm = 1.5;
    return p;
}

// A crease along the image's middle column line, in millimetres: pixel (px, py) is at x = (px - 15.5) * 2,
// y = (py - 15.5) * 2 (so pixels 15 and 16 are 1 mm either side of it) and z = z0 + sign * |x| + tilt * py. sign = +1
// is a convex ridge (the crease nearest the camera, the faces sloping away at 45 degrees), sign = -1 a concave valley.
// The given normals are the faces' unit normals turned toward the camera, (-sign, 0, -1) / sqrt 2 on the left
// (px < 16) and (sign, 0, -1) / sqrt 2 on the right, quantized to (-+sign 5793, 0, -5793) (0.70710677 * 8192 =
// 5792.62). tilt moves the rows away without changing the normals (the merge reads the normals as given).
struct Scene {
    std::vector<float> points;
    std::vector<float> normals;
};

Scene crease(float z0, float sign, float tilt = 0.0f) {
    Scene s;
    const float c = 1.0f / std::sqrt(2.0f);
    for (int py = 0; py < 32; ++py) {
        for (int px = 0; px < 32; ++px) {
            const float x = (static_cast<float>(px) - 15.5f) * 2.0f;
            const float y = (static_cast<float>(py) - 15.5f) * 2.0f;
            const float z = z0 + sign * std::fabs(x) + tilt * static_cast<float>(py);
            s.points.insert(s.points.end(), {x, y, z});
            const float side = px < 16 ? -1.0f : 1.0f;
            s.normals.insert(s.normals.end(), {sign * side * c, 0.0f, -c});
        }
    }
    return s;
}

// The crease scenes without the merge, derived as in ReferenceEndToEnd.TwoPlanesWithDepthStep: the faces meet at 90
// degrees, so columns 15 and 16 (3 of their 8 neighbours across the crease, mean cos 5/8 < cos 0.25) are edges and
// every other pixel is fillable (|dz| is 2 mm to every neighbour). Level 3 (4 x 4) has fillable columns 0 and 3,
// whose first labels are 6 and 9; no label is old (levels 1 and 2 have no fillable texel); edge labelling gives
// column 15 label 6 and column 16 label 9.
std::vector<std::uint32_t> crease_labels(std::uint32_t left, std::uint32_t right) {
    std::vector<std::uint32_t> out;
    for (int py = 0; py < 32; ++py) {
        for (int px = 0; px < 32; ++px) out.push_back(px < 16 ? left : right);
    }
    return out;
}

TEST(ReferenceMerge, ConvexRidgeBecomesOneSegment) {
    // Every row is one crossing of {6, 9}, from p = (15, y) to q = (16, y); with r = 2 the sides reach back one pixel,
    // pa = (14, y) at (-3, y, 903) and pb = (17, y) at (3, y, 903). e = 4 (2^4 >= 16 * 1 mm), so
    // D = G(pb) - G(pa) = (96, 0, 0). Both normals already face the camera (qn . F(P) < 0, P's z dominates):
    // h_a = (-5793, 0, -5793) . D = -556128 and h_b = -((5793, 0, -5793) . D) = -556128, both below
    // tol = floor(1.5 * 2^17) = 196608: 32 good crossings, none bad, 32 >= C = 16 -> {6, 9} joins and every pixel
    // takes 6.
    const Scene s = crease(900.0f, 1.0f);
    const Output off = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, Params{});
    ASSERT_TRUE(off.ok) << off.error;
    EXPECT_EQ(off.segment_count, 2u);
    EXPECT_LABELS(off.raw_labels, crease_labels(6, 9), 32);

    for (int reach : {1, 2, 3, 16}) {
        SCOPED_TRACE("merge_reach " + std::to_string(reach));
        Params p = merged();
        p.merge_reach = reach;
        const Output on = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, p);
        ASSERT_TRUE(on.ok) << on.error;
        EXPECT_EQ(on.segment_count, 1u);
        EXPECT_LABELS(on.raw_labels, crease_labels(6, 6), 32);
        EXPECT_LABELS(on.labels, crease_labels(1, 1), 32);
        EXPECT_EQ(on.fillable, off.fillable);  // the merge changes labels only
        // Section 10's statistics are of the merged labels.
        ASSERT_EQ(on.segments.size(), 1u);
        EXPECT_EQ(on.segments[0].pixel_count, 1024u);
        EXPECT_EQ(on.segments[0].label, 1u);
    }
    // The pair has 32 crossings: C = 32 joins, C = 33 does not.
    Params c32 = merged();
    c32.merge_min_crossings = 32;
    EXPECT_EQ(pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, c32).segment_count, 1u);
    Params c33 = merged();
    c33.merge_min_crossings = 33;
    const Output not_enough = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, c33);
    EXPECT_EQ(not_enough.segment_count, 2u);
    EXPECT_LABELS(not_enough.raw_labels, crease_labels(6, 9), 32);

    // Normals given facing away from the camera are turned toward it (qn . F(P) > 0 -> -qn) before h is computed:
    // negating every normal changes neither the metric (its dot products are the same) nor the merge.
    Scene away = s;
    for (float& v : away.normals) v = -v;
    const Output flipped = pyrseg_ref::segment(away.points.data(), away.normals.data(), 32, 32, merged());
    ASSERT_TRUE(flipped.ok) << flipped.error;
    EXPECT_LABELS(flipped.raw_labels, crease_labels(6, 6), 32);

    // Estimated normals (section 8, and the robust ones of section 8b with edge rounds that close the robust
    // metric's wide edge band, without which the two segments do not touch): two segments without the merge, one
    // with it.
    Params robust = robust_params();
    robust.normal_radius = 2;
    robust.edge_rounds = 10;
    for (const Params& base : {Params{}, robust}) {
        SCOPED_TRACE(base.metric == pyrseg_ref::Metric::robust ? "robust, estimated" : "paper, estimated");
        const Output est_off = pyrseg_ref::segment(s.points.data(), nullptr, 32, 32, base);
        const Output est_on = pyrseg_ref::segment(s.points.data(), nullptr, 32, 32, merged(base));
        ASSERT_TRUE(est_off.ok) << est_off.error;
        ASSERT_TRUE(est_on.ok) << est_on.error;
        EXPECT_EQ(est_off.segment_count, 2u);
        EXPECT_EQ(est_on.segment_count, 1u);
    }
}

TEST(ReferenceMerge, ConcaveValleyStaysTwoSegments) {
    // The ridge turned inside out: pa = (14, y) at (-3, y, 927), pb = (17, y) at (3, y, 927), D = (96, 0, 0) again,
    // but the normals are (5793, 0, -5793) and (-5793, 0, -5793): h_a = h_b = 5793 * 96 = 556128 (each side 4.24 mm
    // in front of the other's tangent plane) > 196608: 32 bad crossings, no join.
    const Scene s = crease(930.0f, -1.0f);
    const Output off = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, Params{});
    const Output on = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, merged());
    ASSERT_TRUE(off.ok) << off.error;
    ASSERT_TRUE(on.ok) << on.error;
    EXPECT_EQ(off.segment_count, 2u);
    EXPECT_LABELS(off.raw_labels, crease_labels(6, 9), 32);
    EXPECT_EQ(on.segment_count, 2u);
    EXPECT_LABELS(on.raw_labels, crease_labels(6, 9), 32);

    // The tolerance is inclusive: T0 = 556128 (t0 = 556128 / 2^17 mm, exact) joins, one unit less does not.
    Params at = merged();
    at.merge_tolerance_mm = 556128.0 / 131072.0;
    EXPECT_EQ(pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, at).segment_count, 1u);
    Params below = merged();
    below.merge_tolerance_mm = 556127.0 / 131072.0;
    EXPECT_EQ(pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, below).segment_count, 2u);

    // With r = 1 the sides do not reach back: pa = (15, y), pb = (16, y), D = (32, 0, 0), h = 5793 * 32 = 185376
    // <= 196608 (each side 1.41 mm in front of the other), so a crease this sharp joins at reach 1; at reach 3,
    // D = (160, 0, 0) and h = 926880: no join.
    Params r1 = merged();
    r1.merge_reach = 1;
    const Output near = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, r1);
    EXPECT_EQ(near.segment_count, 1u);
    EXPECT_LABELS(near.raw_labels, crease_labels(6, 6), 32);
    Params r3 = merged();
    r3.merge_reach = 3;
    EXPECT_EQ(pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, r3).segment_count, 2u);

    // Normals facing away from the camera: turned toward it, so still no join.
    Scene away = s;
    for (float& v : away.normals) v = -v;
    const Output flipped = pyrseg_ref::segment(away.points.data(), away.normals.data(), 32, 32, merged());
    ASSERT_TRUE(flipped.ok) << flipped.error;
    EXPECT_LABELS(flipped.raw_labels, crease_labels(6, 9), 32);

    // Estimated normals: two segments either way.
    Params robust = robust_params();
    robust.normal_radius = 2;
    robust.edge_rounds = 10;
    for (const Params& base : {Params{}, robust}) {
        SCOPED_TRACE(base.metric == pyrseg_ref::Metric::robust ? "robust, estimated" : "paper, estimated");
        const Output est_off = pyrseg_ref::segment(s.points.data(), nullptr, 32, 32, base);
        const Output est_on = pyrseg_ref::segment(s.points.data(), nullptr, 32, 32, merged(base));
        ASSERT_TRUE(est_off.ok) << est_off.error;
        ASSERT_TRUE(est_on.ok) << est_on.error;
        EXPECT_EQ(est_off.segment_count, 2u);
        EXPECT_EQ(est_on.segment_count, 2u);
        EXPECT_EQ(est_on.raw_labels, est_off.raw_labels);
    }
}

TEST(ReferenceMerge, EachSideReachesBackOnItsOwnSide) {
    // A 45 degree concave crease between a sloping face and a frontal one, x as in crease(). Slope on the left:
    // z = 930 + min(x, 0), normals (1, 0, -1) / sqrt 2 (qn (5793, 0, -5793)) for x < 0 and (0, 0, -1) (qn
    // (0, 0, -8192)) for x > 0. Columns 15 and 16 are edges (mean cos (5 + 3 * 0.707) / 8 = 0.89 < cos 0.25), the
    // labels those of crease_labels(6, 9). Each row's crossing, with r = 2: pa = (14, y) at x = -3, z = 927 and
    // pb = (17, y) at x = 3, z = 930, D = (96, 0, 48): h_a = 5793 * (96 - 48) = 278064 (pb 2.1 mm in front of the
    // slope's plane) and h_b = 8192 * 48 = 393216 (pa 3 mm in front of the frontal plane). With r = 1, pa = (15, y)
    // at x = -1, z = 929 and pb = (16, y) at x = 1, z = 930: D = (32, 0, 16), h_a = 5793 * 16 = 92688,
    // h_b = 8192 * 16 = 131072. With T0 = 300000 (t0 = 300000 / 2^17 mm, exact) reach 1 joins, reach 2 does not; a
    // reach that stopped at p on the a side would give h_b = 131072 and join. The mirror image (slope on the right,
    // z = 930 - max(x, 0), qn (-5793, 0, -5793)) swaps the two h, and so tests the b side's reach.
    const float c = 1.0f / std::sqrt(2.0f);
    for (const bool slope_left : {true, false}) {
        SCOPED_TRACE(slope_left ? "slope on the left" : "slope on the right");
        std::vector<float> pts;
        std::vector<float> nrm;
        for (int py = 0; py < 32; ++py) {
            for (int px = 0; px < 32; ++px) {
                const float x = (static_cast<float>(px) - 15.5f) * 2.0f;
                const float y = (static_cast<float>(py) - 15.5f) * 2.0f;
                const bool sloped = slope_left ? x < 0.0f : x > 0.0f;
                const float z = 930.0f - (sloped ? std::fabs(x) : 0.0f);
                pts.insert(pts.end(), {x, y, z});
                if (sloped) {
                    nrm.insert(nrm.end(), {slope_left ? c : -c, 0.0f, -c});
                } else {
                    nrm.insert(nrm.end(), {0.0f, 0.0f, -1.0f});
                }
            }
        }
        Params p = merged();
        p.merge_tolerance_mm = 300000.0 / 131072.0;
        const Output off = pyrseg_ref::segment(pts.data(), nrm.data(), 32, 32, Params{});
        ASSERT_TRUE(off.ok) << off.error;
        EXPECT_LABELS(off.raw_labels, crease_labels(6, 9), 32);
        p.merge_reach = 2;
        const Output r2 = pyrseg_ref::segment(pts.data(), nrm.data(), 32, 32, p);
        EXPECT_LABELS(r2.raw_labels, crease_labels(6, 9), 32);
        p.merge_reach = 1;
        const Output r1 = pyrseg_ref::segment(pts.data(), nrm.data(), 32, 32, p);
        EXPECT_LABELS(r1.raw_labels, crease_labels(6, 6), 32);
        // At reach 2 the larger h is 393216: the tolerance just at it joins.
        p.merge_reach = 2;
        p.merge_tolerance_mm = 393216.0 / 131072.0;
        EXPECT_EQ(pyrseg_ref::segment(pts.data(), nrm.data(), 32, 32, p).segment_count, 1u);
    }
}

TEST(ReferenceMerge, BadShareIsComparedWithRintOfFTimes256) {
    // The valley with rows moving 2 mm away per row (depth differences to every neighbour stay <= 4 mm, so the
    // segmentation is as before) and the tolerance growing with depth only: t0 = 0, t2 = 4.905 mm / m^2, so
    // T2 = (float)(4.905e-6 * 2^17) = 0.642908 and row y's crossing (pa, pb at z = 927 + 2y, D = (96, 0, 0) and
    // h = 556128 as before) has tol = floor(T2 * z^2): 554856 for y = 1 (z^2 = 863041) and 557247 for y = 2
    // (z^2 = 866761). So rows 0 and 1 are bad, rows 2..31 good: g = 30, n_bad = 2, 512 <= S * 32 iff S >= 16.
    const Scene s = crease(930.0f, -1.0f, 2.0f);
    Params base = merged();
    base.merge_tolerance_mm = 0.0;
    base.merge_tolerance_per_m2 = 4.905;
    const auto count_with = [&](double share, int min_crossings) {
        Params p = base;
        p.merge_max_bad_share = share;
        p.merge_min_crossings = min_crossings;
        const Output o = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, p);
        EXPECT_TRUE(o.ok) << o.error;
        return o.segment_count;
    };
    Params off = base;
    off.merge = false;
    const Output unmerged = pyrseg_ref::segment(s.points.data(), s.normals.data(), 32, 32, off);
    EXPECT_EQ(unmerged.segment_count, 2u);
    EXPECT_LABELS(unmerged.raw_labels, crease_labels(6, 9), 32);
    EXPECT_EQ(count_with(0.0625, 16), 1u);  // S = 16: 512 <= 512, inclusive
    EXPECT_EQ(count_with(0.061, 16), 1u);   // S = rint(15.616) = 16, although 0.061 < 2 / 32
    EXPECT_EQ(count_with(0.06, 16), 2u);    // S = rint(15.36) = 15
    EXPECT_EQ(count_with(0.05, 16), 2u);    // the default, S = 13
    EXPECT_EQ(count_with(0.0, 16), 2u);
    // Bad crossings count toward C: 32 crossings in all.
    EXPECT_EQ(count_with(1.0, 32), 1u);
    EXPECT_EQ(count_with(1.0, 33), 2u);
    // Without the growth every crossing is bad; f = 1 (S = 256) still joins them, f just below 1 does not.
    base.merge_tolerance_per_m2 = 0.0;
    EXPECT_EQ(count_with(1.0, 16), 1u);
    EXPECT_EQ(count_with(0.99, 16), 2u);
}

TEST(ReferenceMerge, BoxStandingOnAPlaneStaysApartFromIt) {
    // 64 x 64, 2 mm pixels, x = (px - 32) * 2, y = (py - 32) * 2. A floor at z = 1000 (normal (0, 0, -1)) with a box
    // on it over rows 16..47: its top at z = 950 over columns 12..35 (a 50 mm depth step to the floor at column
    // 11/12 and at rows 15/16 and 47/48), then its side sloping away from the top's edge, z = 950 + 2 (x - 6), normal
    // (2, 0, -1) / sqrt 5, over columns 36..47 (z 950..998), which meets the floor at column 48 in a concave crease.
    // Without the merge: floor, top and side are three segments (raw labels 22, 48 and 176: the first labels of level
    // 4's texels (0, 0) and (2, 3) and of level 5's texel (10, 5)). With it, top and side (a convex crease) join and
    // take 48; the floor meets the top at a depth step and the side at a concave crease, where every crossing is bad
    // (the nearer side lies far in front of the farther one's tangent plane), and keeps 22.
    const int w = 64;
    const int h = 64;
    const float s5 = 1.0f / std::sqrt(5.0f);
    std::vector<float> pts;
    std::vector<float> nrm;
    for (int py = 0; py < h; ++py) {
        for (int px = 0; px < w; ++px) {
            const float x = static_cast<float>(px - 32) * 2.0f;
            const float y = static_cast<float>(py - 32) * 2.0f;
            const bool box_rows = py >= 16 && py < 48;
            float z = 1000.0f;
            std::vector<float> n = {0.0f, 0.0f, -1.0f};
            if (box_rows && px >= 12 && px < 36) {
                z = 950.0f;
            } else if (box_rows && px >= 36 && px < 48) {
                z = 950.0f + 2.0f * (x - 6.0f);
                n = {2.0f * s5, 0.0f, -s5};
            }
            pts.insert(pts.end(), {x, y, z});
            nrm.insert(nrm.end(), n.begin(), n.end());
        }
    }
    const auto at = [&](const Output& o, int px, int py) {
        return o.raw_labels[static_cast<std::size_t>(py * w + px)];
    };
    const Output off = pyrseg_ref::segment(pts.data(), nrm.data(), w, h, Params{});
    const Output on = pyrseg_ref::segment(pts.data(), nrm.data(), w, h, merged());
    ASSERT_TRUE(off.ok) << off.error;
    ASSERT_TRUE(on.ok) << on.error;
    EXPECT_EQ(off.segment_count, 3u);
    EXPECT_EQ(at(off, 0, 0), 22u);     // floor
    EXPECT_EQ(at(off, 20, 30), 48u);   // top
    EXPECT_EQ(at(off, 42, 30), 176u);  // side
    EXPECT_EQ(on.segment_count, 2u);
    EXPECT_EQ(at(on, 0, 0), 22u);
    EXPECT_EQ(at(on, 20, 30), 48u);
    EXPECT_EQ(at(on, 42, 30), 48u);
    // Every pixel: the floor's label where it was, the box's two faces now one.
    for (std::size_t i = 0; i < off.raw_labels.size(); ++i) {
        const std::uint32_t was = off.raw_labels[i];
        EXPECT_EQ(on.raw_labels[i], was == 176u ? 48u : was) << "pixel " << i;
    }
    // Whatever share of bad crossings is allowed short of all of them, the floor stays apart: it has no good one.
    Params lax = merged();
    lax.merge_max_bad_share = 0.99;
    lax.merge_min_crossings = 1;
    EXPECT_EQ(pyrseg_ref::segment(pts.data(), nrm.data(), w, h, lax).segment_count, 2u);
}

TEST(ReferenceMerge, DifferenceBeyondTwoToTheSixteenIsBad) {
    // Two frontal planes (normal (0, 0, -1)), x < 8 at z = 1000 and x >= 8 at z = 1000 + 4096 (D_z = 4096 * 16 = 2^16)
    // or 1000 + 4096.0625 (D_z = 2^16 + 1). The tolerance is huge (t0 = 10^6 mm: T0 = 1.3e11 >= 2^30, tol = 2^30),
    // so h_b = 8192 * 2^16 = 2^29 passes and only |D_c| > 2^16 can make the crossings bad.
    Params p = merged();
    p.merge_tolerance_mm = 1e6;
    for (const float far : {5096.0f, 5096.0625f}) {
        const std::vector<float> pts = grid_points(16, 16, [far](int x, int) { return x < 8 ? 1000.0f : far; });
        const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
        const Output off = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, Params{});
        const Output on = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
        ASSERT_TRUE(off.ok) << off.error;
        ASSERT_TRUE(on.ok) << on.error;
        EXPECT_EQ(off.segment_count, 2u);
        EXPECT_EQ(on.segment_count, far == 5096.0f ? 1u : 2u) << far;
    }
}

TEST(ReferenceMerge, GroupsJoinTransitivelyAndTakeTheirSmallestLabel) {
    // A flat top between two 45 degree slopes (a prism seen from its ridge side), x as in crease(): z = 900 +
    // max(0, |x| - 10), normals (0, 0, -1) on the top (|x| < 10) and (-+1, 0, -1) / sqrt 2 on the slopes. Columns 10,
    // 11, 20 and 21 are edges (3 of 8 neighbours at 45 degrees: mean cos 0.89 < cos 0.25). Without the merge: the
    // slopes take level 3's labels 6 and 9 (texels 0 and 3), the top level 4's label 25 (texel (3, 0), columns 12..15;
    // level 3's texels 1 and 2 contain edge columns). Both creases are convex, so {6, 25} and {9, 25} join; 6 and 9
    // never touch, yet all three are one group and take its smallest label, 6.
    std::vector<float> pts;
    std::vector<float> nrm;
    const float c = 1.0f / std::sqrt(2.0f);
    std::vector<std::uint32_t> unmerged;
    for (int py = 0; py < 32; ++py) {
        for (int px = 0; px < 32; ++px) {
            const float x = (static_cast<float>(px) - 15.5f) * 2.0f;
            const float y = (static_cast<float>(py) - 15.5f) * 2.0f;
            const float ax = std::fabs(x);
            pts.insert(pts.end(), {x, y, 900.0f + std::max(0.0f, ax - 10.0f)});
            if (ax < 10.0f) {
                nrm.insert(nrm.end(), {0.0f, 0.0f, -1.0f});
            } else {
                nrm.insert(nrm.end(), {x < 0.0f ? -c : c, 0.0f, -c});
            }
            unmerged.push_back(px <= 10 ? 6u : px <= 20 ? 25u : 9u);
        }
    }
    const Output off = pyrseg_ref::segment(pts.data(), nrm.data(), 32, 32, Params{});
    const Output on = pyrseg_ref::segment(pts.data(), nrm.data(), 32, 32, merged());
    ASSERT_TRUE(off.ok) << off.error;
    ASSERT_TRUE(on.ok) << on.error;
    EXPECT_EQ(off.segment_count, 3u);
    EXPECT_LABELS(off.raw_labels, unmerged, 32);
    EXPECT_EQ(on.segment_count, 1u);
    EXPECT_LABELS(on.raw_labels, (std::vector<std::uint32_t>(1024, 6u)), 32);
}

TEST(ReferenceMerge, ParameterErrors) {
    const std::vector<std::uint8_t> mask(256, 1);
    const std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto with = [](Params p, auto change) {
        change(p);
        return p;
    };
    // Out of range: rejected by every entry point, merge on or off, with a message naming the parameter.
    const auto rejected_for = [&](Params p, const std::string& name) {
        for (bool merge : {false, true}) {
            p.merge = merge;
            const Output a = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
            const Output b = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p);
            const Output c = pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p);
            for (const Output* o : {&a, &b, &c}) {
                if (o->ok || o->error.find(name) == std::string::npos) return false;
            }
        }
        return true;
    };
    const auto accepted = [&](const Params& p) {
        return pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p).ok &&
               pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p).ok;
    };
    const Params on = merged();
    EXPECT_TRUE(accepted(on));
    EXPECT_TRUE(rejected_for(with(on, [](Params& p) { p.merge_reach = 0; }), "merge_reach"));
    EXPECT_TRUE(rejected_for(with(on, [](Params& p) { p.merge_reach = 17; }), "merge_reach"));
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_reach = 1; })));
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_reach = 16; })));
    for (double bad : {-1.0, nan, inf, -inf}) {
        EXPECT_TRUE(rejected_for(with(on, [&](Params& p) { p.merge_tolerance_mm = bad; }), "merge_tolerance_mm"))
            << bad;
        EXPECT_TRUE(
            rejected_for(with(on, [&](Params& p) { p.merge_tolerance_per_m2 = bad; }), "merge_tolerance_per_m2"))
            << bad;
    }
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_tolerance_mm = 0.0; })));
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_tolerance_per_m2 = 1e6; })));
    EXPECT_TRUE(rejected_for(with(on, [](Params& p) { p.merge_min_crossings = 0; }), "merge_min_crossings"));
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_min_crossings = 1; })));
    for (double bad : {-0.01, 1.01, nan, inf}) {
        EXPECT_TRUE(rejected_for(with(on, [&](Params& p) { p.merge_max_bad_share = bad; }), "merge_max_bad_share"))
            << bad;
    }
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_max_bad_share = 0.0; })));
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_max_bad_share = 1.0; })));
    // T0 = (float)(t0 * 2^17) and T2 = (float)((t2 * 1e-6) * 2^17) in millimetres must be finite float32s (the
    // largest is 3.4028e38): t0 = 2e33 gives 2.6e38, 3e33 gives 3.9e38.
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_tolerance_mm = 2e33; })));
    EXPECT_TRUE(rejected_for(with(on, [](Params& p) { p.merge_tolerance_mm = 3e33; }), "merge_tolerance_mm"));
    EXPECT_TRUE(accepted(with(on, [](Params& p) { p.merge_tolerance_per_m2 = 2e39; })));
    EXPECT_TRUE(rejected_for(with(on, [](Params& p) { p.merge_tolerance_per_m2 = 3e39; }), "merge_tolerance_per_m2"));
    // In metres (unit_mm = 1000, e = 14, u = 2^27): T0 = (t0 / 1000) * 2^27, T2 = (t2 * 1e-6 * 1000) * 2^27.
    Params metres = on;
    metres.unit_mm = 1000.0;
    // (t0 = 2e33 and 3e33 give 2.7e38 and 4.0e38; t2 = 2e33 and 3e33 likewise.)
    EXPECT_TRUE(accepted(with(metres, [](Params& p) { p.merge_tolerance_mm = 2e33; })));
    EXPECT_TRUE(rejected_for(with(metres, [](Params& p) { p.merge_tolerance_mm = 3e33; }), "merge_tolerance_mm"));
    EXPECT_TRUE(accepted(with(metres, [](Params& p) { p.merge_tolerance_per_m2 = 2e33; })));
    EXPECT_TRUE(
        rejected_for(with(metres, [](Params& p) { p.merge_tolerance_per_m2 = 3e33; }), "merge_tolerance_per_m2"));
    // Merge on is accepted for the small-image fallback (8 x 8), where it does not run. (It would have nothing to
    // do there anyway: the fallback's labels are the components of B, so no two different labels are 4-adjacent.)
    EXPECT_TRUE(pyrseg_ref::segment(pts.data(), nrm.data(), 8, 8, on).ok);

    // A mask has no points or normals to merge with: refused with merge on, whatever the image size.
    const Output refused = pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, on);
    EXPECT_FALSE(refused.ok);
    EXPECT_NE(refused.error.find("merge"), std::string::npos) << refused.error;
    EXPECT_FALSE(pyrseg_ref::segment_mask(mask.data(), nullptr, 4, 4, on).ok);
    EXPECT_TRUE(pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, Params{}).ok);
}

// ---------------------------------------------------------------------------------------------------------------
// The colour edge term's curvature gate (docs/algorithm.md section 2c). G = rint(g * 256), round half to even. With
// G > 0 a colour edge pixel counts (B cleared) iff kp >= 1 and S < kp * (2^26 - Lg), Lg = (L >> 8) * G +
// (((L & 255) * G) >> 8) = floor(L * G / 256), with L, S and kp those of section 2b's curvature test.
// ct = 0.25 (the default): L = 2086252 = 8149 * 256 + 108 while Bc = 0, so Lg = 8149 * G + ((108 * G) >> 8):
//   G = 2: 16298, G = 3: 24448, G = 64: 521563, G = 128: 1043126, G = 192: 1564689, G = 256: 2086252 = L.
//
// The scenes: 13 x 7, robust metric at curvature_stride 2, colour (200, 40, 40) for x <= 6 and (40, 160, 40) for
// x >= 7 (D = 160 + 120 = 280 > T = 100), colour_edge_stride 1: the colour edges are the pixels of columns 6 (c(5)
// vs c(7)) and 7 (c(6) vs c(8)), every row, and no others (no vertical ones). A pixel has a horizontal pair iff
// 2 <= x <= 10, a vertical one iff 2 <= y <= 4, diagonal ones only when it has both.

Params gate_params(double g) {
    Params p = robust_params();
    p.curvature_stride = 2;
    p.color_edge_threshold = 100;
    p.color_edge_stride = 1;
    p.color_edge_curvature_share = g;
    return p;
}

// R, G, B per pixel: `left` for x <= last_left, `right` for the others, every row.
std::vector<std::uint8_t> split_colors(int w, int h, int last_left, const std::vector<std::uint8_t>& left,
                                       const std::vector<std::uint8_t>& right) {
    std::vector<std::uint8_t> c;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::vector<std::uint8_t>& rgb = x <= last_left ? left : right;
            c.insert(c.end(), rgb.begin(), rgb.end());
        }
    }
    return c;
}

const std::vector<std::uint8_t> kRed = {200, 40, 40};
const std::vector<std::uint8_t> kGreen = {40, 160, 40};

// The fillable mask of segment() with the colour image; normals empty: estimated.
std::vector<std::uint8_t> gated(const std::vector<float>& pts, const std::vector<float>& normals, int w, int h,
                                const std::vector<std::uint8_t>& color, const Params& p) {
    Output out = pyrseg_ref::segment(pts.data(), normals.empty() ? nullptr : normals.data(), w, h, p, color.data());
    EXPECT_TRUE(out.ok) << out.error;
    return out.fillable;
}

// The 13 x 7 gate scenes' fillable mask (the robust metric at stride 2 keeps the corners out), and the same mask with
// the colour edge's columns 6 and 7 cleared.
std::vector<std::uint8_t> gate_scene_mask() {
    return mask_of({
        "..#########..",  //
        "..#########..",  //
        "#############",  //
        "#############",  //
        "#############",  //
        "..#########..",  //
        "..#########..",  //
    });
}

std::vector<std::uint8_t> gate_scene_mask_cut() {
    return mask_of({
        "..####..###..",  //
        "..####..###..",  //
        "######..#####",  //
        "######..#####",  //
        "######..#####",  //
        "..####..###..",  //
        "..####..###..",  //
    });
}

TEST(ReferenceColorGate, FlatTexturedPlaneKeepsItsColourEdgesFillable) {
    // z = 1000, every normal frontal: every pair has S = 2^26 per pair, so every pixel with a pair is fillable (the
    // plus below), and S = kp * 2^26 >= kp * (2^26 - Lg) for any Lg >= 0: with G > 0 no colour edge counts.
    // G = 0 (g = 0, or g = 0.5 / 256, which rounds half to even to 0) clears columns 6 and 7; g = 1.5 / 256 rounds
    // to G = 2 (Lg = 16298): nothing cleared, like g = 0.25 and g = 1. (Rounding half up would give G = 1 for
    // 0.5 / 256, a gate, and keep the columns.)
    const int w = 13;
    const int h = 7;
    const std::vector<float> pts = grid_points(w, h, [](int, int) { return 1000.0f; });
    const std::vector<float> front = constant_normals(w * h, 0.0f, 0.0f, -1.0f);
    const std::vector<std::uint8_t> color = split_colors(w, h, 6, kRed, kGreen);
    const std::vector<std::uint8_t> plus = gate_scene_mask();
    const std::vector<std::uint8_t> cut = gate_scene_mask_cut();
    // Without a colour image, or with T = 765: the metric's mask.
    Output plain = pyrseg_ref::segment(pts.data(), front.data(), w, h, gate_params(0.0));
    ASSERT_TRUE(plain.ok) << plain.error;
    EXPECT_EQ(plain.fillable, plus);
    Params t765 = gate_params(0.0);
    t765.color_edge_threshold = 765;
    EXPECT_EQ(gated(pts, front, w, h, color, t765), plus);

    EXPECT_EQ(gated(pts, front, w, h, color, gate_params(0.0)), cut);
    EXPECT_EQ(gated(pts, front, w, h, color, gate_params(0.5 / 256.0)), cut);
    EXPECT_EQ(gated(pts, front, w, h, color, gate_params(1.5 / 256.0)), plus);
    EXPECT_EQ(gated(pts, front, w, h, color, gate_params(0.25)), plus);
    EXPECT_EQ(gated(pts, front, w, h, color, gate_params(1.0)), plus);

    // The same with the normals estimated (section 8b): on the flat grid every one is (0, 0, -8192), so the gate
    // reads the same pairs from the normals the metric used.
    Output estimated = pyrseg_ref::segment(pts.data(), nullptr, w, h, gate_params(0.25), color.data());
    ASSERT_TRUE(estimated.ok) << estimated.error;
    EXPECT_EQ(estimated.normals, front);
    EXPECT_EQ(estimated.fillable, plus);
    EXPECT_EQ(gated(pts, {}, w, h, color, gate_params(0.0)), cut);
}

TEST(ReferenceColorGate, WeakCreaseWithAColourChangeIsCut) {
    // Two planes meeting at column 6 at a shallow angle (each tilted by 1/8, z = 1000 + |x - 6| / 8): normals
    // nL = (-1016, 0, -8129) for x <= 5, frontal (0, 0, -8192) at x = 6, nR = (1016, 0, -8129) for x >= 7 (given).
    // Pair dot products: nL.nL = nR.nR = 67112897, nL.nC = nR.nC = 66592768, nL.nR = 8129^2 - 1016^2 = 65048385,
    // each >= 2^26 - L = 65022612: the metric keeps every pixel with a pair (the plus of the flat scene), the crease
    // too (1 - cos across it is 2060479 / 2^26 = 0.0307 at most, below ct's 1 - cos(0.25) = 0.0311). d <= 1/8.
    // The colour edge pixels, columns 6 and 7, straddle the crease (their pairs at stride 2 reach x = 4..9):
    //   rows 0, 1, 5, 6: only the horizontal pair, nR.nL: kp = 1, S = 65048385; counts iff Lg < 2060479.
    //   rows 2..4, column 6: 3 * nR.nL + nC.nC = 262254019, kp = 4; counts iff 4 * Lg < 2^28 - S = 6181437.
    //   rows 2..4, column 7: 3 * nR.nL + nR.nR = 262258052, kp = 4; counts iff 4 * Lg < 6177404.
    // G = 64 (Lg = 521563) and G = 128 (1043126): every one counts. G = 192 (1564689): rows 0, 1, 5, 6 only (a gate
    // that looked at stride 1 would see kp = 4 and S = 262254019 or 262258052 in rows 1 and 5 too, and keep them).
    // G = 256 (Lg = L): none (they passed the metric's test with L).
    const int w = 13;
    const int h = 7;
    const std::vector<float> pts =
        grid_points(w, h, [](int x, int) { return 1000.0f + static_cast<float>(x > 6 ? x - 6 : 6 - x) / 8.0f; });
    std::vector<float> nrm;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::vector<float> n =
                x < 6 ? q13(-1016, 0, -8129) : (x == 6 ? q13(0, 0, -8192) : q13(1016, 0, -8129));
            nrm.insert(nrm.end(), n.begin(), n.end());
        }
    }
    const std::vector<std::uint8_t> color = split_colors(w, h, 6, kRed, kGreen);
    const std::vector<std::uint8_t> plus = gate_scene_mask();
    const std::vector<std::uint8_t> cut = gate_scene_mask_cut();
    const std::vector<std::uint8_t> outer_rows_cut = mask_of({
        "..####..###..",  //
        "..####..###..",  //
        "#############",  //
        "#############",  //
        "#############",  //
        "..####..###..",  //
        "..####..###..",  //
    });
    Output plain = pyrseg_ref::segment(pts.data(), nrm.data(), w, h, gate_params(0.0));
    ASSERT_TRUE(plain.ok) << plain.error;
    EXPECT_EQ(plain.fillable, plus);  // the crease is too weak for the metric

    EXPECT_EQ(gated(pts, nrm, w, h, color, gate_params(0.0)), cut);
    EXPECT_EQ(gated(pts, nrm, w, h, color, gate_params(0.25)), cut);
    EXPECT_EQ(gated(pts, nrm, w, h, color, gate_params(0.5)), cut);
    EXPECT_EQ(gated(pts, nrm, w, h, color, gate_params(0.75)), outer_rows_cut);
    EXPECT_EQ(gated(pts, nrm, w, h, color, gate_params(1.0)), plus);
}

// A W x 1 row at curvature_stride 1 with colour (0, 0, 0) but for the last pixel, (255, 255, 255): in a 3 x 1 row
// pixel 1 is the only colour edge (D(c(0), c(2)) = 765 > T = 100) and the only pixel with a pair (0 and 2, kp = 1):
// it is fillable iff S = qn_0 . qn_2 >= 2^26 - L, and then cleared iff S < 2^26 - Lg. Its own normal takes no part.
std::vector<std::uint8_t> gated_row(const std::vector<float>& z, const std::vector<std::vector<float>>& normals,
                                    Params p) {
    p.metric = pyrseg_ref::Metric::robust;
    p.curvature_stride = 1;
    p.color_edge_threshold = 100;
    p.color_edge_stride = 1;
    const int w = static_cast<int>(z.size());
    const std::vector<float> pts = grid_points(w, 1, [&](int x, int) { return z[static_cast<std::size_t>(x)]; });
    std::vector<float> nrm;
    for (const std::vector<float>& n : normals) nrm.insert(nrm.end(), n.begin(), n.end());
    return gated(pts, nrm, w, 1, split_colors(w, 1, w - 2, {0, 0, 0}, {255, 255, 255}), p);
}

TEST(ReferenceColorGate, LimitIsFloorOfLTimesGOver256AndTheTestIsStrict) {
    // qn_0 = (1, 0, -8192) and qn_2 = (c, 0, -d): S = c + 8192 d.
    const std::vector<float> z(3, 1000.0f);
    const std::vector<float> tilted = q13(1, 0, -8192);
    const std::vector<std::uint8_t> kept = {0, 1, 0};
    const std::vector<std::uint8_t> cleared = {0, 0, 0};
    Params p;
    p.color_edge_curvature_share = 0.25;  // G = 64, Lg = 521563, 2^26 - Lg = 66587301
    // S = 2724 + 8192 * 8128 = 66587300 counts; 66587301 does not. (Lg without the low byte's share, 521536, would
    // clear both; Lg rounded up, 521564, would clear neither.)
    EXPECT_EQ(gated_row(z, {tilted, kFront, q13(2724, 0, -8128)}, p), cleared);
    EXPECT_EQ(gated_row(z, {tilted, kFront, q13(2725, 0, -8128)}, p), kept);
    // g = 2.5 / 256 rounds half to even to G = 2: Lg = 16298, 2^26 - Lg = 67092566. S = 85 + 8192 * 8190 =
    // 67092565 counts, 67092566 does not. (G = 3, Lg = 24448, would count neither.)
    p.color_edge_curvature_share = 2.5 / 256.0;
    EXPECT_EQ(gated_row(z, {tilted, kFront, q13(85, 0, -8190)}, p), cleared);
    EXPECT_EQ(gated_row(z, {tilted, kFront, q13(86, 0, -8190)}, p), kept);
    p.color_edge_curvature_share = 3.0 / 256.0;
    EXPECT_EQ(gated_row(z, {tilted, kFront, q13(85, 0, -8190)}, p), kept);

    // L from the pixel's own depth (section 2b's growth): ct_growth_per_m2 = 0.01 gives L = 2274014 = 8882 * 256 +
    // 222 at z = 3000 and L = 2091467 = 8169 * 256 + 203 at z = 500 (see CurvatureGrowthMakesANoisyFarSurfaceFillable).
    // G = 128: Lg = 1137007 (2^26 - Lg = 65971857) at 3000, 1045733 (66063131) at 500; without the growth 1043126
    // (66065738). S = kFront . (0, 0, -8060) = 66027520 (fillable in every case: >= 2^26 - 2086252) counts at 500 and
    // without the growth, not at 3000.
    const std::vector<std::vector<float>> weak = {kFront, kFront, q13(0, 0, -8060)};
    p.color_edge_curvature_share = 0.5;
    EXPECT_EQ(gated_row(std::vector<float>(3, 3000.0f), weak, p), cleared);
    p.ct_growth_per_m2 = 0.01;
    EXPECT_EQ(gated_row(std::vector<float>(3, 3000.0f), weak, p), kept);
    EXPECT_EQ(gated_row(std::vector<float>(3, 500.0f), weak, p), cleared);
    p.ct_growth_per_m2 = 0.0;

    // ct >= pi: L = 2^28, and every pair passes the metric, even opposed ones: (1, 1, 1) . (-1, -1, -1) gives
    // S = -3 * 2^26 = -201326592 = 2^26 - 2^28. G = 255: Lg = 2^20 * 255 = 267386880 (L * G itself overflows 32
    // bits), 2^26 - Lg = -200278016 > S: counts. G = 256: Lg = L, S is not below 2^26 - L: kept.
    p.ct = std::numbers::pi;
    const std::vector<std::vector<float>> opposed = {{1.0f, 1.0f, 1.0f}, kFront, {-1.0f, -1.0f, -1.0f}};
    p.color_edge_curvature_share = 255.0 / 256.0;
    EXPECT_EQ(gated_row(z, opposed, p), cleared);
    p.color_edge_curvature_share = 1.0;
    EXPECT_EQ(gated_row(z, opposed, p), kept);
    p.color_edge_curvature_share = 0.0;
    EXPECT_EQ(gated_row(z, opposed, p), cleared);
}

TEST(ReferenceColorGate, ParameterErrors) {
    const std::vector<std::uint8_t> mask(256, 1);
    const std::vector<float> pts = grid_points(16, 16, [](int, int) { return 1000.0f; });
    const std::vector<float> nrm = constant_normals(256, 0.0f, 0.0f, -1.0f);
    const std::vector<std::uint8_t> color(3 * 256, 0);
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // Rejected by every entry point, colour image or none, with a message naming the parameter.
    const auto rejected_for = [&](const Params& p, const std::string& name) {
        const Output a = pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p);
        const Output b = pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p, color.data());
        const Output c = pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p);
        for (const Output* o : {&a, &b, &c}) {
            if (o->ok || o->error.find(name) == std::string::npos) return false;
        }
        return true;
    };
    const auto accepted = [&](const Params& p) {
        return pyrseg_ref::segment(pts.data(), nrm.data(), 16, 16, p).ok &&
               pyrseg_ref::segment(pts.data(), nullptr, 16, 16, p, color.data()).ok &&
               pyrseg_ref::segment_mask(mask.data(), nullptr, 16, 16, p).ok;
    };
    const auto with = [](Params p, double g) {
        p.color_edge_curvature_share = g;
        return p;
    };
    const Params paper;
    const Params robust = robust_params();
    for (double bad : {-0.1, 1.5, nan, inf, -inf, std::nextafter(1.0, 2.0), -std::numeric_limits<double>::min()}) {
        EXPECT_TRUE(rejected_for(with(robust, bad), "color_edge_curvature_share")) << bad;
        EXPECT_TRUE(rejected_for(with(paper, bad), "color_edge_curvature_share")) << bad;
    }
    for (double good : {0.0, -0.0, 0.25, 0.5, 1.0}) EXPECT_TRUE(accepted(with(robust, good))) << good;
    // Robust only: with the paper metric it must keep its default.
    EXPECT_TRUE(rejected_for(with(paper, 0.5), "color_edge_curvature_share"));
    EXPECT_TRUE(rejected_for(with(paper, 1.0), "color_edge_curvature_share"));
    EXPECT_TRUE(rejected_for(with(paper, 1.0 / 1024.0), "color_edge_curvature_share"));  // G = 0, still not 0
    EXPECT_TRUE(accepted(with(paper, 0.0)));
    EXPECT_TRUE(accepted(with(paper, -0.0)));
}

}  // namespace
