// The CPU backend's vector row passes (backends/cpu/simd/): for every Highway target this build has and this CPU
// runs, forced in turn with PYRSEG_CPU_SIMD, each row function gives the bytes of the shared scalar function on
// adversarial inputs (special floats, extreme exponents, odd widths, strided layouts), and whole segmentations give
// the normals, fillable mask and labels of the scalar path and of the independent reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/cpu_targets.hpp"
#include "support/guarded_array.hpp"
#include "support/oracle.hpp"
#include "support/test_frame.hpp"

namespace pyrseg::test {
namespace {

namespace simd = ::pyrseg::cpu::simd;
namespace pixel = ::pyrseg::cpu::pixel;
using ::pyrseg::cpu::kQuantWords;
using ::pyrseg::cpu::PassContext;

// A quantized pixel as the metric tests make them (stored with cpu::store_quant).
struct QuantPixel {
    std::int16_t q[3] = {0, 0, 0};
    std::uint16_t valid = 0;
    float z = 0;
};

std::vector<std::uint32_t> to_words(const std::vector<QuantPixel>& pixels) {
    std::vector<std::uint32_t> words(kQuantWords * pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const QuantPixel& p = pixels[i];
        ::pyrseg::cpu::store_quant(words.data() + kQuantWords * i, p.q[0], p.q[1], p.q[2], p.valid, p.z);
    }
    return words;
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kDenorm = std::numeric_limits<float>::denorm_min();
constexpr float kMin = std::numeric_limits<float>::min();
constexpr float kMax = std::numeric_limits<float>::max();

float from_bits(std::uint32_t bits) {
    float f = 0;
    std::memcpy(&f, &bits, sizeof f);
    return f;
}

// A value that breaks something: non-finite, zero of either sign, subnormal, extreme, or random bits.
float special_value(std::mt19937& rng) {
    static const float kSpecial[] = {kNaN,    -kNaN,    kInf,   -kInf,  0.0f,   -0.0f, -1.0f, -1e30f,
                                     kDenorm, -kDenorm, kMin,   -kMin,  1e-38f, kMax,  -kMax, 1e30f,
                                     -1e-38f, 3e38f,    2e-45f, 1e-40f, 5e-39f, 1.0f,  -3e38f};
    const std::uint32_t pick = rng() % (std::size(kSpecial) + 4);
    if (pick < std::size(kSpecial)) return kSpecial[pick];
    return from_bits(static_cast<std::uint32_t>(rng()));
}

// A smooth bumpy surface in front of the camera, times `scale`, with a fraction of components replaced by special
// values and a few pixels by random bit patterns.
std::vector<float> make_points(int w, int h, float scale, double special_fraction, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-0.5f, 0.5f);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> p(3 * std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float* q = &p[3 * (std::size_t(y) * std::size_t(w) + std::size_t(x))];
            const float z = 1000.0f + 40.0f * std::sin(float(x) * 0.21f) * std::cos(float(y) * 0.17f) +
                            (x > w / 2 ? 35.0f : 0.0f) + noise(rng);
            q[0] = (float(x) - float(w) / 2) * 1.7f * scale;
            q[1] = (float(y) - float(h) / 2) * 1.7f * scale;
            q[2] = z * scale;
            for (int c = 0; c < 3; ++c) {
                if (unit(rng) < special_fraction) q[c] = special_value(rng);
            }
        }
    }
    return p;
}

// Normals of any length (given normals need not be unit), with special values mixed in.
std::vector<float> make_normals(std::size_t pixels, double special_fraction, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> component(-1.3f, 1.3f);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::uniform_int_distribution<int> tie(-8193, 8193);
    std::vector<float> n(3 * pixels);
    for (float& v : n) {
        const float u = unit(rng);
        if (u < special_fraction) {
            v = special_value(rng);
        } else if (u < special_fraction + 0.1) {
            v = (float(tie(rng)) + 0.5f) / 8192.0f;  // exactly half way between two quantized values
        } else if (u < special_fraction + 0.15) {
            v = float(tie(rng)) / 8192.0f;
        } else {
            v = component(rng);
        }
    }
    return n;
}

// The first differing byte of two buffers, as "element i (pixel p, byte b)", or "" when equal.
std::string first_difference(const void* a, const void* b, std::size_t bytes, std::size_t element_bytes) {
    const auto* x = static_cast<const unsigned char*>(a);
    const auto* y = static_cast<const unsigned char*>(b);
    for (std::size_t i = 0; i < bytes; ++i) {
        if (x[i] != y[i]) {
            std::ostringstream s;
            s << "element " << i / element_bytes << ", byte " << i % element_bytes << ": " << int(x[i]) << " vs "
              << int(y[i]);
            return s.str();
        }
    }
    return "";
}

// A cloud in a given layout: point_floats floats a point, rows padded by `pad` points (filled with junk).
struct Layout {
    std::vector<float> floats;
    std::size_t point_floats = 3;
    std::size_t row_floats = 0;
};

Layout lay_out(const std::vector<float>& packed, int w, int h, std::size_t point_floats, std::size_t pad) {
    Layout l;
    l.point_floats = point_floats;
    l.row_floats = (std::size_t(w) + pad) * point_floats;
    l.floats.assign(l.row_floats * std::size_t(h), -777.0f);
    for (std::size_t y = 0; y < std::size_t(h); ++y) {
        for (std::size_t x = 0; x < std::size_t(w); ++x) {
            for (std::size_t c = 0; c < 3; ++c) {
                l.floats[y * l.row_floats + x * point_floats + c] = packed[3 * (y * std::size_t(w) + x) + c];
            }
        }
    }
    return l;
}

struct Size {
    int w, h;
};
const Size kSizes[] = {{1, 1},  {2, 3},  {3, 2},  {5, 7},  {7, 5},   {8, 3},   {9, 9},   {15, 4},  {16, 5},
                       {17, 6}, {31, 3}, {33, 8}, {63, 4}, {65, 11}, {67, 45}, {131, 9}, {17, 40}, {1, 30}};

class CpuSimdRows : public ::testing::TestWithParam<std::string> {};

// pyr_normal_q, pixel by pixel, against the target's normals_row: every size, radius, scale and layout.
TEST_P(CpuSimdRows, NormalsMatchTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::uint32_t seed = 1;
    const float scales[] = {1.0f, 1e30f, 1e-38f, 1e-30f, 3e36f};
    std::size_t defined = 0;
    std::size_t pixels = 0;
    for (const Size s : kSizes) {
        for (const int r : {1, 2, 3, 5, 8, 40}) {
            for (const float scale : scales) {
                for (const std::size_t pf : {std::size_t{3}, std::size_t{4}, std::size_t{7}}) {
                    const double specials = seed % 3 == 0 ? 0.0 : 0.08;
                    const std::vector<float> packed = make_points(s.w, s.h, scale, specials, seed++);
                    const Layout l = lay_out(packed, s.w, s.h, pf, pf == 3 ? 0 : 5);
                    PassContext c;
                    c.points = l.floats.data();
                    c.point_floats = l.point_floats;
                    c.row_floats = l.row_floats;
                    const auto w = std::uint32_t(s.w);
                    const auto h = std::uint32_t(s.h);
                    std::vector<float> expected(packed.size());
                    for (std::uint32_t y = 0; y < h; ++y) {
                        for (std::uint32_t x = 0; x < w; ++x) {
                            const PyrIVec3 q = pixel::pyr_normal_q(c, w, h, x, y, std::uint32_t(r));
                            float* n = &expected[3 * (std::size_t(y) * w + x)];
                            n[0] = float(q.x) * PYR_NORMAL_UNIT;
                            n[1] = float(q.y) * PYR_NORMAL_UNIT;
                            n[2] = float(q.z) * PYR_NORMAL_UNIT;
                            defined += (q.x | q.y | q.z) != 0 ? 1 : 0;
                        }
                    }
                    pixels += std::size_t(w) * h;
                    std::vector<float> actual(packed.size(), 99.0f);
                    for (std::uint32_t y = 0; y < h; ++y) {
                        k.normals_row(c, w, h, y, std::uint32_t(r), actual.data() + 3 * std::size_t(y) * w);
                    }
                    const std::string diff = first_difference(actual.data(), expected.data(),
                                                              actual.size() * sizeof(float), 3 * sizeof(float));
                    ASSERT_EQ(diff, "") << s.w << "x" << s.h << " r=" << r << " scale=" << scale << " stride=" << pf;
                }
            }
        }
    }
    EXPECT_GT(defined, pixels / 4) << "too few pixels with a normal to test much";
}

// Tangents chosen in fixed point: rows 3k and 3k + 2 give v = P(x, 3k + 2) - P(x, 3k) freely, row 3k + 1 gives
// u = P(x + 1) - P(x - 1) freely (a chain on each parity of x). Among them the cross products whose largest
// component rounds up to the next power of two in float (2^30 - 1 = 32767 * 32769: u = (32767, -2, a),
// v = (32767, 32767, b)), parallel tangents, tiny and huge ones.
TEST_P(CpuSimdRows, NormalsOfCraftedTangentsMatchTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(21);
    const std::uint32_t w = 70;
    const std::uint32_t blocks = 60;
    const std::uint32_t h = 3 * blocks;
    std::vector<float> points(3 * std::size_t(w) * h);
    const auto at = [&](std::uint32_t x, std::uint32_t y) { return &points[3 * (std::size_t(y) * w + x)]; };
    std::uniform_int_distribution<int> big(-32767, 32767);
    std::uniform_int_distribution<int> small(-9, 9);
    std::uniform_int_distribution<int> medium(-16000, 16000);
    for (std::uint32_t b = 0; b < blocks; ++b) {
        const int kind = int(b % 4);  // 0: the carry case, 1: random, 2: small, 3: parallel
        const auto draw = [&](int which) { return float(which == 2 ? small(rng) : big(rng)); };
        float u[70][3];
        float v[70][3];
        for (std::uint32_t x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                u[x][c] = draw(kind);
                v[x][c] = draw(kind);
            }
            if (kind == 0 || (kind == 1 && x % 5 == 0)) {
                // |z| <= 16000 keeps 2^30 - 1 the largest component, and the others need all their bits.
                const float cu[3] = {32767.0f, -2.0f, float(medium(rng))};
                const float cv[3] = {32767.0f, 32767.0f, float(medium(rng))};
                for (int c = 0; c < 3; ++c) {
                    u[x][c] = (x % 2 == 0) ? cu[c] : -cu[c];
                    v[x][c] = (x % 3 == 0) ? cv[c] : -cv[c];
                }
            }
            if (kind == 3) {
                for (int c = 0; c < 3; ++c) v[x][c] = u[x][c] * float(1 + x % 3);
            }
        }
        for (std::uint32_t x = 0; x < w; ++x) {
            float* top = at(x, 3 * b);
            float* bottom = at(x, 3 * b + 2);
            top[0] = 0.0f;
            top[1] = 0.0f;
            top[2] = 50000.0f;
            for (int c = 0; c < 3; ++c) bottom[c] = top[c] + v[x][c];
        }
        // Row 3b + 1: P(x + 1) = P(x - 1) + u(x), from P(0) and P(1).
        for (std::uint32_t x = 0; x < 2; ++x) {
            float* p = at(x, 3 * b + 1);
            p[0] = float(x);
            p[1] = 0.0f;
            p[2] = 4194304.0f;  // 2^22: stays positive and exact along the chain
        }
        for (std::uint32_t x = 1; x + 1 < w; ++x) {
            const float* left = at(x - 1, 3 * b + 1);
            float* right = at(x + 1, 3 * b + 1);
            for (int c = 0; c < 3; ++c) right[c] = left[c] + u[x][c];
        }
    }
    PassContext c;
    c.points = points.data();
    c.row_floats = 3 * std::size_t(w);
    std::vector<float> expected(points.size());
    std::vector<float> actual(points.size(), 99.0f);
    int defined = 0;
    for (std::uint32_t y = 0; y < h; ++y) {
        for (std::uint32_t x = 0; x < w; ++x) {
            const PyrIVec3 q = pixel::pyr_normal_q(c, w, h, x, y, 1);
            float* n = &expected[3 * (std::size_t(y) * w + x)];
            n[0] = float(q.x) * PYR_NORMAL_UNIT;
            n[1] = float(q.y) * PYR_NORMAL_UNIT;
            n[2] = float(q.z) * PYR_NORMAL_UNIT;
            defined += (q.x | q.y | q.z) != 0 ? 1 : 0;
        }
        k.normals_row(c, w, h, y, 1, actual.data() + 3 * std::size_t(y) * w);
    }
    EXPECT_GT(defined, int(w * h / 2));
    const std::string diff =
        first_difference(actual.data(), expected.data(), actual.size() * sizeof(float), 3 * sizeof(float));
    EXPECT_EQ(diff, "");
}

