// The CPU backend's segmentation stage on the vector rows: step 5's label init row (inherit_row) and step 6c's
// edge row (edge_row) against the shared functions on every Highway target this CPU runs, and whole masks (noise,
// thin lines and single pixels, which make step 6's runs, blocks and band borders, at odd sizes) segmented on every
// target against the scalar path, whose steps are the shared functions pixel by pixel.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "backends/cpu/thread_pool.hpp"
#include "backends/cpu/union_find_fill.hpp"
#include "pyrseg/segmenter.hpp"
#include "support/cpu_targets.hpp"
#include "support/guarded_array.hpp"

namespace pyrseg::test {
namespace {

namespace simd = ::pyrseg::cpu::simd;
namespace pixel = ::pyrseg::cpu::pixel;
using ::pyrseg::cpu::kQuantWords;
using ::pyrseg::cpu::PassContext;

const std::uint32_t kWidths[] = {1, 2, 3, 4, 5, 7, 8, 15, 16, 17, 31, 32, 33, 63, 64, 65, 66, 127, 129, 130, 257, 1000};

class CpuStageRows : public ::testing::TestWithParam<std::string> {};

// pyr_label_init_texel (PYR_INIT_INHERIT) pixel by pixel against inherit_row, and the bitmap of the fillable pixels
// it leaves at 0; masks with every bit pattern, parents with zeros.
TEST_P(CpuStageRows, InheritRowMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(11);
    for (const std::uint32_t w : kWidths) {
        for (int trial = 0; trial < 6; ++trial) {
            const std::uint32_t pw = (w + 1) / 2;
            // Level 1 is the parent (one row, at offset 0), level 2 the row (offset pw).
            std::vector<std::uint8_t> mask(pw + w);
            std::vector<std::uint32_t> labels(pw + w, 0xdeadbeef);
            const int zero_percent = trial * 20;
            for (std::uint32_t x = 0; x < pw; ++x) {
                labels[x] = int(rng() % 100) < zero_percent ? 0u : std::uint32_t(rng() % 5000 + 1);
            }
            for (std::uint32_t x = 0; x < w; ++x) mask[pw + x] = std::uint8_t(rng() % (trial == 5 ? 2 : 256));
            PassContext c;
            c.mask = mask.data();
            c.labels = labels.data();
            const PyrLevel parent{pw, 1, 0};
            const PyrLevel level{w, 1, pw};
            std::vector<std::uint32_t> actual(w, 0x12345678);
            std::vector<std::uint64_t> bits((w + 63) / 64 + 1, 0xffffffffffffffffu);
            const bool any = k.inherit_row(mask.data() + pw, labels.data(), w, actual.data(), bits.data());
            std::vector<std::uint32_t> without(w, 0x12345678);
            k.inherit_row(mask.data() + pw, labels.data(), w, without.data(), nullptr);
            bool expected_any = false;
            for (std::uint32_t x = 0; x < w; ++x) {
                const std::uint32_t e = pixel::pyr_label_init_texel(c, level, parent, x, 0, PYR_INIT_INHERIT);
                ASSERT_EQ(actual[x], e) << "width " << w << " x " << x;
                ASSERT_EQ(without[x], e) << "width " << w << " x " << x;
                const bool hole = (mask[pw + x] & PYR_MASK_FILLABLE) != 0 && e == 0;
                expected_any |= hole;
                ASSERT_EQ((bits[x / 64] >> (x % 64)) & 1u, hole ? 1u : 0u) << "width " << w << " x " << x;
            }
            for (std::uint32_t x = w; x < (w + 63) / 64 * 64; ++x) {
                ASSERT_EQ((bits[x / 64] >> (x % 64)) & 1u, 0u) << "bit past the row, width " << w << " x " << x;
            }
            EXPECT_EQ(bits.back(), 0xffffffffffffffffu) << "a word past the row was written, width " << w;
            EXPECT_EQ(any, expected_any) << "width " << w;
        }
    }
}

// column_step against pyr_fill_step (once) pixel by pixel on the marked pixels: marks anywhere in the words (whole
// words, single bits, none), neighbours fillable or not, labelled or not; the marks of the pixels that took a label
// are cleared and no word past the row is touched.
TEST_P(CpuStageRows, ColumnStepMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(23);
    for (const std::uint32_t w : kWidths) {
        for (int trial = 0; trial < 8; ++trial) {
            const std::size_t words = (w + 63) / 64;
            std::vector<std::uint8_t> from_mask(w);
            std::vector<std::uint32_t> from(w);
            std::vector<std::uint32_t> row(w);
            std::vector<std::uint64_t> marked(words + 1, 0);
            marked.back() = 0x0123456789abcdefu;
            for (std::uint32_t x = 0; x < w; ++x) {
                from_mask[x] = std::uint8_t(rng() % 256);
                from[x] = rng() % 3 == 0 ? 0u : std::uint32_t(rng() % 100000 + 1);
                const bool mark = trial == 0 || (trial != 1 && rng() % std::uint32_t(trial) == 0);
                row[x] = mark ? 0u : std::uint32_t(rng() % 100000 + 1);
                if (mark) marked[x / 64] |= std::uint64_t{1} << (x % 64);
            }
            std::vector<std::uint32_t> expected = row;
            std::vector<std::uint64_t> expected_marks = marked;
            bool expected_took = false;
            for (std::uint32_t x = 0; x < w; ++x) {
                if (((marked[x / 64] >> (x % 64)) & 1u) == 0) continue;
                expected[x] = pixel::pyr_fill_step(row[x], PYR_MASK_FILLABLE, from[x], from_mask[x], 1u);
                if (expected[x] != 0) {
                    expected_marks[x / 64] &= ~(std::uint64_t{1} << (x % 64));
                    expected_took = true;
                }
            }
            const bool took = k.column_step(from_mask.data(), from.data(), row.data(), marked.data(), w);
            ASSERT_EQ(row, expected) << "width " << w << " trial " << trial;
            ASSERT_EQ(marked, expected_marks) << "width " << w << " trial " << trial;
            EXPECT_EQ(took, expected_took) << "width " << w << " trial " << trial;
        }
    }
}

// row_runs against the contract's step 6a written out (docs/algorithm.md section 5: left to right, then right to
// left, an unlabelled fillable pixel takes the label of a fillable, labelled neighbour, visible to the next pixel),
// on rows marked as inherit_row leaves them: runs of every length, across words, at the row's ends, whole rows.
TEST_P(CpuStageRows, RowRunsMatchTheContractsRowSweeps) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(31);
    for (const std::uint32_t w : kWidths) {
        for (int trial = 0; trial < 10; ++trial) {
            std::vector<std::uint8_t> mask(w);
            std::vector<std::uint32_t> row(w);
            for (std::uint32_t x = 0; x < w; ++x) {
                const std::uint32_t hole_odds = trial < 3 ? 2u : std::uint32_t(trial);
                const bool fillable = trial >= 8 || rng() % 4 != 0;  // 8, 9: runs across words, whole rows
                mask[x] = std::uint8_t((fillable ? PYR_MASK_FILLABLE : 0) | (rng() % 2 << 1));
                const bool hole = trial == 9 || (trial == 8 ? rng() % 150 != 0 : rng() % hole_odds == 0);
                row[x] = hole ? 0u : std::uint32_t(rng() % 100000 + 1);
                if ((mask[x] & PYR_MASK_FILLABLE) == 0) row[x] = rng() % 2 == 0 ? 0u : 7u;  // not read
            }
            const auto marks_of = [&](const std::vector<std::uint32_t>& labels) {
                std::vector<std::uint64_t> bits((w + 63) / 64 + 1, 0);
                for (std::uint32_t x = 0; x < w; ++x) {
                    if ((mask[x] & PYR_MASK_FILLABLE) != 0 && labels[x] == 0)
                        bits[x / 64] |= std::uint64_t{1} << (x % 64);
                }
                return bits;
            };
            std::vector<std::uint32_t> expected = row;
            const auto labelled_fillable = [&](std::uint32_t x) {
                return (mask[x] & PYR_MASK_FILLABLE) != 0 && expected[x] != 0;
            };
            for (std::uint32_t x = 1; x < w; ++x) {
                if ((mask[x] & PYR_MASK_FILLABLE) != 0 && expected[x] == 0 && labelled_fillable(x - 1))
                    expected[x] = expected[x - 1];
            }
            for (std::uint32_t x = w; x-- > 1;) {
                if ((mask[x - 1] & PYR_MASK_FILLABLE) != 0 && expected[x - 1] == 0 && labelled_fillable(x))
                    expected[x - 1] = expected[x];
            }
            std::vector<std::uint64_t> marked = marks_of(row);
            marked.back() = 0x0123456789abcdefu;
            std::vector<std::uint64_t> expected_marks = marks_of(expected);
            expected_marks.back() = marked.back();
            bool expected_remain = false;
            for (std::size_t i = 0; i + 1 < expected_marks.size(); ++i) expected_remain |= expected_marks[i] != 0;
            // The row ends where the mapping does (runs at its end must write nothing past it: on NEON a masked
            // store is a load and a store of the whole vector).
            GuardedArray<std::uint32_t> guarded(row);
            const bool remain = k.row_runs(mask.data(), guarded.data(), marked.data(), w);
            row = guarded.values();
            ASSERT_EQ(row, expected) << "width " << w << " trial " << trial;
            ASSERT_EQ(marked, expected_marks) << "width " << w << " trial " << trial;
            EXPECT_EQ(remain, expected_remain) << "width " << w << " trial " << trial;
        }
    }
}

// compact_row against the table lookup: long runs of one label (many vectors' worth), short ones, zeros inside runs,
// a new label at every pixel.
TEST_P(CpuStageRows, CompactRowMatchesTheTable) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(29);
    std::vector<std::uint32_t> lut(4096);
    for (std::size_t i = 1; i < lut.size(); ++i) lut[i] = std::uint32_t(rng());
    lut[0] = 0;
    for (const std::uint32_t w : kWidths) {
        for (int trial = 0; trial < 4; ++trial) {
            std::vector<std::uint32_t> raw(w);
            std::uint32_t label = 0;
            for (std::uint32_t x = 0; x < w; ++x) {
                if (trial == 3 || rng() % std::uint32_t(trial == 0 ? 40 : 3) == 0) label = rng() % 4096;
                raw[x] = trial == 2 && x % 5 == 0 ? 0u : label;
            }
            std::vector<std::uint32_t> out(w + 1, 0xabababab);
            k.compact_row(raw.data(), lut.data(), w, out.data());
            for (std::uint32_t x = 0; x < w; ++x) ASSERT_EQ(out[x], lut[raw[x]]) << "width " << w << " x " << x;
            EXPECT_EQ(out[w], 0xababababu) << "written past the row, width " << w;
        }
    }
}

