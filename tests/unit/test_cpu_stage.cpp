// The CPU backend's segmentation stage on the vector kernels: step 5's label init row (inherit_row) and step 6c's
// edge row (edge_row) against the shared functions on every Highway target this CPU runs, and whole masks (noise,
// thin lines and single pixels, which make step 6's runs, blocks and band borders, at odd sizes) segmented on every
// target against the scalar path, whose steps are the shared functions pixel by pixel.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends/cpu/cpu_kernels.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "pyrseg/segmenter.hpp"
#include "support/cpu_targets.hpp"

namespace pyrseg::test {
namespace {

namespace simd = ::pyrseg::cpu::simd;
namespace kernels = ::pyrseg::cpu::kernels;
using ::pyrseg::cpu::PassContext;

const std::uint32_t kWidths[] = {1, 2, 3, 4, 5, 7, 8, 15, 16, 17, 31, 32, 33, 63, 64, 65, 66, 127, 129, 130, 257, 1000};

class CpuStageRows : public ::testing::TestWithParam<std::string> {};

// pyr_label_init_texel (PYR_INIT_INHERIT) pixel by pixel against inherit_row, and the bitmap of the fillable pixels
// it leaves at 0; masks with every bit pattern, parents with zeros.
TEST_P(CpuStageRows, InheritRowMatchesTheSharedFunction) {
    const simd::RowKernels& k = kernels_named(GetParam());
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
                const std::uint32_t e = kernels::pyr_label_init_texel(c, level, parent, x, 0, PYR_INIT_INHERIT);
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

// pyr_edge_label (round 1) against edge_row on three-row images whose non-fillable pixels are unlabelled (the
// contract's state), and the minimum with the pixel's own label when it has one.
TEST_P(CpuStageRows, EdgeRowMatchesTheSharedFunction) {
    const simd::RowKernels& k = kernels_named(GetParam());
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
                            expected[i] = kernels::pyr_edge_label(c, level, x, y, 1u);
                            continue;
                        }
                        // With its own label: the minimum of it and what it would get unlabelled.
                        const std::uint32_t own = labels[i];
                        const bool edge = (mask[i] & PYR_MASK_FILLABLE) == 0 && valid[i] != 0;
                        if (edge) labels[i] = 0;
                        const std::uint32_t fresh = kernels::pyr_edge_label(c, level, x, y, 1u);
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
            }
        }
    }
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

INSTANTIATE_TEST_SUITE_P(Targets, CpuStageFrames, ::testing::ValuesIn(simd::accepted_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