// pyr_quantize against quantize_row: special points and normals, ties, components past +-1, layouts.
TEST_P(CpuSimdRows, QuantizeMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::uint32_t seed = 100;
    for (const int w : {1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 33, 64, 65, 131, 1000}) {
        for (const std::size_t pf : {std::size_t{3}, std::size_t{4}, std::size_t{12}}) {
            for (const std::size_t nf : {std::size_t{3}, std::size_t{5}}) {
                const std::vector<float> points = make_points(w, 1, seed % 2 == 0 ? 1.0f : 1e-38f, 0.2, seed);
                const std::vector<float> normals = make_normals(std::size_t(w), 0.2, seed + 7);
                ++seed;
                const Layout lp = lay_out(points, w, 1, pf, 0);
                const Layout ln = lay_out(normals, w, 1, nf, 0);
                std::vector<std::uint32_t> expected(kQuantWords * std::size_t(w), 0xabababab);
                std::vector<std::uint32_t> actual(kQuantWords * std::size_t(w), 0xcdcdcdcd);
                for (std::size_t x = 0; x < std::size_t(w); ++x) {
                    const float* p = &lp.floats[x * pf];
                    const float* n = &ln.floats[x * nf];
                    const PyrQuant q = pixel::pyr_quantize(p[0], p[1], p[2], n[0], n[1], n[2]);
                    ::pyrseg::cpu::store_quant(expected.data() + kQuantWords * x, q.qx, q.qy, q.qz, q.valid, p[2]);
                }
                k.quantize_row(lp.floats.data(), pf, ln.floats.data(), nf, std::uint32_t(w), actual.data());
                const std::string diff =
                    first_difference(actual.data(), expected.data(), actual.size() * sizeof(std::uint32_t),
                                     kQuantWords * sizeof(std::uint32_t));
                ASSERT_EQ(diff, "") << "width " << w << " point stride " << pf << " normal stride " << nf;
            }
        }
    }
}