// pyr_edge_label (round 1) against edge_row (and edge_row_from_candidates) on three-row images whose non-fillable
// pixels are unlabelled (the contract's state), and the minimum with the pixel's own label when it has one.
TEST_P(CpuStageRows, EdgeRowMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(12);
    for (const std::uint32_t w : kWidths) {
        for (std::uint32_t h = 1; h <= 3; ++h) {
            for (int trial = 0; trial < 8; ++trial) {
                const std::size_t n = std::size_t(w) * h;
                std::vector<std::uint8_t> mask(n);
                std::vector<std::uint8_t> valid(n);
                std::vector<std::uint32_t> labels(n);
                const bool own_labels = trial >= 6;  // non-fillable pixels labelled already
                for (std::size_t i = 0; i < n; ++i) {
                    mask[i] = std::uint8_t(rng() % (trial % 2 == 0 ? 2 : 256));
                    valid[i] = std::uint8_t(rng() % 4 == 0 ? 0 : (trial % 3 == 0 ? 1 : rng() % 255 + 1));
                    labels[i] = rng() % 4 == 0 ? 0u : std::uint32_t(rng() % (trial < 3 ? 4 : 100000) + 1);
                    if ((mask[i] & PYR_MASK_FILLABLE) == 0 && !own_labels) labels[i] = 0;
                }
                PassContext c;
                c.mask = mask.data();
                c.labels = labels.data();
                c.mask_valid = valid.data();
                const PyrLevel level{w, h, 0};
                std::vector<std::uint32_t> expected(labels);
                for (std::uint32_t y = 0; y < h; ++y) {
                    for (std::uint32_t x = 0; x < w; ++x) {
                        const std::size_t i = std::size_t(y) * w + x;
                        if (!own_labels) {
                            expected[i] = pixel::pyr_edge_label(c, level, x, y, 1u, 0.0f);
                            continue;
                        }
                        // With its own label: the minimum of it and what it would get unlabelled.
                        const std::uint32_t own = labels[i];
                        const bool edge = (mask[i] & PYR_MASK_FILLABLE) == 0 && valid[i] != 0;
                        if (edge) labels[i] = 0;
                        const std::uint32_t fresh = pixel::pyr_edge_label(c, level, x, y, 1u, 0.0f);
                        labels[i] = own;
                        if (edge && own != 0 && (fresh == 0 || own < fresh))
                            expected[i] = own;
                        else
                            expected[i] = edge ? fresh : own;
                    }
                }
                // Rows one at a time, in place, top to bottom (each reads only fillable neighbours, which no row
                // changes).
                std::vector<std::uint32_t> actual(labels);
                for (std::uint32_t y = 0; y < h; ++y) {
                    const std::size_t i = std::size_t(y) * w;
                    const bool up = y > 0;
                    const bool down = y + 1 < h;
                    k.edge_row(up ? mask.data() + i - w : nullptr, mask.data() + i,
                               down ? mask.data() + i + w : nullptr, up ? actual.data() + i - w : nullptr,
                               actual.data() + i, down ? actual.data() + i + w : nullptr, valid.data() + i, w);
                }
                for (std::size_t i = 0; i < n; ++i) {
                    ASSERT_EQ(actual[i], expected[i]) << w << "x" << h << " trial " << trial << " pixel " << i;
                }
                // The same from the rows' candidates (edge_candidates of the labels as they were).
                std::vector<std::uint32_t> candidates(n + 1, 0x5a5a5a5au);
                k.edge_candidates(mask.data(), labels.data(), std::uint32_t(n), candidates.data());
                EXPECT_EQ(candidates[n], 0x5a5a5a5au) << "written past the row";
                std::vector<std::uint32_t> from_candidates(labels);
                for (std::uint32_t y = 0; y < h; ++y) {
                    const std::size_t i = std::size_t(y) * w;
                    k.edge_row_from_candidates(y > 0 ? candidates.data() + i - w : nullptr, candidates.data() + i,
                                               y + 1 < h ? candidates.data() + i + w : nullptr, mask.data() + i,
                                               valid.data() + i, from_candidates.data() + i, w);
                }
                for (std::size_t i = 0; i < n; ++i) {
                    ASSERT_EQ(from_candidates[i], expected[i])
                        << "from candidates, " << w << "x" << h << " trial " << trial << " pixel " << i;
                }
            }
        }
    }
}