// ---- The fused front end's rows (simd::PointRow, simd::QuantRow)

using GuardedFloats = GuardedArray<float>;

// A layout's floats up to its last point's third, all a cloud must hold.
std::vector<float> cloud_floats(const Layout& l, int w, int h) {
    const std::size_t used = (std::size_t(h) - 1) * l.row_floats + (std::size_t(w) - 1) * l.point_floats + 3;
    return {l.floats.begin(), l.floats.begin() + std::ptrdiff_t(used)};
}

// Rows of the fused front end with storage of their own, w wide, every element junk at first.
struct RowStore {
    std::vector<float> floats;
    std::vector<std::int32_t> ints;
    std::vector<simd::PointRow> points;
    std::vector<simd::QuantRow> quant;

    RowStore(std::size_t rows, std::uint32_t w) : floats(4 * rows * w, -555.0f), ints(9 * rows * w, 0x5a5a5a5a) {
        float* f = floats.data();
        std::int32_t* i = ints.data();
        const auto next_float = [&] { return std::exchange(f, f + w); };
        const auto next_int = [&] { return std::exchange(i, i + w); };
        for (std::size_t r = 0; r < rows; ++r) {
            simd::PointRow p;
            p.x = next_float();
            p.y = next_float();
            p.z = next_float();
            p.valid = next_int();
            points.push_back(p);
            simd::QuantRow q;
            for (std::int32_t*& c : q.q) c = next_int();
            q.valid = next_int();
            q.z = next_float();
            for (std::int32_t*& s : q.sum) s = next_int();
            quant.push_back(q);
        }
    }
};

std::uint32_t bits_of(float f) {
    std::uint32_t b = 0;
    std::memcpy(&b, &f, sizeof b);
    return b;
}

// The first difference between a split row and its points (`stride` floats apart), or "".
std::string split_difference(const float* points, std::size_t stride, std::uint32_t w, const simd::PointRow& row) {
    for (std::size_t x = 0; x < w; ++x) {
        const float* p = points + x * stride;
        const std::int32_t valid = pixel::pyr_point_valid(p[0], p[1], p[2]) != 0 ? -1 : 0;
        if (bits_of(row.x[x]) != bits_of(p[0]) || bits_of(row.y[x]) != bits_of(p[1]) ||
            bits_of(row.z[x]) != bits_of(p[2]) || row.valid[x] != valid) {
            return "point " + std::to_string(x);
        }
    }
    return "";
}

// The first difference between an unpacked row and the w pixels whose store_quant words are `words` (QuantRow's
// contract: qn and depth of the valid ones, +infinity for the depth of the others, the sums), or "".
std::string unpacked_difference(const std::uint32_t* words, std::uint32_t w, const simd::QuantRow& row) {
    std::vector<std::int32_t> fields[4];
    for (std::vector<std::int32_t>& f : fields) f.assign(w, 0);
    for (std::size_t x = 0; x < w; ++x) {
        const std::uint32_t valid = words[kQuantWords * x + 1] >> 16;
        for (int c = 0; c < 3; ++c) {
            fields[c][x] = valid != 0 ? ::pyrseg::cpu::quant_component(words, x, c) : 0;
            if (row.q[c][x] != fields[c][x]) return "qn " + std::to_string(c) + " of pixel " + std::to_string(x);
        }
        fields[3][x] = std::int32_t(valid);
        if (row.valid[x] != fields[3][x]) return "validity of pixel " + std::to_string(x);
        const float z = valid != 0 ? from_bits(words[kQuantWords * x + 2]) : kInf;
        if (bits_of(row.z[x]) != bits_of(z)) return "depth of pixel " + std::to_string(x);
    }
    for (std::size_t x = 1; x + 1 < w; ++x) {
        for (int f = 0; f < 4; ++f) {
            if (row.sum[f][x] != fields[f][x - 1] + fields[f][x] + fields[f][x + 1]) {
                return "sum " + std::to_string(f) + " of pixel " + std::to_string(x);
            }
        }
    }
    return "";
}

// split_points_row against the points and pyr_point_valid, on clouds that end at their last point's third float
// (the padding of PCL's points is never read past it).
TEST_P(CpuSimdRows, SplitPointsMatchTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::uint32_t seed = 200;
    for (const int w : {1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 33, 64, 65, 131, 1000}) {
        for (const std::size_t pf : {std::size_t{3}, std::size_t{4}, std::size_t{7}}) {
            const std::vector<float> packed = make_points(w, 1, seed % 2 == 0 ? 1.0f : 1e-38f, 0.2, seed);
            ++seed;
            const GuardedFloats cloud(cloud_floats(lay_out(packed, w, 1, pf, 0), w, 1));
            RowStore store(1, std::uint32_t(w));
            k.split_points_row(cloud.data(), pf, std::uint32_t(w), store.points[0]);
            ASSERT_EQ(split_difference(cloud.data(), pf, std::uint32_t(w), store.points[0]), "")
                << "width " << w << " stride " << pf;
        }
    }
}

// normals_quant_row, on rows split by split_points_row, against pyr_normal_q and pyr_quantize pixel by pixel:
// normals, quantize's words, validity bytes and the unpacked row, every size, radius, scale and layout.
TEST_P(CpuSimdRows, FusedNormalsMatchTheSharedFunctions) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::uint32_t seed = 300;
    std::size_t defined = 0;
    std::size_t pixels = 0;
    for (const Size s : kSizes) {
        for (const int r : {1, 2, 5, 40}) {
            for (const float scale : {1.0f, 1e30f, 1e-38f}) {
                for (const std::size_t pf : {std::size_t{3}, std::size_t{4}, std::size_t{7}}) {
                    const double specials = seed % 3 == 0 ? 0.0 : 0.08;
                    const bool all_outputs = seed % 2 == 0;
                    const std::vector<float> packed = make_points(s.w, s.h, scale, specials, seed++);
                    const Layout l = lay_out(packed, s.w, s.h, pf, pf == 3 ? 0 : 5);
                    const GuardedFloats cloud(cloud_floats(l, s.w, s.h));
                    PassContext c;
                    c.points = cloud.data();
                    c.point_floats = l.point_floats;
                    c.row_floats = l.row_floats;
                    const auto w = std::uint32_t(s.w);
                    const auto h = std::uint32_t(s.h);
                    const auto ur = std::uint32_t(r);
                    const std::size_t pixel_count = std::size_t(w) * h;
                    std::vector<float> expected_normals(3 * pixel_count);
                    std::vector<std::uint32_t> expected_words(kQuantWords * pixel_count);
                    std::vector<std::uint8_t> expected_valid(pixel_count);
                    for (std::uint32_t y = 0; y < h; ++y) {
                        for (std::uint32_t x = 0; x < w; ++x) {
                            const std::size_t i = std::size_t(y) * w + x;
                            const PyrIVec3 q = pixel::pyr_normal_q(c, w, h, x, y, ur);
                            float* n = &expected_normals[3 * i];
                            n[0] = float(q.x) * PYR_NORMAL_UNIT;
                            n[1] = float(q.y) * PYR_NORMAL_UNIT;
                            n[2] = float(q.z) * PYR_NORMAL_UNIT;
                            const float* p = c.points + y * c.row_floats + x * c.point_floats;
                            const PyrQuant v = pixel::pyr_quantize(p[0], p[1], p[2], n[0], n[1], n[2]);
                            ::pyrseg::cpu::store_quant(&expected_words[kQuantWords * i], v.qx, v.qy, v.qz, v.valid,
                                                       p[2]);
                            expected_valid[i] = std::uint8_t(v.valid);
                            defined += v.valid;
                        }
                    }
                    pixels += pixel_count;
                    RowStore store(h, w);
                    for (std::uint32_t y = 0; y < h; ++y) {
                        k.split_points_row(c.points + y * c.row_floats, pf, w, store.points[y]);
                        ASSERT_EQ(split_difference(c.points + y * c.row_floats, pf, w, store.points[y]), "");
                    }
                    std::vector<float> normals(3 * pixel_count, 99.0f);
                    std::vector<std::uint32_t> words(kQuantWords * pixel_count, 0xcdcdcdcd);
                    std::vector<std::uint8_t> valid(pixel_count, 0x77);
                    // Reading ahead anywhere in the cloud changes nothing.
                    simd::ReadAhead ahead;
                    ahead.at[0] = cloud.data();
                    ahead.bytes = cloud_floats(l, s.w, s.h).size() * sizeof(float);
                    for (std::uint32_t y = 0; y < h; ++y) {
                        const simd::PointRow& row = store.points[y];
                        const simd::PointRow& up = y >= ur ? store.points[y - ur] : row;
                        const simd::PointRow& down = y + ur < h ? store.points[y + ur] : row;
                        const std::size_t i = std::size_t(y) * w;
                        k.normals_quant_row(c, up, row, down, w, h, y, ur, all_outputs ? &normals[3 * i] : nullptr,
                                            all_outputs ? &words[kQuantWords * i] : nullptr,
                                            all_outputs ? &valid[i] : nullptr, store.quant[y], ahead);
                        ASSERT_EQ(unpacked_difference(&expected_words[kQuantWords * i], w, store.quant[y]), "")
                            << s.w << "x" << s.h << " r=" << r << " scale=" << scale << " stride=" << pf << " row "
                            << y;
                    }
                    if (!all_outputs) continue;
                    ASSERT_EQ(first_difference(normals.data(), expected_normals.data(), normals.size() * sizeof(float),
                                               3 * sizeof(float)),
                              "")
                        << s.w << "x" << s.h << " r=" << r << " scale=" << scale << " stride=" << pf;
                    ASSERT_EQ(
                        first_difference(words.data(), expected_words.data(), words.size() * sizeof(std::uint32_t),
                                         kQuantWords * sizeof(std::uint32_t)),
                        "")
                        << s.w << "x" << s.h << " r=" << r << " scale=" << scale << " stride=" << pf;
                    ASSERT_EQ(first_difference(valid.data(), expected_valid.data(), valid.size(), 1), "")
                        << s.w << "x" << s.h << " r=" << r << " scale=" << scale << " stride=" << pf;
                }
            }
        }
    }
    EXPECT_GT(defined, pixels / 4) << "too few pixels with a normal to test much";
}