// Rounds 1 .. 12 of step 6c with several rounds: masks with earlier rounds in their upper bits (and rounds from later
// ones, which must not count), labels on fillable pixels and on pixels labelled in a round, without and with the
// depth test (depths a few steps apart, some exactly at the limit); exactly the pixels whose label pyr_edge_label
// changes are marked, with that label, and nothing is written past the row.
TEST_P(CpuStageRows, EdgeRoundRowMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(13);
    std::size_t taken = 0;
    std::size_t refused_by_depth = 0;
    for (const float depth_step : {0.0f, 0.02f})
        for (const std::uint32_t w : kWidths) {
            for (std::uint32_t h = 1; h <= 3; ++h) {
                for (std::uint32_t round = 1; round <= 12; round += (w > 100 ? 5 : 1)) {
                    const std::size_t n = std::size_t(w) * h;
                    std::vector<std::uint8_t> mask(n);
                    std::vector<std::uint8_t> valid(n);
                    std::vector<std::uint32_t> labels(n);
                    std::vector<std::uint32_t> quant(kQuantWords * n);
                    for (std::size_t i = 0; i < n; ++i) {
                        // |1000 - 1020| is exactly 0.02 * 1000 (both exact in float32): the test's boundary.
                        constexpr std::array<float, 5> kDepths = {1000.0f, 1010.0f, 1020.0f, 1050.0f, 2000.0f};
                        quant[kQuantWords * i + 2] = std::bit_cast<std::uint32_t>(kDepths[rng() % kDepths.size()]);
                        const bool fillable = rng() % 3 == 0;
                        const std::uint32_t labelled_round = rng() % 2 == 0 ? 0u : std::uint32_t(rng() % 14 + 1);
                        mask[i] = std::uint8_t((fillable ? PYR_MASK_FILLABLE : 0u) | (rng() % 2 != 0 ? 2u : 0u) |
                                               (labelled_round << PYR_MASK_EDGE_SHIFT));
                        valid[i] = std::uint8_t(rng() % 5 == 0 ? 0 : rng() % 255 + 1);
                        const bool labelled = fillable ? rng() % 4 != 0 : labelled_round != 0;
                        labels[i] = labelled ? std::uint32_t(rng() % (round % 2 == 0 ? 5 : 1000000) + 1) : 0u;
                    }
                    PassContext c;
                    c.mask = mask.data();
                    c.labels = labels.data();
                    c.mask_valid = valid.data();
                    c.quant = quant.data();
                    const PyrLevel level{w, h, 0};
                    for (std::uint32_t y = 0; y < h; ++y) {
                        const std::size_t i = std::size_t(y) * w;
                        const bool up = y > 0;
                        const bool down = y + 1 < h;
                        // Both end at a guard page.
                        GuardedArray<std::uint32_t> out(std::vector<std::uint32_t>(w, 0x5a5a5a5au));
                        const std::size_t words = (std::size_t(w) + 63) / 64;
                        GuardedArray<std::uint64_t> changed(std::vector<std::uint64_t>(words, ~std::uint64_t{0}));
                        const bool any = k.edge_round_row(
                            up ? mask.data() + i - w : nullptr, mask.data() + i, down ? mask.data() + i + w : nullptr,
                            up ? labels.data() + i - w : nullptr, labels.data() + i,
                            down ? labels.data() + i + w : nullptr, valid.data() + i, w, round,
                            simd::EdgeDepths{depth_step, depth_step > 0.0f ? quant.data() + kQuantWords * i : nullptr},
                            out.data(), changed.data());
                        bool expected_any = false;
                        for (std::uint32_t x = 0; x < w; ++x) {
                            const std::uint32_t expected = pixel::pyr_edge_label(c, level, x, y, round, depth_step);
                            if (pixel::pyr_edge_label(c, level, x, y, round, 0.0f) != expected) ++refused_by_depth;
                            const bool takes = expected != labels[i + x];
                            const bool marked = ((changed.data()[x / 64] >> (x % 64)) & 1u) != 0;
                            ASSERT_EQ(marked, takes)
                                << w << "x" << h << " round " << round << " pixel " << x << "," << y;
                            if (takes) {
                                ASSERT_EQ(out.data()[x], expected)
                                    << w << "x" << h << " round " << round << " pixel " << x << "," << y;
                            }
                            expected_any |= takes;
                            taken += takes ? 1 : 0;
                        }
                        EXPECT_EQ(any, expected_any);
                        for (std::size_t b = w; b < 64 * words; ++b) {
                            ASSERT_EQ((changed.data()[b / 64] >> (b % 64)) & 1u, 0u) << "a bit past the row";
                        }
                    }
                }
            }
        }
    EXPECT_GT(taken, 1000u) << "too few pixels labelled in a round to test much";
    EXPECT_GT(refused_by_depth, 100u) << "too few labels changed by the depth test to test it";
}