// quantize_quant_row against pyr_quantize: quantize's words, validity bytes and the unpacked row, on special points
// and normals, ties, components past +-1 and layouts (clouds that end at their last point's third float).
TEST_P(CpuSimdRows, FusedQuantizeMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::uint32_t seed = 400;
    for (const int w : {1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 18, 31, 33, 64, 65, 131, 1000}) {
        for (const std::size_t pf : {std::size_t{3}, std::size_t{4}, std::size_t{12}}) {
            for (const std::size_t nf : {std::size_t{3}, std::size_t{4}, std::size_t{5}}) {
                const bool all_outputs = seed % 2 == 0;
                const std::vector<float> points = make_points(w, 1, seed % 2 == 0 ? 1.0f : 1e-38f, 0.2, seed);
                const std::vector<float> normals = make_normals(std::size_t(w), 0.2, seed + 7);
                ++seed;
                const GuardedFloats lp(cloud_floats(lay_out(points, w, 1, pf, 0), w, 1));
                const GuardedFloats ln(cloud_floats(lay_out(normals, w, 1, nf, 0), w, 1));
                std::vector<std::uint32_t> expected(kQuantWords * std::size_t(w), 0xabababab);
                std::vector<std::uint8_t> expected_valid(std::size_t(w), 0);
                for (std::size_t x = 0; x < std::size_t(w); ++x) {
                    const float* p = lp.data() + x * pf;
                    const float* n = ln.data() + x * nf;
                    const PyrQuant q = pixel::pyr_quantize(p[0], p[1], p[2], n[0], n[1], n[2]);
                    ::pyrseg::cpu::store_quant(expected.data() + kQuantWords * x, q.qx, q.qy, q.qz, q.valid, p[2]);
                    expected_valid[x] = std::uint8_t(q.valid);
                }
                std::vector<std::uint32_t> actual(kQuantWords * std::size_t(w), 0xcdcdcdcd);
                std::vector<std::uint8_t> valid(std::size_t(w), 0x77);
                RowStore store(1, std::uint32_t(w));
                k.quantize_quant_row(lp.data(), pf, ln.data(), nf, std::uint32_t(w),
                                     all_outputs ? actual.data() : nullptr, all_outputs ? valid.data() : nullptr,
                                     store.quant[0]);
                ASSERT_EQ(unpacked_difference(expected.data(), std::uint32_t(w), store.quant[0]), "")
                    << "width " << w << " point stride " << pf << " normal stride " << nf;
                if (!all_outputs) continue;
                ASSERT_EQ(first_difference(actual.data(), expected.data(), actual.size() * sizeof(std::uint32_t),
                                           kQuantWords * sizeof(std::uint32_t)),
                          "")
                    << "width " << w << " point stride " << pf << " normal stride " << nf;
                ASSERT_EQ(first_difference(valid.data(), expected_valid.data(), valid.size(), 1), "")
                    << "width " << w << " point stride " << pf << " normal stride " << nf;
            }
        }
    }
}

// metric_quant_row against pyr_metric_fillable on the same pixels made into points and normals (qn / 2^13, which
// quantizes back to qn; a tiny normal for a valid qn of 0, none for a pixel that is not valid) and quantized by
// quantize_quant_row, a row at a time as the fused front end does; the expected bytes come from pyr_quantize's words
// of the same points and normals (a pixel whose depth is not a valid point's is then not valid either).
void check_fused_metric(const simd::VectorRows& k, std::uint32_t w, std::uint32_t h,
                        const std::vector<QuantPixel>& quant, std::int32_t tc, float dt) {
    std::vector<float> points(3 * quant.size());
    std::vector<float> normals(3 * quant.size());
    std::vector<std::uint32_t> words(kQuantWords * quant.size());
    for (std::size_t i = 0; i < quant.size(); ++i) {
        const QuantPixel& p = quant[i];
        float* point = &points[3 * i];
        float* normal = &normals[3 * i];
        point[0] = 0.5f;
        point[1] = -0.25f;
        point[2] = p.z;
        for (int c = 0; c < 3; ++c) normal[c] = p.valid != 0 ? float(p.q[c]) / 8192.0f : 0.0f;
        if (p.valid != 0 && p.q[0] == 0 && p.q[1] == 0 && p.q[2] == 0) normal[0] = 1e-7f;
        const PyrQuant q = pixel::pyr_quantize(point[0], point[1], point[2], normal[0], normal[1], normal[2]);
        ::pyrseg::cpu::store_quant(&words[kQuantWords * i], q.qx, q.qy, q.qz, q.valid, point[2]);
    }
    PassContext c;
    c.quant = words.data();
    RowStore store(h, w);
    for (std::uint32_t y = 0; y < h; ++y) {
        const std::size_t i = std::size_t(y) * w;
        k.quantize_quant_row(&points[3 * i], 3, &normals[3 * i], 3, w, nullptr, nullptr, store.quant[y]);
    }
    std::vector<std::uint8_t> expected(quant.size());
    std::vector<std::uint8_t> actual(quant.size(), 0x55);
    simd::ReadAhead ahead;  // reading ahead anywhere in the points changes nothing
    ahead.at[0] = points.data();
    ahead.at[1] = normals.data();
    ahead.bytes = points.size() * sizeof(float);
    for (std::uint32_t y = 0; y < h; ++y) {
        for (std::uint32_t x = 0; x < w; ++x) {
            expected[std::size_t(y) * w + x] = std::uint8_t(pixel::pyr_metric_fillable(c, w, h, x, y, tc, dt));
        }
        k.metric_quant_row(y > 0 ? &store.quant[y - 1] : nullptr, store.quant[y],
                           y + 1 < h ? &store.quant[y + 1] : nullptr, w, tc, dt, actual.data() + std::size_t(y) * w,
                           ahead);
    }
    const std::string diff = first_difference(actual.data(), expected.data(), actual.size(), 1);
    EXPECT_EQ(diff, "") << "fused, " << w << "x" << h << " tc=" << tc << " dt=" << dt;
}

// pyr_metric_fillable against metric_row over a whole image (and against metric_quant_row: check_fused_metric);
// returns how many pixels are fillable.
int check_metric(const simd::VectorRows& k, std::uint32_t w, std::uint32_t h, const std::vector<QuantPixel>& quant,
                 std::int32_t tc, float dt) {
    check_fused_metric(k, w, h, quant, tc, dt);
    const std::vector<std::uint32_t> words = to_words(quant);
    PassContext c;
    c.quant = words.data();
    std::vector<std::uint8_t> expected(quant.size());
    std::vector<std::uint8_t> actual(quant.size(), 0x55);
    int fillable = 0;
    for (std::uint32_t y = 0; y < h; ++y) {
        for (std::uint32_t x = 0; x < w; ++x) {
            expected[std::size_t(y) * w + x] = std::uint8_t(pixel::pyr_metric_fillable(c, w, h, x, y, tc, dt));
            fillable += expected[std::size_t(y) * w + x];
        }
        k.metric_row(c, w, h, y, tc, dt, actual.data() + std::size_t(y) * w);
    }
    const std::string diff = first_difference(actual.data(), expected.data(), actual.size(), 1);
    EXPECT_EQ(diff, "") << w << "x" << h << " tc=" << tc << " dt=" << dt;
    return fillable;
}

// Random quantized pixels (random validity, qn, depths of every magnitude) and thresholds over their whole range.
TEST_P(CpuSimdRows, MetricMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> qn(-8192, 8192);
    std::uniform_int_distribution<int> near(-40, 40);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const std::int32_t tcs[] = {-268435456, 67108864, 0, 60000000, -5000000, 67100000};
    const float dts[] = {0.0f, 1.0f, 5.0f, kDenorm, 1e-38f, 3e38f, 0.25f};
    int round = 0;
    int fillable = 0;
    std::size_t pixels = 0;
    for (const Size s : kSizes) {
        for (const std::int32_t tc : tcs) {
            const float dt = dts[std::size_t(round++) % std::size(dts)];
            const auto w = std::uint32_t(s.w);
            const auto h = std::uint32_t(s.h);
            std::vector<QuantPixel> quant(std::size_t(w) * h);
            const bool smooth = round % 2 == 0;  // nearly parallel normals, so that the curvature test passes too
            for (QuantPixel& p : quant) {
                p.valid = unit(rng) < 0.85f ? 1 : 0;
                if (smooth) {
                    p.q[0] = std::int16_t(near(rng));
                    p.q[1] = std::int16_t(near(rng));
                    p.q[2] = std::int16_t(-8150 + near(rng));
                } else {
                    for (std::int16_t& c : p.q) c = std::int16_t(qn(rng));
                }
                const float u = unit(rng);
                p.z = u < 0.05f ? kDenorm * float(rng() % 1000)
                                : (u < 0.1f ? 3e38f * unit(rng) : 1000.0f + 6.0f * unit(rng));
                if (p.valid == 0 && u < 0.3f) p.z = kNaN;  // invalid pixels may hold anything
            }
            fillable += check_metric(k, w, h, quant, tc, dt);
            pixels += quant.size();
            if (::testing::Test::HasFailure()) return;
        }
    }
    EXPECT_GT(fillable, int(pixels / 20)) << "too few fillable pixels to test much";
    EXPECT_LT(fillable, int(pixels / 2)) << "too many fillable pixels to test much";
}

// The thresholds' ties: s == k * tc (fillable) and dmax - dmin == dt (fillable), on many pixels.
TEST_P(CpuSimdRows, MetricTiesMatchTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const float depths[] = {1000.0f, 1001.0f, 1003.0f, 1000.5f};
    for (const Size s : kSizes) {
        const auto w = std::uint32_t(s.w);
        const auto h = std::uint32_t(s.h);
        std::vector<QuantPixel> quant(std::size_t(w) * h);
        for (QuantPixel& p : quant) {
            p.valid = unit(rng) < 0.9f ? 1 : 0;
            p.q[0] = 0;
            p.q[1] = std::int16_t(unit(rng) < 0.2f ? 1 : 0);
            p.q[2] = -8150;
            p.z = depths[rng() % std::size(depths)];
        }
        for (const float dt : {0.0f, 0.5f, 1.0f, 2.0f, 2.5f, 3.0f}) {
            for (const std::int32_t tc : {8150 * 8150, 8150 * 8150 - 1, 8150 * 8150 + 1}) {
                check_metric(k, w, h, quant, tc, dt);
                if (::testing::Test::HasFailure()) return;
            }
        }
    }
}

// pyr_mip_texel against mip_row, called as the CPU backend calls it, on random mask bytes (all bits set at random:
// only bit 0 counts).
TEST_P(CpuSimdRows, MipMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(9);
    for (int cw = 1; cw <= 140; cw += (cw < 40 ? 1 : 13)) {
        for (const int ch : {1, 2, 3, 6, 7}) {
            const PyrLevel child = pyr_level(std::uint32_t(cw), std::uint32_t(ch), 3);
            const std::uint32_t pw = (child.width + 1) / 2;
            const std::uint32_t ph = (child.height + 1) / 2;
            std::vector<std::uint8_t> mask(3 + std::size_t(cw) * std::size_t(ch));
            for (std::uint8_t& m : mask) m = std::uint8_t(rng() % 4 == 0 ? rng() : 0xff);
            PassContext c;
            c.mask = mask.data();
            std::vector<std::uint8_t> expected(std::size_t(pw) * ph);
            std::vector<std::uint8_t> actual(expected.size(), 0x77);
            for (std::uint32_t y = 0; y < ph; ++y) {
                for (std::uint32_t x = 0; x < pw; ++x) {
                    expected[std::size_t(y) * pw + x] = std::uint8_t(pixel::pyr_mip_texel(c, child, x, y));
                }
                const std::size_t cy = 2 * std::size_t(y);
                const std::uint8_t* top =
                    cy + 1 < child.height ? mask.data() + child.offset + cy * child.width : nullptr;
                k.mip_row(top, child.width, pw, actual.data() + std::size_t(y) * pw);
            }
            const std::string diff = first_difference(actual.data(), expected.data(), actual.size(), 1);
            ASSERT_EQ(diff, "") << "child " << cw << "x" << ch;
        }
    }
}