INSTANTIATE_TEST_SUITE_P(Targets, CpuStageRows, ::testing::ValuesIn(target_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

struct MaskFrame {
    int w = 0;
    int h = 0;
    std::vector<unsigned char> fillable;
    std::vector<unsigned char> valid;
};

// Blobs (so the pyramid has regions and bridges), cut by thin lines and dotted with single pixels and holes, and
// random validity; kind 1 is plain noise.
MaskFrame make_mask(int w, int h, int kind, std::uint32_t seed) {
    std::mt19937 rng(seed);
    MaskFrame f;
    f.w = w;
    f.h = h;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    f.fillable.assign(n, 0);
    f.valid.assign(n, 1);
    const auto at = [&](int x, int y) -> unsigned char& { return f.fillable[std::size_t(y) * std::size_t(w) + x]; };
    if (kind == 1) {
        for (unsigned char& v : f.fillable) v = rng() % 3 != 0 ? 1 : 0;
    } else {
        for (int b = 0; b < 12; ++b) {
            const int x0 = int(rng() % std::uint32_t(w));
            const int y0 = int(rng() % std::uint32_t(h));
            const int bw = 1 + int(rng() % std::uint32_t(w / 2 + 1));
            const int bh = 1 + int(rng() % std::uint32_t(h / 2 + 1));
            for (int y = y0; y < std::min(h, y0 + bh); ++y) {
                for (int x = x0; x < std::min(w, x0 + bw); ++x) at(x, y) = 1;
            }
        }
        for (int l = 0; l < 6; ++l) {  // one-pixel lines, fillable and not
            const unsigned char v = l % 2 == 0 ? 1 : 0;
            const int x = int(rng() % std::uint32_t(w));
            const int y = int(rng() % std::uint32_t(h));
            for (int yy = 0; yy < h; ++yy) at(x, yy) = v;
            for (int xx = 0; xx < w; ++xx) at(xx, y) = v;
        }
        for (std::size_t i = 0; i < n / 20; ++i) {
            f.fillable[rng() % n] = std::uint8_t(rng() % 2 == 0 ? 1 : 0);
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (rng() % 10 == 0) f.valid[i] = std::uint8_t(rng() % 3 == 0 ? 0 : 7);
        if (kind == 2 && rng() % 2 == 0) f.fillable[i] = std::uint8_t(f.fillable[i] * (1 + rng() % 200));
    }
    return f;
}

Result segment_mask_with(const std::string& mode, const MaskFrame& f, const Params& params) {
    const ScopedEnv env("PYRSEG_CPU_SIMD", mode);
    Outputs outputs;
    outputs.raw_labels = true;
    outputs.fillable_mask = true;
    outputs.segment_stats = true;
    Segmenter segmenter(f.w, f.h, params, "cpu", outputs);
    const MaskView view{f.fillable.data(), f.valid.data(), f.w, f.h};
    Result r;
    segmenter.segment_mask(view, r);
    segmenter.segment_mask(view, r);  // a warm frame: the scratch of the first must not leak into it
    return r;
}

class CpuStageFrames : public ::testing::TestWithParam<std::string> {};

TEST_P(CpuStageFrames, MasksMatchTheScalarPath) {
    const std::string& mode = GetParam();
    const int sizes[][2] = {{9, 9}, {17, 13}, {64, 33}, {65, 64}, {130, 70}, {257, 129}, {311, 203}};
    std::uint32_t seed = 1;
    std::uint32_t segments = 0;
    for (const auto& size : sizes) {
        for (int kind = 0; kind < 3; ++kind) {
            for (int variant = 0; variant < 4; ++variant) {
                const MaskFrame f = make_mask(size[0], size[1], kind, seed++);
                Params params;
                params.label_edges = variant != 1;
                params.edge_rounds = variant == 2 ? 3 : 1;
                params.compact = variant != 3;
                SCOPED_TRACE(std::to_string(f.w) + "x" + std::to_string(f.h) + " kind " + std::to_string(kind) +
                             " variant " + std::to_string(variant));
                const Result scalar = segment_mask_with("scalar", f, params);
                // Many threads, many bands of rows: step 6's column sweeps cross more band borders.
                const ScopedEnv threads("PYRSEG_THREADS", variant % 2 == 0 ? "7" : "2");
                const Result r = segment_mask_with(mode, f, params);
                ASSERT_EQ(r.raw_labels, scalar.raw_labels);
                ASSERT_EQ(r.labels, scalar.labels);
                ASSERT_EQ(r.fillable_mask, scalar.fillable_mask);
                ASSERT_EQ(r.segment_count, scalar.segment_count);
                ASSERT_EQ(r.segments.size(), scalar.segments.size());
                segments += r.segment_count;
            }
        }
    }
    EXPECT_GT(segments, 300u);
}

// The union-find fill and the shared sweeps reach the same fixed points on the same masks.
TEST(CpuStageFill, UnionFindMatchesTheSweeps) {
    std::uint32_t seed = 100;
    for (const auto& size : {std::pair{65, 64}, std::pair{257, 129}}) {
        for (int kind = 0; kind < 2; ++kind) {
            const MaskFrame f = make_mask(size.first, size.second, kind, seed++);
            const Result uf = segment_mask_with("auto", f, {});
            Result sweeps;
            {
                const ScopedEnv fill("PYRSEG_CPU_FILL", "sweeps");
                sweeps = segment_mask_with("auto", f, {});
            }
            ASSERT_EQ(uf.raw_labels, sweeps.raw_labels);
        }
    }
}

// The contract of steps 2 and 4 by flood fill: each 4-connected component of fillable, non-anchored texels takes the
// smallest non-zero label inside it or on an anchored texel next to it (0 when there is none).
std::vector<std::uint32_t> flood_fill_reference(std::uint32_t w, std::uint32_t h, const std::uint8_t* mask,
                                                const std::uint32_t* labels) {
    const auto eligible = [&](std::size_t i) {
        return (mask[i] & (PYR_MASK_FILLABLE | PYR_MASK_ANCHORED)) == PYR_MASK_FILLABLE;
    };
    const std::size_t n = std::size_t(w) * h;
    std::vector<std::uint32_t> out(labels, labels + n);
    std::vector<char> seen(n, 0);
    std::vector<std::size_t> component;
    for (std::size_t start = 0; start < n; ++start) {
        if (seen[start] != 0 || !eligible(start)) continue;
        component.clear();
        std::deque<std::size_t> queue{start};
        seen[start] = 1;
        std::uint32_t best = 0;
        const auto take = [&](std::uint32_t label) {
            if (label != 0 && (best == 0 || label < best)) best = label;
        };
        while (!queue.empty()) {
            const std::size_t i = queue.front();
            queue.pop_front();
            component.push_back(i);
            take(labels[i]);
            const std::uint32_t x = std::uint32_t(i % w);
            const std::uint32_t y = std::uint32_t(i / w);
            const std::size_t next[4] = {x > 0 ? i - 1 : i, x + 1 < w ? i + 1 : i, y > 0 ? i - w : i,
                                         y + 1 < h ? i + w : i};
            for (const std::size_t j : next) {
                if (j == i) continue;
                if ((mask[j] & PYR_MASK_ANCHORED) != 0) take(labels[j]);
                if (seen[j] == 0 && eligible(j)) {
                    seen[j] = 1;
                    queue.push_back(j);
                }
            }
        }
        for (const std::size_t i : component) out[i] = best;
    }
    return out;
}

// union_find_fill against the flood fill on noise (many short runs, so every row's run lists interleave and the
// merge walks and the stripes' border joins see every kind of overlap), with anchored texels, at sizes that cut
// the bit words and the stripes anywhere, with 1, 2 and 3 threads.
TEST(CpuStageFill, UnionFindMatchesAFloodFillOnNoise) {
    const std::uint32_t sizes[][2] = {{1, 1},   {1, 97},  {97, 1},   {2, 2},     {3, 50},   {63, 17},   {64, 31},
                                      {65, 40}, {127, 9}, {129, 64}, {200, 150}, {4100, 6}, {5000, 23}, {7, 900}};
    std::mt19937 rng(1234);
    std::uint64_t texels = 0;
    for (const unsigned threads : {1u, 2u, 3u}) {
        ::pyrseg::cpu::ThreadPool pool(::pyrseg::cpu::ThreadSetting{threads, nullptr});
        for (const auto& size : sizes) {
            const std::uint32_t w = size[0];
            const std::uint32_t h = size[1];
            const std::size_t n = std::size_t(w) * h;
            for (int trial = 0; trial < 6; ++trial) {
                const bool anchors = trial % 2 == 1;
                const std::uint32_t eligible_percent = trial < 2 ? 55 : (trial < 4 ? 70 : 90);
                const std::uint32_t label_range = trial < 4 ? 20 : 1000000;
                // The level lies at an offset of a larger buffer, as the pyramid's levels do.
                const std::uint32_t offset = 5;
                std::vector<std::uint8_t> mask(offset + n + 3, 0xff);
                std::vector<std::uint32_t> labels(offset + n + 3, 0xdeadbeef);
                for (std::size_t i = offset; i < offset + n; ++i) {
                    const std::uint32_t roll = rng() % 100;
                    // Bits 2..7 are the edge rounds' and must not matter.
                    std::uint8_t m = std::uint8_t(rng() % 64 << 2);
                    if (roll < eligible_percent) {
                        m |= PYR_MASK_FILLABLE;
                    } else if (anchors && roll < eligible_percent + 5) {
                        m |= PYR_MASK_FILLABLE | PYR_MASK_ANCHORED;
                    }
                    mask[i] = m;
                    labels[i] = rng() % 3 == 0 ? 0u : 1u + rng() % label_range;
                }
                const std::vector<std::uint32_t> expected =
                    flood_fill_reference(w, h, mask.data() + offset, labels.data() + offset);
                // Scratch from a larger level and full of garbage: the fill must not rely on either.
                std::vector<std::uint32_t> scratch(::pyrseg::cpu::union_find_scratch_size(w + 1, h + 1), 0xabababab);
                ::pyrseg::cpu::union_find_fill(pool, PyrLevel{w, h, offset}, mask.data(), labels.data(), anchors,
                                               scratch.data());
                for (std::size_t i = 0; i < n; ++i) {
                    ASSERT_EQ(labels[offset + i], expected[i])
                        << w << "x" << h << " trial " << trial << " threads " << threads << " texel " << i;
                }
                for (std::uint32_t i = 0; i < offset; ++i) ASSERT_EQ(labels[i], 0xdeadbeef);
                for (std::size_t i = offset + n; i < labels.size(); ++i) ASSERT_EQ(labels[i], 0xdeadbeef);
                texels += n;
            }
        }
    }
    EXPECT_GT(texels, 1000000u);
}

INSTANTIATE_TEST_SUITE_P(Targets, CpuStageFrames, ::testing::ValuesIn(simd::accepted_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