// pyr_depth_point against depth_row, both formats, on samples that hit every branch (no data, special floats,
// products that underflow, overflow or turn subnormal), for rows aligned and starting at an odd byte.
TEST_P(CpuSimdRows, DepthRowMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(13);
    const float special[] = {0.0f,  -0.0f, kDenorm, -kDenorm, kMin, -kMin,  kNaN,  -kNaN,   kInf,
                             -kInf, kMax,  1.0f,    -1.0f,    0.5f, 1e-30f, 1e30f, 3.0e38f, 65535.0f};
    // Scales: millimetres to millimetres, to metres, and two that push products out of the normal range.
    const float scales[] = {1.0f, 0.001f, 1e35f, 1.5e-38f};
    for (const std::uint32_t format : {std::uint32_t{PYR_DEPTH_U16}, std::uint32_t{PYR_DEPTH_F32}}) {
        for (const float scale : scales) {
            for (const std::uint32_t w : {1u, 3u, 15u, 16u, 17u, 40u, 131u}) {
                for (const std::size_t offset : {std::size_t{0}, std::size_t{1}}) {
                    const std::size_t sample = format == PYR_DEPTH_U16 ? 2 : 4;
                    std::vector<unsigned char> bytes(offset + sample * w);
                    std::vector<float> ku(w);
                    for (std::uint32_t x = 0; x < w; ++x) {
                        if (format == PYR_DEPTH_U16) {
                            const auto v = std::uint16_t(rng() % 5 == 0 ? (rng() % 3 == 0 ? 0 : 65535) : rng());
                            std::memcpy(bytes.data() + offset + 2 * x, &v, 2);
                        } else {
                            const float v = rng() % 3 == 0 ? special[rng() % std::size(special)]
                                                           : std::uniform_real_distribution<float>(0.0f, 5000.0f)(rng);
                            std::memcpy(bytes.data() + offset + 4 * x, &v, 4);
                        }
                        // Slopes of both signs, zero, and tiny ones whose products are subnormal.
                        const std::uint32_t pick = rng() % 6;
                        ku[x] = pick == 0
                                    ? 0.0f
                                    : (pick == 1 ? -1e-38f
                                                 : (pick == 2 ? 3e-39f : float(int(rng() % 2001) - 1000) / 700.0f));
                    }
                    for (const float kv : {-0.7f, 0.0f, 1e-39f}) {
                        std::vector<float> expected(3 * std::size_t(w));
                        std::vector<float> actual(expected.size(), 7.0f);
                        for (std::uint32_t x = 0; x < w; ++x) {
                            std::uint32_t value = 0;
                            if (format == PYR_DEPTH_U16) {
                                std::uint16_t d = 0;
                                std::memcpy(&d, bytes.data() + offset + 2 * x, 2);
                                value = d;
                            } else {
                                std::memcpy(&value, bytes.data() + offset + 4 * x, 4);
                            }
                            const PyrFVec3 p = pixel::pyr_depth_point(value, format, scale, ku[x], kv);
                            expected[3 * x] = p.x;
                            expected[3 * x + 1] = p.y;
                            expected[3 * x + 2] = p.z;
                        }
                        k.depth_row(bytes.data() + offset, format, w, scale, ku.data(), kv, actual.data());
                        const std::string diff =
                            first_difference(actual.data(), expected.data(), actual.size() * 4, 12);
                        ASSERT_EQ(diff, "") << "format " << format << " scale " << scale << " width " << w << " offset "
                                            << offset << " kv " << kv;
                    }
                }
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Targets, CpuSimdRows, ::testing::ValuesIn(target_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

// ---- Whole segmentations

// Given normals at lengths from 0.985 to 1.02 (components past +-1 clamp when quantized), so that most pixels still
// pass the curvature test while no quantized component is the one of the unit normal; a few much shorter or longer.
std::vector<float> lengthen(std::vector<float> normals, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> length(0.985f, 1.02f);
    for (std::size_t i = 0; i < normals.size(); i += 3) {
        const float f = i % 97 == 0 ? 0.3f : (i % 89 == 0 ? 3.7f : length(rng));
        for (std::size_t c = 0; c < 3; ++c) normals[i + c] *= f;
    }
    return normals;
}

std::vector<TestFrame> frames() {
    std::vector<TestFrame> out;
    const Size sizes[] = {{131, 97}, {67, 45}, {1, 1}, {2, 3}, {17, 300}, {33, 1}, {1, 29}, {200, 7}};
    std::uint32_t seed = 11;
    for (const Size s : sizes) {
        for (const int radius : {1, 2, 3, 5}) {
            for (const double unit_mm : {1.0, 1000.0}) {
                synthetic::SceneOptions o;
                o.width = s.w;
                o.height = s.h;
                o.seed = seed++;
                o.object_count = 6;
                o.threads = 1;
                const synthetic::Scene scene = synthetic::generate(o);
                TestFrame f;
                f.w = s.w;
                f.h = s.h;
                f.points = scene.points;
                if (unit_mm != 1.0) {
                    for (float& v : f.points) v *= 0.001f;  // metres
                }
                f.params.unit_mm = unit_mm;
                f.params.normal_radius = radius;
                const bool given = radius == 2;
                if (given) f.normals = lengthen(scene.normals, seed);
                std::ostringstream name;
                name << s.w << "x" << s.h << "_r" << radius << "_unit" << unit_mm << (given ? "_given" : "_estimated");
                f.name = name.str();
                out.push_back(std::move(f));
            }
        }
    }
    // Clouds with special values and extreme magnitudes, estimated and given (non-unit, special) normals.
    const float scales[] = {1.0f, 1e30f, 1e-38f};
    for (const float scale : scales) {
        for (const Size s : {Size{131, 97}, Size{67, 45}, Size{17, 300}, Size{2, 3}}) {
            for (const bool given : {false, true}) {
                TestFrame f;
                f.w = s.w;
                f.h = s.h;
                f.points = make_points(s.w, s.h, scale, 0.03, seed);
                if (given) {  // facing the camera, tilted a little, at lengths other than 1, a few special
                    std::mt19937 rng(seed);
                    std::uniform_real_distribution<float> tilt(-0.05f, 0.05f);
                    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
                    f.normals.resize(f.points.size());
                    for (std::size_t i = 0; i < f.normals.size(); i += 3) {
                        f.normals[i] = tilt(rng);
                        f.normals[i + 1] = tilt(rng);
                        f.normals[i + 2] = -1.0f;
                        for (std::size_t c = 0; c < 3; ++c) {
                            if (unit(rng) < 0.01f) f.normals[i + c] = special_value(rng);
                        }
                    }
                    f.normals = lengthen(f.normals, seed);
                }
                ++seed;
                f.params.normal_radius = 1 + int(seed % 3);
                f.params.dt = 30.0 * double(scale);
                std::ostringstream name;
                name << "special_" << s.w << "x" << s.h << "_scale" << scale << (given ? "_given" : "_estimated");
                f.name = name.str();
                out.push_back(std::move(f));
            }
        }
    }
    return out;
}

class CpuSimdFrames : public ::testing::TestWithParam<std::string> {};

TEST_P(CpuSimdFrames, MatchTheScalarPathAndTheReference) {
    const std::string& mode = GetParam();
    std::uint32_t segments = 0;
    for (const TestFrame& f : frames()) {
        SCOPED_TRACE(f.name);
        const pyrseg_ref::Output ref = pyrseg_ref::segment(
            f.points.data(), f.normals.empty() ? nullptr : f.normals.data(), f.w, f.h, to_reference(f.params));
        ASSERT_TRUE(ref.ok) << ref.error;
        segments += ref.segment_count;
        const Result scalar = segment_on_target("scalar", f, everything());
        const Result r = segment_on_target(mode, f, everything());
        EXPECT_TRUE(same_bytes("normals", r.normals, ref.normals, f.w, 3));
        EXPECT_TRUE(same_bytes("fillable mask", r.fillable_mask, ref.fillable, f.w));
        EXPECT_TRUE(same_bytes("raw labels", r.raw_labels, ref.raw_labels, f.w));
        EXPECT_TRUE(same_bytes("labels", r.labels, ref.labels, f.w));
        EXPECT_TRUE(same_segments(r.segments, ref.segments));
        EXPECT_TRUE(same_segments(scalar.segments, ref.segments)) << "the scalar path's statistics";
        EXPECT_TRUE(same_bytes("normals (scalar path)", r.normals, scalar.normals, f.w, 3));
        EXPECT_TRUE(same_bytes("fillable mask (scalar path)", r.fillable_mask, scalar.fillable_mask, f.w));
        EXPECT_TRUE(same_bytes("labels (scalar path)", r.labels, scalar.labels, f.w));
        if (::testing::Test::HasFailure()) return;
    }
    EXPECT_GT(segments, 200u) << "the frames must have segments for the labels to say much";
}

// A strided cloud (PCL's padded PointXYZ, rows padded) reads like the packed one on every target.
TEST_P(CpuSimdFrames, StridedCloudsMatchTheReference) {
    synthetic::SceneOptions o;
    o.width = 97;
    o.height = 61;
    o.seed = 3;
    o.threads = 1;
    const synthetic::Scene scene = synthetic::generate(o);
    const Layout l = lay_out(scene.points, o.width, o.height, 4, 3);
    const Layout ln = lay_out(scene.normals, o.width, o.height, 4, 3);
    for (const bool given : {false, true}) {
        const pyrseg_ref::Output ref = pyrseg_ref::segment(scene.points.data(), given ? scene.normals.data() : nullptr,
                                                           o.width, o.height, to_reference({}));
        ASSERT_TRUE(ref.ok);
        const ScopedEnv env("PYRSEG_CPU_SIMD", GetParam());
        Segmenter segmenter(o.width, o.height, {}, "cpu", everything());
        CloudView view;
        view.points = l.floats.data();
        view.normals = given ? ln.floats.data() : nullptr;
        view.width = o.width;
        view.height = o.height;
        view.point_stride = 4;
        view.row_stride = std::size_t(o.width) + 3;
        Result r;
        segmenter.segment(view, r);
        EXPECT_TRUE(same_bytes("normals", r.normals, ref.normals, o.width, 3));
        EXPECT_TRUE(same_bytes("fillable mask", r.fillable_mask, ref.fillable, o.width));
        EXPECT_TRUE(same_bytes("labels", r.labels, ref.labels, o.width));
    }
}

INSTANTIATE_TEST_SUITE_P(Targets, CpuSimdFrames, ::testing::ValuesIn(simd::accepted_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

TEST(CpuSimd, ListsTheScalarPathAndTheTargets) {
    const std::vector<std::string> names = simd::accepted_names();
    ASSERT_GE(names.size(), 2u) << "at least one Highway target (its one-lane fallback) must be available";
    EXPECT_EQ(names.front(), "scalar");
    for (const std::string& name : names) std::cout << "[ PYRSEG_CPU_SIMD ] " << name << "\n";
}

TEST(CpuSimd, AnUnknownTargetIsAnError) {
    const ScopedEnv env("PYRSEG_CPU_SIMD", "no_such_target");
    try {
        Segmenter segmenter(16, 16, {}, "cpu");
        FAIL() << "PYRSEG_CPU_SIMD=no_such_target was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
        EXPECT_NE(std::string(e.what()).find("scalar"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace pyrseg::test
