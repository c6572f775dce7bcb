// The CPU backend's vector row passes (cpu_simd.hpp), compiled once per Highway target: foreach_target.h includes
// this file again for each target, with HWY_NAMESPACE naming that target's namespace, and HWY_EXPORT /
// HWY_DYNAMIC_DISPATCH pick the best one at run time.
//
// Bit-identity with the shared scalar functions (shaders/pyr_*.h), which every backend and the reference match:
//  - every float operation is the scalar code's: IEEE add, sub, mul, div and sqrt are correctly rounded on every
//    Highway target; no MulAdd (the project compiles with -ffp-contract=off); Min/Max, in the lanes whose result is
//    used, only on operands that are finite or +infinity, never NaN or zeros of both signs (they then equal the
//    scalar code's comparisons); Round is round-half-to-even like nearbyint in the default rounding mode;
//  - integer arithmetic is the scalar code's, in lanes of the same width; every bound the scalar code states (no
//    int32 overflow) holds in every lane, including lanes whose result is thrown away (those are kept in range on
//    purpose, so that Highway's one-lane target, which uses plain C++ integers, has no undefined behaviour);
//  - the two operations with no exact vector instruction, pyr_isqrt and the division of pyr_unit_component, are
//    computed as a float estimate proven to be within 1 of the exact integer result, then corrected by one integer
//    comparison each way: the exact result, which is what the scalar code computes (the proofs are at
//    isqrt_floor and unit_component below);
//  - pixels whose neighbour tests differ from the interior's (image borders) call the shared scalar function;
//  - subnormals are IEEE on every target used (x86 without FTZ/DAZ, AArch64 NEON and SVE with FPCR.FZ clear, as
//    Linux starts processes); 32-bit Arm NEON, which flushes them, is left out (registry below).
// tests/unit/test_cpu_simd.cpp checks every target this CPU runs against the scalar functions and the reference.
#include "backends/cpu/simd/cpu_simd.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "backends/cpu/cpu_kernels.hpp"
#include "pyrseg/error.hpp"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "backends/cpu/simd/cpu_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
// (foreach_target.h must come before highway.h)
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace pyrseg::cpu::simd {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MI = hn::Mask<DI>;

// The most lanes of any vector here; buffers on the stack are sized with it.
constexpr std::size_t kMaxLanes = hn::MaxLanes(DF());

// ---- Loads

// Components 0, 1, 2 of n = Lanes(df) points, the first at p, each `stride` floats after the one before.
HWY_INLINE void load_points(DF df, const float* HWY_RESTRICT p, std::size_t stride, VF& x, VF& y, VF& z) {
    if (stride == 3) {
        hn::LoadInterleaved3(df, p, x, y, z);
        return;
    }
    // Any other layout (PCL's padded points, interleaved normals, byte steps): lane by lane. Only the three floats
    // of each point are read, never a padding float past the last point of a row.
    HWY_ALIGN float buffer[3][kMaxLanes];
    const std::size_t n = hn::Lanes(df);
    for (std::size_t i = 0; i < n; ++i) {
        buffer[0][i] = p[i * stride];
        buffer[1][i] = p[i * stride + 1];
        buffer[2][i] = p[i * stride + 2];
    }
    x = hn::Load(df, buffer[0]);
    y = hn::Load(df, buffer[1]);
    z = hn::Load(df, buffer[2]);
}

// ---- Validity (shaders/pyr_validity.h), on the float bit patterns

HWY_INLINE MI is_finite(VI bits) {
    const DI di;
    const VI exponent_field = hn::Set(di, 0x7f800000);
    return hn::Ne(hn::And(bits, exponent_field), exponent_field);  // (bits >> 23) & 255 != 255
}

HWY_INLINE MI point_valid(VF x, VF y, VF z) {
    const DI di;
    const VI bz = hn::BitCast(di, z);
    return hn::And(hn::And(is_finite(hn::BitCast(di, x)), is_finite(hn::BitCast(di, y))),
                   hn::And(is_finite(bz), hn::Gt(bz, hn::Zero(di))));
}

HWY_INLINE MI normal_valid(VF x, VF y, VF z) {
    const DI di;
    const VI bx = hn::BitCast(di, x);
    const VI by = hn::BitCast(di, y);
    const VI bz = hn::BitCast(di, z);
    const VI magnitudes = hn::And(hn::Or(hn::Or(bx, by), bz), hn::Set(di, 0x7fffffff));
    return hn::And(hn::And(is_finite(bx), is_finite(by)), hn::And(is_finite(bz), hn::Ne(magnitudes, hn::Zero(di))));
}

// ---- The normals (shaders/pyr_normals.h)
// Triples of vectors are out-parameters, not structs: SVE's sizeless vectors cannot be members or array elements.

// pyr_fixed_exponent: the exponent field, 0 for 255.
HWY_INLINE VI fixed_exponent(VI bits) {
    const DI di;
    const VI e = hn::And(hn::ShiftRight<23>(bits), hn::Set(di, 255));
    return hn::IfThenZeroElse(hn::Eq(e, hn::Set(di, 255)), e);
}

// pyr_fixed_component. The shift 9 + max_exponent - e is at least 9 where it is used; it is clamped to 0..31
// (past 31 the 24-bit magnitude shifts to 0, as the scalar code's `shift > 31` returns, and lanes where it is not
// used must not shift by a negative or too large count).
HWY_INLINE VI fixed_component(VI bits, VI max_exponent) {
    const DI di;
    const DU du;
    const VI e = hn::And(hn::ShiftRight<23>(bits), hn::Set(di, 255));
    const MI zero = hn::Or(hn::Eq(e, hn::Zero(di)), hn::Eq(e, hn::Set(di, 255)));
    const VI shift = hn::Min(hn::Max(hn::Sub(hn::Add(hn::Set(di, 9), max_exponent), e), hn::Zero(di)), hn::Set(di, 31));
    const VU significand = hn::BitCast(du, hn::Or(hn::And(bits, hn::Set(di, 0x7fffff)), hn::Set(di, 0x800000)));
    const VI magnitude = hn::BitCast(di, hn::Shr(significand, hn::BitCast(du, shift)));
    const VI signed_magnitude = hn::IfThenElse(hn::Lt(bits, hn::Zero(di)), hn::Neg(magnitude), magnitude);
    return hn::IfThenZeroElse(zero, signed_magnitude);
}

// pyr_to_fixed: each |component| < 2^15, whatever the input.
HWY_INLINE void to_fixed(VF x, VF y, VF z, VI& fx, VI& fy, VI& fz) {
    const DI di;
    const VI bx = hn::BitCast(di, x);
    const VI by = hn::BitCast(di, y);
    const VI bz = hn::BitCast(di, z);
    const VI e = hn::Max(hn::Max(fixed_exponent(bx), fixed_exponent(by)), fixed_exponent(bz));
    fx = fixed_component(bx, e);
    fy = fixed_component(by, e);
    fz = fixed_component(bz, e);
}

// PYR_MSB(m) for 1 <= m < 2^31: the exponent of float(m), less one where rounding to float carried into the next
// power of two (m then has no bit at that position).
HWY_INLINE VI msb(VI m) {
    const DF df;
    const DI di;
    const DU du;
    const VI e = hn::Sub(hn::ShiftRight<23>(hn::BitCast(di, hn::ConvertTo(df, m))), hn::Set(di, 127));  // 0..31
    const MI carried = hn::RebindMask(di, hn::Eq(hn::Shr(hn::BitCast(du, m), hn::BitCast(du, e)), hn::Zero(du)));
    return hn::IfThenElse(carried, hn::Sub(e, hn::Set(di, 1)), e);
}

// pyr_shift_magnitude for -14 <= s <= 16 and |v| < 2^31 (|v| < 2^14 where s < 0).
HWY_INLINE VI shift_magnitude(VI v, VI s) {
    const DI di;
    const DU du;
    const VU a = hn::BitCast(du, hn::Abs(v));
    const VU right = hn::BitCast(du, hn::Max(s, hn::Zero(di)));
    const VU left = hn::BitCast(du, hn::Max(hn::Neg(s), hn::Zero(di)));
    const VI m = hn::BitCast(di, hn::Shr(hn::Shl(a, left), right));  // one of the two shifts is by 0
    return hn::IfThenElse(hn::Lt(v, hn::Zero(di)), hn::Neg(m), m);
}

// pyr_isqrt(n) = floor(sqrt(n)), for 2^28 <= n < 3 * 2^30 (the range of pyr_unit_normal_from_tangents: the largest
// |d| has its top bit at 14, so 2^28 <= n <= 3 * (2^15 - 1)^2).
// Estimate: t = n >> 2 < 3 * 2^28 converts from int32; e = 2 * sqrt(float(t)). float(t) and sqrt each round with
// relative error <= 2^-24 (the * 2 is exact), so e = 2 sqrt(t) (1 + h) with |h| < 2^-23, and
// 0 <= sqrt(n) - 2 sqrt(t) = (n - 4t) / (sqrt(n) + 2 sqrt(t)) <= 3 / 2^15. Hence |e - sqrt(n)| < 2^-13 + 2^16 * 2^-23
// < 1/100, and the truncation r0 of e is floor(sqrt(n)) - 1, floor(sqrt(n)) or floor(sqrt(n)) + 1. One step down
// where r^2 > n, then one step up where (r + 1)^2 <= n, leave exactly floor(sqrt(n)), the value the scalar loops
// reach. Every square is below (2^16 - 1)^2 < 2^32 (sqrt(n) < 56756), so the uint32 products and comparisons are exact.
// (Checked exhaustively too, over every n of the range: r0 is 1 above in 4862366 cases and never below, so the
// upward step, kept for the argument above, never changes a result.)
HWY_INLINE VU isqrt_floor(VU n) {
    const DF df;
    const DI di;
    const DU du;
    const VF t = hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<2>(n)));
    const VF e = hn::Mul(hn::Sqrt(t), hn::Set(df, 2.0f));
    VU r = hn::BitCast(du, hn::ConvertTo(di, e));  // truncation, e >= 0
    const VU one = hn::Set(du, 1u);
    r = hn::IfThenElse(hn::Gt(hn::Mul(r, r), n), hn::Sub(r, one), r);
    const VU r1 = hn::Add(r, one);
    return hn::IfThenElse(hn::Gt(hn::Mul(r1, r1), n), r, r1);  // (integer <= is not in every target)
}

// pyr_unit_component: q = floor(a / b) with a = (|d| << 14) + len and b = 2 len, sign of d, for 2^14 <= len and
// |d| <= len < 2^16 (len = isqrt(n) above; |d| <= len since d^2 <= n).
// Then a < 2^30 (exact in int32), 2^15 <= b < 2^17 (exact in float) and a / b = 8192 |d| / len + 1/2 <= 8192.5.
// Estimate: e = float(a) / float(b); float(a) and the division each round with relative error <= 2^-24, so
// |e - a/b| <= 8192.5 * (2^-23 + 2^-48) < 1/1000, and the truncation q0 of e is q - 1, q or q + 1. One step down
// where q0 * b > a, then one step up where (q0 + 1) * b <= a, leave exactly q = floor(a / b), the scalar code's
// integer division. The products are at most 8194 * 2^17 < 2^31. (Checked exhaustively too, over every len and |d|
// of the range: the estimate is never more than 1 away; it is 1 below in 777 and 1 above in 161717 of the
// 1188732928 cases, so both steps are needed.)
HWY_INLINE VI unit_component(VI d, VI len) {
    const DF df;
    const DI di;
    const VI a = hn::Add(hn::ShiftLeft<14>(hn::Abs(d)), len);
    const VI b = hn::Add(len, len);
    const VF e = hn::Div(hn::ConvertTo(df, a), hn::ConvertTo(df, b));
    VI q = hn::ConvertTo(di, e);  // truncation, e >= 0
    const VI one = hn::Set(di, 1);
    q = hn::IfThenElse(hn::Gt(hn::Mul(q, b), a), hn::Sub(q, one), q);
    const VI q1 = hn::Add(q, one);
    q = hn::IfThenElse(hn::Gt(hn::Mul(q1, b), a), q, q1);
    return hn::IfThenElse(hn::Lt(d, hn::Zero(di)), hn::Neg(q), q);
}

// pyr_unit_normal_from_tangents in two halves (the fused front end runs them as two loops over a few vectors, so that
// more of their long chains of dependent operations overlap). The first: the cross product with its largest
// component's top bit at 14 (d), and `some` where the result is not (0, 0, 0); `defined` clear where the scalar code
// returns (0, 0, 0) before it gets here.
HWY_INLINE void normal_direction(VI ux, VI uy, VI uz, VI vx, VI vy, VI vz, MI defined, VI& dx, VI& dy, VI& dz,
                                 MI& some) {
    const DI di;
    // |u|, |v| < 2^15: each product < 2^30, each difference < 2^31.
    const VI cx = hn::Sub(hn::Mul(uy, vz), hn::Mul(uz, vy));
    const VI cy = hn::Sub(hn::Mul(uz, vx), hn::Mul(ux, vz));
    const VI cz = hn::Sub(hn::Mul(ux, vy), hn::Mul(uy, vx));
    const VI m = hn::Max(hn::Max(hn::Abs(cx), hn::Abs(cy)), hn::Abs(cz));
    some = hn::And(defined, hn::Gt(m, hn::Zero(di)));
    // Lanes with m == 0 give (0, 0, 0); they compute with m = 1 (then d = 0, len = 0, taken as 1 below) so that
    // no lane shifts by an out-of-range count or divides by zero.
    const VI s = hn::Sub(msb(hn::Max(m, hn::Set(di, 1))), hn::Set(di, 14));
    dx = shift_magnitude(cx, s);
    dy = shift_magnitude(cy, s);
    dz = shift_magnitude(cz, s);
}

// The second half: q from d, toward the camera seen from the point P.
HWY_INLINE void normal_from_direction(VI dx, VI dy, VI dz, MI some, VF px, VF py, VF pz, VI& qx, VI& qy, VI& qz) {
    const DI di;
    const DU du;
    const VU n = hn::Add(hn::Add(hn::BitCast(du, hn::Mul(dx, dx)), hn::BitCast(du, hn::Mul(dy, dy))),
                         hn::BitCast(du, hn::Mul(dz, dz)));
    const VI len = hn::Max(hn::BitCast(di, isqrt_floor(n)), hn::Set(di, 1));
    const VI ex = unit_component(dx, len);
    const VI ey = unit_component(dy, len);
    const VI ez = unit_component(dz, len);
    // Toward the camera: q . F(P) < 0 (|q| <= 2^13, |F(P)| < 2^15: the dot fits int32).
    VI fx, fy, fz;  // NOLINT(readability-isolate-declaration)
    to_fixed(px, py, pz, fx, fy, fz);
    const VI dot = hn::Add(hn::Add(hn::Mul(ex, fx), hn::Mul(ey, fy)), hn::Mul(ez, fz));
    const MI flip = hn::Gt(dot, hn::Zero(di));
    qx = hn::IfThenElseZero(some, hn::IfThenElse(flip, hn::Neg(ex), ex));
    qy = hn::IfThenElseZero(some, hn::IfThenElse(flip, hn::Neg(ey), ey));
    qz = hn::IfThenElseZero(some, hn::IfThenElse(flip, hn::Neg(ez), ez));
}

void store_normal(const PyrIVec3& q, float* out) {
    out[0] = float(q.x) * PYR_NORMAL_UNIT;
    out[1] = float(q.y) * PYR_NORMAL_UNIT;
    out[2] = float(q.z) * PYR_NORMAL_UNIT;
}

// pyr_normal_q for n pixels, all with both horizontal neighbours inside the image, from their points (c) and those
// of their neighbours: right (x + r), left (x - r), up (y - r) and down (y + r), each with its validity (has_up /
// has_down clear where that row is outside the image); up to the first half of pyr_unit_normal_from_tangents
// (normal_direction), whose results are d and `some`.
HWY_INLINE void normal_direction_of(VF cx, VF cy, VF cz, MI center, VF rx, VF ry, VF rz, MI has_right, VF lx, VF ly,
                                    VF lz, MI has_left, VF ux, VF uy, VF uz, MI has_up, VF dx, VF dy, VF dz,
                                    MI has_down, VI& direction_x, VI& direction_y, VI& direction_z, MI& some) {
    const DF df;
    const MI defined = hn::And(center, hn::And(hn::Or(has_right, has_left), hn::Or(has_down, has_up)));
    // u = P(xa) - P(xb), v = P(ya) - P(yb): the neighbour where it is valid, else the pixel itself.
    const auto right = hn::RebindMask(df, has_right);
    const auto left = hn::RebindMask(df, has_left);
    const auto below = hn::RebindMask(df, has_down);
    const auto above = hn::RebindMask(df, has_up);
    VI fux, fuy, fuz, fvx, fvy, fvz;  // NOLINT(readability-isolate-declaration)
    to_fixed(hn::Sub(hn::IfThenElse(right, rx, cx), hn::IfThenElse(left, lx, cx)),
             hn::Sub(hn::IfThenElse(right, ry, cy), hn::IfThenElse(left, ly, cy)),
             hn::Sub(hn::IfThenElse(right, rz, cz), hn::IfThenElse(left, lz, cz)), fux, fuy, fuz);
    to_fixed(hn::Sub(hn::IfThenElse(below, dx, cx), hn::IfThenElse(above, ux, cx)),
             hn::Sub(hn::IfThenElse(below, dy, cy), hn::IfThenElse(above, uy, cy)),
             hn::Sub(hn::IfThenElse(below, dz, cz), hn::IfThenElse(above, uz, cz)), fvx, fvy, fvz);
    normal_direction(fux, fuy, fuz, fvx, fvy, fvz, defined, direction_x, direction_y, direction_z, some);
}

// pyr_normal_q for n pixels as normal_direction_of describes them.
HWY_INLINE void normal_q_of(VF cx, VF cy, VF cz, MI center, VF rx, VF ry, VF rz, MI has_right, VF lx, VF ly, VF lz,
                            MI has_left, VF ux, VF uy, VF uz, MI has_up, VF dx, VF dy, VF dz, MI has_down, VI& qx,
                            VI& qy, VI& qz) {
    VI ex, ey, ez;  // NOLINT(readability-isolate-declaration)
    MI some;
    normal_direction_of(cx, cy, cz, center, rx, ry, rz, has_right, lx, ly, lz, has_left, ux, uy, uz, has_up, dx, dy, dz,
                        has_down, ex, ey, ez, some);
    normal_from_direction(ex, ey, ez, some, cx, cy, cz, qx, qy, qz);
}

// pyr_normal_q for the pixels x .. x + n - 1 of row y, all with both horizontal neighbours inside the image, and
// their points' z. up / down: the rows y - r / y + r, or row y itself where that row is outside the image (has_up /
// has_down clear).
HWY_INLINE void normal_q_vector(const float* row, const float* up, const float* down, std::size_t pf, std::size_t x,
                                std::size_t r, MI has_up_row, MI has_down_row, VI& qx, VI& qy, VI& qz, VF& z) {
    const DF df;
    VF cx, cy, cz, rx, ry, rz, lx, ly, lz, ux, uy, uz, dx, dy, dz;  // NOLINT(readability-isolate-declaration)
    load_points(df, row + x * pf, pf, cx, cy, cz);
    load_points(df, row + (x + r) * pf, pf, rx, ry, rz);
    load_points(df, row + (x - r) * pf, pf, lx, ly, lz);
    load_points(df, up + x * pf, pf, ux, uy, uz);
    load_points(df, down + x * pf, pf, dx, dy, dz);
    normal_q_of(cx, cy, cz, point_valid(cx, cy, cz), rx, ry, rz, point_valid(rx, ry, rz), lx, ly, lz,
                point_valid(lx, ly, lz), ux, uy, uz, hn::And(has_up_row, point_valid(ux, uy, uz)), dx, dy, dz,
                hn::And(has_down_row, point_valid(dx, dy, dz)), qx, qy, qz);
    z = cz;
}

// n = q * 2^-13, packed (the scalar code's store_normal).
HWY_INLINE void store_normals(VI qx, VI qy, VI qz, float* out) {
    const DF df;
    const VF unit = hn::Set(df, PYR_NORMAL_UNIT);
    hn::StoreInterleaved3(hn::Mul(hn::ConvertTo(df, qx), unit), hn::Mul(hn::ConvertTo(df, qy), unit),
                          hn::Mul(hn::ConvertTo(df, qz), unit), df, out);
}

// What quantize makes of the normal n = q * 2^-13 of a point with depth z: n is finite, and non-zero exactly where
// q is (|q| >= 1 and 2^-13 is a normal float); q is (0, 0, 0) wherever the point is not valid (pyr_normal_q); and
// rint(clamp(n, -1, 1) * 2^13) = q since |q| <= 2^13 and the products by powers of two are exact. So the pixel is
// valid iff q != 0, its qn is q, and its words are store_quant's of (q, valid, z).
HWY_INLINE void store_quant_of_normal(VI qx, VI qy, VI qz, VF z, std::uint32_t* out) {
    const DI di;
    const DU du;
    const VI low = hn::Set(di, 0xffff);
    const MI valid = hn::Ne(hn::Or(hn::Or(qx, qy), qz), hn::Zero(di));
    const VU w0 = hn::BitCast(du, hn::Or(hn::And(qx, low), hn::ShiftLeft<16>(qy)));
    const VU w1 = hn::BitCast(du, hn::Or(hn::And(qz, low), hn::IfThenElseZero(valid, hn::Set(di, 1 << 16))));
    hn::StoreInterleaved3(w0, w1, hn::BitCast(du, z), du, out);
}

// A row of w pixels whose pixels r .. w - r - 1 have both horizontal neighbours at distance r: vector(x) for whole
// vectors of n pixels over those (the last ending at w - r, overlapping the one before: vector must write the same
// wherever they do), scalar(x) for the others, and for every pixel of a row too short for one vector.
template <class Scalar, class Vector>
HWY_INLINE void interior_vectors(std::uint32_t w, std::uint32_t r, std::size_t n, const Scalar& scalar,
                                 const Vector& vector) {
    if (std::size_t(w) < 2 * std::size_t(r) + n) {
        for (std::uint32_t x = 0; x < w; ++x) scalar(x);
        return;
    }
    const std::uint32_t x_end = w - r;
    for (std::uint32_t x = 0; x < r; ++x) scalar(x);
    for (std::uint32_t x = x_end; x < w; ++x) scalar(x);
    for (std::size_t x = r;; x += n) {
        x = std::min(x, std::size_t(x_end) - n);
        vector(x);
        if (x + n >= x_end) break;
    }
}

// Row y of the paper metric's normals, as floats (normals, unless null) and as quantize's words (quant, unless
// null): what normals_row and then quantize_row write, in one pass over the row's points.
void normals_to_row(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r,
                    float* normals, std::uint32_t* quant) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const auto scalar = [&](std::uint32_t x) {
        const PyrIVec3 q = kernels::pyr_normal_q(c, w, h, x, y, r);
        float v[3];
        store_normal(q, v);
        if (normals != nullptr) std::copy_n(v, 3, normals + 3 * std::size_t(x));
        if (quant == nullptr) return;
        const float* p = c.points + std::size_t(y) * c.row_floats + std::size_t(x) * c.point_floats;
        const PyrQuant pq = kernels::pyr_quantize(p[0], p[1], p[2], v[0], v[1], v[2]);
        store_quant(quant + kQuantWords * x, pq.qx, pq.qy, pq.qz, pq.valid, p[2]);
    };
    const std::size_t pf = c.point_floats;
    const float* row = c.points + std::size_t(y) * c.row_floats;
    const bool up_exists = y >= r;
    const bool down_exists = std::size_t(y) + r < h;
    const float* up = up_exists ? row - std::size_t(r) * c.row_floats : row;
    const float* down = down_exists ? row + std::size_t(r) * c.row_floats : row;
    const MI has_up_row = hn::Ne(hn::Set(di, up_exists ? 1 : 0), hn::Zero(di));
    const MI has_down_row = hn::Ne(hn::Set(di, down_exists ? 1 : 0), hn::Zero(di));
    interior_vectors(w, r, n, scalar, [&](std::size_t x) {
        VI qx, qy, qz;  // NOLINT(readability-isolate-declaration)
        VF z;
        normal_q_vector(row, up, down, pf, x, r, has_up_row, has_down_row, qx, qy, qz, z);
        if (normals != nullptr) store_normals(qx, qy, qz, normals + 3 * x);
        if (quant != nullptr) store_quant_of_normal(qx, qy, qz, z, quant + kQuantWords * x);
    });
}

void normals_row(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r, float* out) {
    normals_to_row(c, w, h, y, r, out, nullptr);
}

// ---- The fused front end's rows (cpu_simd.hpp: PointRow, QuantRow)

// f(x) for vectors of n pixels from x covering begin .. end - 1 (end - begin >= n): the first at begin, the next ones
// at multiples of n (where the rows' arrays start on a cache line, loads at x then do not straddle two), the last
// ending at end. They overlap: f must write the same wherever they do.
template <class F>
HWY_INLINE void for_vectors(std::size_t begin, std::size_t end, std::size_t n, const F& f) {
    f(begin);
    if (begin + n >= end) return;
    for (std::size_t x = (begin / n + 1) * n; x < end; x += n) f(std::min(x, end - n));
}

// A ReadAhead's lines, spread over the vectors of for_vectors(begin, end, n): step() with each vector reads the next
// few (for_vectors calls f at least (end - begin) / n times, rounded up).
class ReadingAhead {
public:
    ReadingAhead(const ReadAhead& ahead, std::size_t begin, std::size_t end, std::size_t n)
        : ahead_(ahead), lines_((ahead.bytes + kLine - 1) / kLine) {
        const std::size_t vectors = (end - begin + n - 1) / n;
        per_vector_ = (lines_ + vectors - 1) / vectors;
    }

    HWY_INLINE void step() {
        const std::size_t end = std::min(lines_, next_ + per_vector_);
        for (; next_ < end; ++next_) {
            for (const void* at : ahead_.at) {
                // Read, into the L2 cache (locality 2): the L1 cache is smaller than a row or two of points.
                if (at != nullptr) __builtin_prefetch(static_cast<const char*>(at) + kLine * next_, 0, 2);
            }
        }
    }

private:
    static constexpr std::size_t kLine = 64;
    const ReadAhead& ahead_;
    std::size_t lines_;
    std::size_t per_vector_ = 0;
    std::size_t next_ = 0;
};

// Points x .. x + n - 1 of a row of w points, `stride` floats apart: components 0, 1, 2. PCL's padded points
// (stride 4) are deinterleaved too, except in the vector that holds the row's last point (whose padding float may
// lie past the cloud's end); other layouts go through load_points.
HWY_INLINE void load_row_points(DF df, const float* HWY_RESTRICT row, std::size_t stride, std::size_t x, std::size_t w,
                                VF& px, VF& py, VF& pz) {
    if (stride == 4 && x + hn::Lanes(df) < w) {
        VF padding;
        hn::LoadInterleaved4(df, row + 4 * x, px, py, pz, padding);
        return;
    }
    load_points(df, row + x * stride, stride, px, py, pz);
}

void split_points_row(const float* points, std::size_t point_floats, std::uint32_t w, const PointRow& out) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    if (w < n) {
        for (std::size_t x = 0; x < w; ++x) {
            const float* p = points + x * point_floats;
            out.x[x] = p[0];
            out.y[x] = p[1];
            out.z[x] = p[2];
            out.valid[x] = kernels::pyr_point_valid(p[0], p[1], p[2]) != 0 ? -1 : 0;
        }
        return;
    }
    for (std::size_t x = 0;; x += n) {
        x = std::min(x, std::size_t(w) - n);
        VF px, py, pz;  // NOLINT(readability-isolate-declaration)
        load_row_points(df, points, point_floats, x, w, px, py, pz);
        hn::StoreU(px, df, out.x + x);
        hn::StoreU(py, df, out.y + x);
        hn::StoreU(pz, df, out.z + x);
        hn::StoreU(hn::VecFromMask(di, point_valid(px, py, pz)), di, out.valid + x);
        if (x + n >= w) break;
    }
}

// Pixels x .. x + n - 1 of an unpacked row, from qn (0 where not valid), validity and z; and their validity bytes
// unless `valid_bytes` is null.
HWY_INLINE void store_quant_row(VI qx, VI qy, VI qz, MI valid, VF z, const QuantRow& out, std::size_t x,
                                std::uint8_t* valid_bytes) {
    const DF df;
    const DI di;
    const VI one = hn::IfThenElseZero(valid, hn::Set(di, 1));
    hn::StoreU(qx, di, out.q[0] + x);
    hn::StoreU(qy, di, out.q[1] + x);
    hn::StoreU(qz, di, out.q[2] + x);
    hn::StoreU(one, di, out.valid + x);
    hn::StoreU(hn::IfThenElse(hn::RebindMask(df, valid), z, hn::Set(df, std::numeric_limits<float>::infinity())), df,
               out.z + x);
    if (valid_bytes != nullptr) {
        const hn::Rebind<std::uint8_t, DI> d8;
        hn::StoreU(hn::DemoteTo(d8, one), d8, valid_bytes + x);
    }
}

// Pixel x of an unpacked row from the scalar code's quantized pixel of a point with depth z.
void store_quant_pixel(const PyrQuant& q, float z, const QuantRow& out, std::size_t x) {
    out.q[0][x] = q.qx;
    out.q[1][x] = q.qy;
    out.q[2][x] = q.qz;
    out.valid[x] = q.valid != 0 ? 1 : 0;
    out.z[x] = q.valid != 0 ? z : std::numeric_limits<float>::infinity();
}

// The sums of an unpacked row (QuantRow::sum) for pixels 1 .. w - 2 (the metric's vectors read them where the row is
// at least a vector and two wide).
void sum_quant_row(const QuantRow& r, std::uint32_t w) {
    const DI di;
    const std::size_t n = hn::Lanes(di);
    const std::int32_t* const fields[4] = {r.q[0], r.q[1], r.q[2], r.valid};
    std::int32_t* const sums[4] = {r.sum[0], r.sum[1], r.sum[2], r.sum[3]};
    if (std::size_t(w) < n + 2) {
        for (std::size_t x = 1; x + 1 < w; ++x) {
            for (int f = 0; f < 4; ++f) sums[f][x] = fields[f][x - 1] + fields[f][x] + fields[f][x + 1];
        }
        return;
    }
    for_vectors(1, std::size_t(w) - 1, n, [&](std::size_t x) {
        for (int f = 0; f < 4; ++f) {
            const std::int32_t* v = fields[f];
            hn::StoreU(hn::Add(hn::Add(hn::LoadU(di, v + x - 1), hn::LoadU(di, v + x)), hn::LoadU(di, v + x + 1)), di,
                       sums[f] + x);
        }
    });
}

void normals_quant_row(const PassContext& c, const PointRow& up, const PointRow& row, const PointRow& down,
                       std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r, float* normals,
                       std::uint32_t* quant, std::uint8_t* valid, const QuantRow& out, const ReadAhead& ahead) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const auto scalar = [&](std::uint32_t x) {
        const PyrIVec3 q = kernels::pyr_normal_q(c, w, h, x, y, r);
        float v[3];
        store_normal(q, v);
        if (normals != nullptr) std::copy_n(v, 3, normals + 3 * std::size_t(x));
        const float* p = c.points + std::size_t(y) * c.row_floats + std::size_t(x) * c.point_floats;
        const PyrQuant pq = kernels::pyr_quantize(p[0], p[1], p[2], v[0], v[1], v[2]);
        if (quant != nullptr) store_quant(quant + kQuantWords * x, pq.qx, pq.qy, pq.qz, pq.valid, p[2]);
        if (valid != nullptr) valid[x] = std::uint8_t(pq.valid);
        store_quant_pixel(pq, p[2], out, x);
    };
    // Pixels r .. w - r - 1 have both horizontal neighbours; the others are the scalar code's.
    if (std::size_t(w) < 2 * std::size_t(r) + n) {
        for (std::uint32_t x = 0; x < w; ++x) scalar(x);
        sum_quant_row(out, w);
        return;
    }
    const std::uint32_t x_end = w - r;
    for (std::uint32_t x = 0; x < r; ++x) scalar(x);
    for (std::uint32_t x = x_end; x < w; ++x) scalar(x);
    const MI has_up_row = hn::Ne(hn::Set(di, y >= r ? 1 : 0), hn::Zero(di));
    const MI has_down_row = hn::Ne(hn::Set(di, std::size_t(y) + r < h ? 1 : 0), hn::Zero(di));
    const auto valid_at = [&](const PointRow& p, std::size_t x) { return hn::MaskFromVec(hn::LoadU(di, p.valid + x)); };
    // Whole vectors (for_vectors), a block of them at a time in two loops: the first to the normals' directions
    // (normal_direction_of), kept in `block`, the second from them to q and the stores. Each loop's chain of
    // dependent operations is half the whole one, so the core overlaps more vectors (the whole chain, through a
    // square root and a division, is longer than its out-of-order window holds). The rows' pointers are in locals,
    // which the stores cannot change.
    const PointRow u = up;
    const PointRow m = row;
    const PointRow d = down;
    const QuantRow o = out;
    constexpr std::size_t kBlock = 8;
    HWY_ALIGN std::int32_t block[4][kBlock * kMaxLanes];  // dx, dy, dz, some (-1 or 0)
    std::size_t at[kBlock];
    std::size_t count = 0;
    const auto run_block = [&] {
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t x = at[k];
            const std::size_t xr = x + r;
            const std::size_t xl = x - r;
            VI dx, dy, dz;  // NOLINT(readability-isolate-declaration)
            MI some;
            normal_direction_of(hn::LoadU(df, m.x + x), hn::LoadU(df, m.y + x), hn::LoadU(df, m.z + x), valid_at(m, x),
                                hn::LoadU(df, m.x + xr), hn::LoadU(df, m.y + xr), hn::LoadU(df, m.z + xr),
                                valid_at(m, xr), hn::LoadU(df, m.x + xl), hn::LoadU(df, m.y + xl),
                                hn::LoadU(df, m.z + xl), valid_at(m, xl), hn::LoadU(df, u.x + x),
                                hn::LoadU(df, u.y + x), hn::LoadU(df, u.z + x), hn::And(has_up_row, valid_at(u, x)),
                                hn::LoadU(df, d.x + x), hn::LoadU(df, d.y + x), hn::LoadU(df, d.z + x),
                                hn::And(has_down_row, valid_at(d, x)), dx, dy, dz, some);
            hn::Store(dx, di, block[0] + k * n);
            hn::Store(dy, di, block[1] + k * n);
            hn::Store(dz, di, block[2] + k * n);
            hn::Store(hn::VecFromMask(di, some), di, block[3] + k * n);
        }
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t x = at[k];
            const VF cz = hn::LoadU(df, m.z + x);
            VI qx, qy, qz;  // NOLINT(readability-isolate-declaration)
            normal_from_direction(hn::Load(di, block[0] + k * n), hn::Load(di, block[1] + k * n),
                                  hn::Load(di, block[2] + k * n), hn::MaskFromVec(hn::Load(di, block[3] + k * n)),
                                  hn::LoadU(df, m.x + x), hn::LoadU(df, m.y + x), cz, qx, qy, qz);
            if (normals != nullptr) store_normals(qx, qy, qz, normals + 3 * x);
            if (quant != nullptr) store_quant_of_normal(qx, qy, qz, cz, quant + kQuantWords * x);
            // Valid where q != 0 (store_quant_of_normal).
            store_quant_row(qx, qy, qz, hn::Ne(hn::Or(hn::Or(qx, qy), qz), hn::Zero(di)), cz, o, x, valid);
        }
        count = 0;
    };
    ReadingAhead reading(ahead, r, x_end, n);
    for_vectors(r, x_end, n, [&](std::size_t x) {
        reading.step();
        at[count++] = x;
        if (count == kBlock) run_block();
    });
    run_block();
    sum_quant_row(out, w);
}

// ---- Quantize (shaders/pyr_quantize.h)

// pyr_quantize_component for finite n: clamp to [-1, 1] (Min/Max equal the scalar comparisons for finite n), the
// exact product by 2^13, rounded half to even.
HWY_INLINE VI quantize_component(VF n) {
    const DF df;
    const DI di;
    const VF clamped = hn::Min(hn::Max(n, hn::Set(df, -1.0f)), hn::Set(df, 1.0f));
    return hn::ConvertTo(di, hn::Round(hn::Mul(clamped, hn::Set(df, PYR_NORMAL_SCALE))));
}

// pyr_quantize on n pixels: qn (0 where not valid: the scalar code converts only valid ones) and the validity.
HWY_INLINE MI quantize_vectors(VF px, VF py, VF pz, VF nx, VF ny, VF nz, VI& qx, VI& qy, VI& qz) {
    const MI valid = hn::And(point_valid(px, py, pz), normal_valid(nx, ny, nz));
    qx = hn::IfThenElseZero(valid, quantize_component(nx));
    qy = hn::IfThenElseZero(valid, quantize_component(ny));
    qz = hn::IfThenElseZero(valid, quantize_component(nz));
    return valid;
}

// store_quant's words of n pixels.
HWY_INLINE void store_quant_words(VI qx, VI qy, VI qz, MI valid, VF z, std::uint32_t* out) {
    const DI di;
    const DU du;
    const VI low = hn::Set(di, 0xffff);
    const VU w0 = hn::BitCast(du, hn::Or(hn::And(qx, low), hn::ShiftLeft<16>(qy)));
    const VU w1 = hn::BitCast(du, hn::Or(hn::And(qz, low), hn::IfThenElseZero(valid, hn::Set(di, 1 << 16))));
    hn::StoreInterleaved3(w0, w1, hn::BitCast(du, z), du, out);
}

// The quantized words of row pixels 0 .. w - 1 one at a time (rows narrower than a vector), and of the fused path
// their validity bytes and its unpacked row.
void quantize_pixels(const float* points, std::size_t point_floats, const float* normals, std::size_t normal_floats,
                     std::uint32_t w, std::uint32_t* quant, std::uint8_t* valid, const QuantRow* out) {
    for (std::size_t x = 0; x < w; ++x) {
        const float* p = points + x * point_floats;
        const float* q = normals + x * normal_floats;
        const PyrQuant v = kernels::pyr_quantize(p[0], p[1], p[2], q[0], q[1], q[2]);
        if (quant != nullptr) store_quant(quant + kQuantWords * x, v.qx, v.qy, v.qz, v.valid, p[2]);
        if (valid != nullptr) valid[x] = std::uint8_t(v.valid);
        if (out != nullptr) store_quant_pixel(v, p[2], *out, x);
    }
}

void quantize_row(const float* points, std::size_t point_floats, const float* normals, std::size_t normal_floats,
                  std::uint32_t w, std::uint32_t* out) {
    const DF df;
    const std::size_t n = hn::Lanes(df);
    if (w < n) return quantize_pixels(points, point_floats, normals, normal_floats, w, out, nullptr, nullptr);
    for (std::size_t x = 0;; x += n) {
        x = std::min(x, std::size_t(w) - n);
        VF px, py, pz, nx, ny, nz;  // NOLINT(readability-isolate-declaration)
        load_points(df, points + x * point_floats, point_floats, px, py, pz);
        load_points(df, normals + x * normal_floats, normal_floats, nx, ny, nz);
        VI qx, qy, qz;  // NOLINT(readability-isolate-declaration)
        const MI valid = quantize_vectors(px, py, pz, nx, ny, nz, qx, qy, qz);
        store_quant_words(qx, qy, qz, valid, pz, out + kQuantWords * x);
        if (x + n >= w) break;
    }
}

void quantize_quant_row(const float* points, std::size_t point_floats, const float* normals, std::size_t normal_floats,
                        std::uint32_t w, std::uint32_t* quant, std::uint8_t* valid, const QuantRow& out) {
    const DF df;
    const std::size_t n = hn::Lanes(df);
    if (w < n) {
        quantize_pixels(points, point_floats, normals, normal_floats, w, quant, valid, &out);
        sum_quant_row(out, w);
        return;
    }
    for (std::size_t x = 0;; x += n) {
        x = std::min(x, std::size_t(w) - n);
        VF px, py, pz, nx, ny, nz;  // NOLINT(readability-isolate-declaration)
        load_row_points(df, points, point_floats, x, w, px, py, pz);
        load_row_points(df, normals, normal_floats, x, w, nx, ny, nz);
        VI qx, qy, qz;  // NOLINT(readability-isolate-declaration)
        const MI is_valid = quantize_vectors(px, py, pz, nx, ny, nz, qx, qy, qz);
        if (quant != nullptr) store_quant_words(qx, qy, qz, is_valid, pz, quant + kQuantWords * x);
        store_quant_row(qx, qy, qz, is_valid, pz, out, x, valid);
        if (x + n >= w) break;
    }
    sum_quant_row(out, w);
}

// ---- The paper metric (shaders/pyr_metric.h)
//
// Per pixel the scalar code sums qn . qn_j over the valid 8-neighbours j and takes the smallest and largest |z - z_j|.
// The sum is computed as qn . (sum of the valid neighbours' qn): the same integer, as integer arithmetic is exact
// and no partial sum overflows (|sum of qn_j| <= 8 * 2^13, so each product is below 2^29 and their sum below 2^31).
// The neighbours' sums come from column sums (three rows) of qn masked by validity: the 3 x 3 box less the pixel.
// A row is handled in chunks: its three quant rows are unpacked, per pixel, into column sums, the middle row's qn,
// and each row's depth and validity.

// Pixels per chunk (with one more on either side).
constexpr std::size_t kMetricChunk = 128;
constexpr std::size_t kMetricSpan = kMetricChunk + 2;

// The n quantized pixels whose words start at `words` (store_quant): qn (0 where not valid), validity (-1 where
// valid, else 0) and depth.
HWY_INLINE void load_quant(const std::uint32_t* words, VI& qx, VI& qy, VI& qz, VI& valid, VF& z) {
    const DF df;
    const DI di;
    const DU du;
    VU w0, w1, w2;  // NOLINT(readability-isolate-declaration)
    hn::LoadInterleaved3(du, words, w0, w1, w2);
    const VI i0 = hn::BitCast(di, w0);
    const VI i1 = hn::BitCast(di, w1);
    const MI is_valid = hn::RebindMask(di, hn::Ne(hn::ShiftRight<16>(w1), hn::Zero(du)));
    qx = hn::IfThenElseZero(is_valid, hn::ShiftRight<16>(hn::ShiftLeft<16>(i0)));  // sign-extended halves
    qy = hn::IfThenElseZero(is_valid, hn::ShiftRight<16>(i0));
    qz = hn::IfThenElseZero(is_valid, hn::ShiftRight<16>(hn::ShiftLeft<16>(i1)));
    valid = hn::VecFromMask(di, is_valid);
    z = hn::BitCast(df, w2);
}

// One chunk of a row, unpacked. Index i is the pixel begin - 1 + i.
struct MetricChunk {
    HWY_ALIGN std::int32_t column[4][kMetricSpan];  // column sums of qx, qy, qz (masked) and of validity (-count)
    HWY_ALIGN std::int32_t middle[4][kMetricSpan];  // the middle row's qx, qy, qz (masked) and validity
    HWY_ALIGN std::int32_t valid[3][kMetricSpan];   // each row's validity, -1 or 0
    HWY_ALIGN float z[3][kMetricSpan];              // each row's depth
};

// pyr_metric_fillable for the pixels begin + i .. begin + i + n - 1, which have both horizontal neighbours.
HWY_INLINE void metric_vector(const MetricChunk& m, const bool has_row[3], std::size_t i, std::int32_t tc, float dt,
                              std::uint8_t* out) {
    const DF df;
    const DI di;
    const hn::Rebind<std::uint8_t, DI> d8;
    const std::size_t c = i + 1;  // the pixel itself
    // The 3 x 3 box of field f less the pixel itself.
    const auto neighbours = [&](int f) {
        const VI box = hn::Add(hn::Add(hn::LoadU(di, m.column[f] + c - 1), hn::LoadU(di, m.column[f] + c)),
                               hn::LoadU(di, m.column[f] + c + 1));
        return hn::Sub(box, hn::LoadU(di, m.middle[f] + c));
    };
    const VI qx = hn::LoadU(di, m.middle[0] + c);
    const VI qy = hn::LoadU(di, m.middle[1] + c);
    const VI qz = hn::LoadU(di, m.middle[2] + c);
    const VI s = hn::Add(hn::Add(hn::Mul(qx, neighbours(0)), hn::Mul(qy, neighbours(1))), hn::Mul(qz, neighbours(2)));
    const VI k = hn::Neg(neighbours(3));  // 0..8
    // Both depths are finite where both pixels are valid: |dz| is then finite and >= 0, and Min / Max are the scalar
    // code's comparisons. Invalid neighbours leave dmin and dmax as they are.
    const VF z = hn::LoadU(df, m.z[1] + c);
    VF dmin = hn::Set(df, hwy::HighestValue<float>());
    VF dmax = hn::Zero(df);
    for (int row = 0; row < 3; ++row) {
        if (!has_row[row]) continue;
        for (std::size_t j = c - 1; j <= c + 1; ++j) {
            if (row == 1 && j == c) continue;
            const auto use = hn::MaskFromVec(hn::BitCast(df, hn::LoadU(di, m.valid[row] + j)));
            const VF dd = hn::Abs(hn::Sub(z, hn::LoadU(df, m.z[row] + j)));
            dmin = hn::IfThenElse(use, hn::Min(dmin, dd), dmin);
            dmax = hn::IfThenElse(use, hn::Max(dmax, dd), dmax);
        }
    }
    // k * tc fits int32: k <= 8, tc in [-2^28, 2^26].
    const MI curvature_ok = hn::Not(hn::Lt(s, hn::Mul(k, hn::Set(di, tc))));
    const MI depth_ok = hn::RebindMask(di, hn::Le(hn::Sub(dmax, dmin), hn::Set(df, dt)));
    const MI center_valid = hn::Ne(hn::LoadU(di, m.middle[3] + c), hn::Zero(di));
    const MI fillable = hn::And(hn::And(center_valid, hn::Gt(k, hn::Zero(di))), hn::And(curvature_ok, depth_ok));
    hn::StoreU(hn::DemoteTo(d8, hn::IfThenElseZero(fillable, hn::Set(di, 1))), d8, out);
}

void metric_row(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::int32_t tc, float dt,
                std::uint8_t* out) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const auto scalar = [&](std::uint32_t x) {
        out[x] = std::uint8_t(kernels::pyr_metric_fillable(c, w, h, x, y, tc, dt));
    };
    if (std::size_t(w) < n + 2 || n > kMetricChunk) {
        for (std::uint32_t x = 0; x < w; ++x) scalar(x);
        return;
    }
    scalar(0);
    scalar(w - 1);
    const bool has_row[3] = {y > 0, true, std::size_t(y) + 1 < h};
    const std::uint32_t* source[3];
    for (int k = 0; k < 3; ++k) {
        source[k] = c.quant + kQuantWords * std::size_t(has_row[k] ? y - 1 + std::uint32_t(k) : y) * w;
    }
    // Scratch: each chunk writes every element it reads first (zeroing it would cost a pass over 10 KiB a row).
    MetricChunk m;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    // Pixels 1 .. w - 2 in chunks; a chunk narrower than a vector starts earlier (recomputing some pixels).
    for (std::size_t x0 = 1; x0 < std::size_t(w) - 1; x0 += kMetricChunk) {
        const std::size_t x1 = std::min(x0 + kMetricChunk, std::size_t(w) - 1);
        const std::size_t begin = std::min(x0, x1 - n);
        const std::size_t span = x1 - begin + 2;  // pixels begin - 1 .. x1
        // Every store below is a function of the words at i only: the last, overlapping vector rewrites the same.
        for (std::size_t i = 0;; i += n) {
            i = std::min(i, span - n);
            VI cx, cy, cz, cv, qx, qy, qz, valid;  // NOLINT(readability-isolate-declaration)
            VF z;
            load_quant(source[1] + kQuantWords * (begin - 1 + i), cx, cy, cz, cv, z);
            hn::StoreU(cx, di, m.middle[0] + i);
            hn::StoreU(cy, di, m.middle[1] + i);
            hn::StoreU(cz, di, m.middle[2] + i);
            hn::StoreU(cv, di, m.middle[3] + i);
            hn::StoreU(cv, di, m.valid[1] + i);
            hn::StoreU(z, df, m.z[1] + i);
            for (int k = 0; k < 3; k += 2) {
                if (!has_row[k]) continue;
                load_quant(source[k] + kQuantWords * (begin - 1 + i), qx, qy, qz, valid, z);
                cx = hn::Add(cx, qx);
                cy = hn::Add(cy, qy);
                cz = hn::Add(cz, qz);
                cv = hn::Add(cv, valid);
                hn::StoreU(valid, di, m.valid[k] + i);
                hn::StoreU(z, df, m.z[k] + i);
            }
            hn::StoreU(cx, di, m.column[0] + i);
            hn::StoreU(cy, di, m.column[1] + i);
            hn::StoreU(cz, di, m.column[2] + i);
            hn::StoreU(cv, di, m.column[3] + i);
            if (i + n >= span) break;
        }
        for (std::size_t x = begin;; x += n) {
            x = std::min(x, x1 - n);
            metric_vector(m, has_row, x - begin, tc, dt, out + x);
            if (x + n >= x1) break;
        }
    }
}

// pyr_metric_fillable of pixel x from unpacked rows (rows[1] its own, rows[0] / rows[2] above / below or null): the
// shared function on the image's part of the pixel's 3 x 3 box, packed into store_quant's words as an image of its
// own, whose borders are the image's wherever the box meets them (so every neighbour test is the same).
std::uint8_t metric_pixel(const QuantRow* const rows[3], std::uint32_t w, std::uint32_t x, std::int32_t tc, float dt) {
    std::uint32_t words[9 * kQuantWords];
    const std::uint32_t x0 = x > 0 ? x - 1 : 0;
    const std::uint32_t x1 = std::min(w, x + 2);
    const std::uint32_t box_w = x1 - x0;
    std::uint32_t box_h = 0;
    std::uint32_t box_y = 0;
    for (int k = 0; k < 3; ++k) {
        const QuantRow* row = rows[k];
        if (row == nullptr) continue;
        if (k == 1) box_y = box_h;
        for (std::uint32_t i = x0; i < x1; ++i) {
            store_quant(words + kQuantWords * (std::size_t(box_h) * box_w + (i - x0)), row->q[0][i], row->q[1][i],
                        row->q[2][i], std::uint32_t(row->valid[i]), row->z[i]);
        }
        ++box_h;
    }
    PassContext c;
    c.quant = words;
    return std::uint8_t(kernels::pyr_metric_fillable(c, box_w, box_h, x - x0, box_y, tc, dt));
}

// pyr_metric_fillable for the pixels x .. x + n - 1 of a row, which have both horizontal neighbours, from the
// unpacked rows (metric_vector's arithmetic): qn . (the 3 x 3 box of sums less the pixel's own qn), k from the
// validity sums; each neighbour's |z - z_j| once. A neighbour that is not valid has z_j = +infinity: |z - z_j| is
// +infinity where the pixel is valid (z finite), which leaves dmin as it is (Min with +infinity is exact on every
// target, like Min of finite values), and dmax takes only the valid ones. In lanes whose pixel is not valid
// (z = +infinity) the depths may be NaN; the result there is 0 whatever they are.
template <bool kAbove, bool kBelow>
HWY_INLINE void metric_quant_vector(const QuantRow& above, const QuantRow& row, const QuantRow& below, std::size_t x,
                                    VI tc, VF dt, std::uint8_t* out) {
    const DF df;
    const DI di;
    const hn::Rebind<std::uint8_t, DI> d8;
    const auto box = [&](int f) {
        VI s = hn::LoadU(di, row.sum[f] + x);
        if constexpr (kAbove) s = hn::Add(s, hn::LoadU(di, above.sum[f] + x));
        if constexpr (kBelow) s = hn::Add(s, hn::LoadU(di, below.sum[f] + x));
        return s;
    };
    const VI qx = hn::LoadU(di, row.q[0] + x);
    const VI qy = hn::LoadU(di, row.q[1] + x);
    const VI qz = hn::LoadU(di, row.q[2] + x);
    const VI s = hn::Add(hn::Add(hn::Mul(qx, hn::Sub(box(0), qx)), hn::Mul(qy, hn::Sub(box(1), qy))),
                         hn::Mul(qz, hn::Sub(box(2), qz)));
    const VI valid = hn::LoadU(di, row.valid + x);
    const VI k = hn::Sub(box(3), valid);  // 0..8
    const VF z = hn::LoadU(df, row.z + x);
    const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
    VF dmin = inf;
    VF dmax = hn::Zero(df);
    const auto neighbour = [&](const float* at) {
        const VF zj = hn::LoadU(df, at);
        const VF dd = hn::Abs(hn::Sub(z, zj));
        dmin = hn::Min(dmin, dd);
        dmax = hn::IfThenElse(hn::Lt(zj, inf), hn::Max(dmax, dd), dmax);
    };
    if constexpr (kAbove) {
        neighbour(above.z + x - 1);
        neighbour(above.z + x);
        neighbour(above.z + x + 1);
    }
    neighbour(row.z + x - 1);
    neighbour(row.z + x + 1);
    if constexpr (kBelow) {
        neighbour(below.z + x - 1);
        neighbour(below.z + x);
        neighbour(below.z + x + 1);
    }
    // k * tc fits int32: k <= 8, tc in [-2^28, 2^26].
    const MI curvature_ok = hn::Not(hn::Lt(s, hn::Mul(k, tc)));
    const MI depth_ok = hn::RebindMask(di, hn::Le(hn::Sub(dmax, dmin), dt));
    const MI fillable =
        hn::And(hn::And(hn::Ne(valid, hn::Zero(di)), hn::Gt(k, hn::Zero(di))), hn::And(curvature_ok, depth_ok));
    hn::StoreU(hn::DemoteTo(d8, hn::IfThenElseZero(fillable, hn::Set(di, 1))), d8, out + x);
}

template <bool kAbove, bool kBelow>
void metric_quant_vectors(const QuantRow* above, const QuantRow& row, const QuantRow* below, std::uint32_t w,
                          std::int32_t tc, float dt, std::uint8_t* out, const ReadAhead& ahead) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const VI tcv = hn::Set(di, tc);
    const VF dtv = hn::Set(df, dt);
    // The rows' pointers in locals, which the stores cannot change; a row outside the image is not read.
    const QuantRow a = kAbove ? *above : row;
    const QuantRow m = row;
    const QuantRow b = kBelow ? *below : row;
    ReadingAhead reading(ahead, 1, std::size_t(w) - 1, n);
    for_vectors(1, std::size_t(w) - 1, n, [&](std::size_t x) {
        reading.step();
        metric_quant_vector<kAbove, kBelow>(a, m, b, x, tcv, dtv, out);
    });
}

void metric_quant_row(const QuantRow* above, const QuantRow& row, const QuantRow* below, std::uint32_t w,
                      std::int32_t tc, float dt, std::uint8_t* out, const ReadAhead& ahead) {
    const QuantRow* const rows[3] = {above, &row, below};
    // Pixels 1 .. w - 2 by vectors where the rows have their sums (sum_quant_row), the others the scalar code's.
    if (std::size_t(w) < hn::Lanes(DF()) + 2) {
        for (std::uint32_t x = 0; x < w; ++x) out[x] = metric_pixel(rows, w, x, tc, dt);
        return;
    }
    out[0] = metric_pixel(rows, w, 0, tc, dt);
    out[w - 1] = metric_pixel(rows, w, w - 1, tc, dt);
    if (above != nullptr && below != nullptr) {
        metric_quant_vectors<true, true>(above, row, below, w, tc, dt, out, ahead);
    } else if (above != nullptr) {
        metric_quant_vectors<true, false>(above, row, below, w, tc, dt, out, ahead);
    } else if (below != nullptr) {
        metric_quant_vectors<false, true>(above, row, below, w, tc, dt, out, ahead);
    } else {
        metric_quant_vectors<false, false>(above, row, below, w, tc, dt, out, ahead);
    }
}

// ---- Depth images (shaders/pyr_depth.h)

// pyr_depth_point lane by lane: bit tests, then the three correctly rounded products; the tests pick NaN points
// where the scalar code returns `none`, so every lane computes (products of non-finite values included are thrown
// away, and float products never trap).
HWY_INLINE void depth_vector(VU value, bool u16, float scale, const float* ku, float kv, float* out) {
    const DF df;
    const DI di;
    const DU du;
    MI none;
    VF zs;
    if (u16) {
        none = hn::RebindMask(di, hn::Eq(value, hn::Zero(du)));
        zs = hn::ConvertTo(df, hn::BitCast(di, value));  // < 2^16: exact
    } else {
        const VU e = hn::And(hn::ShiftRight<23>(value), hn::Set(du, 255u));
        none = hn::RebindMask(di, hn::Or(hn::Ne(hn::ShiftRight<31>(value), hn::Zero(du)),
                                         hn::Or(hn::Eq(e, hn::Zero(du)), hn::Eq(e, hn::Set(du, 255u)))));
        zs = hn::BitCast(df, value);
    }
    const VF z = hn::Mul(zs, hn::Set(df, scale));
    const VU ez = hn::And(hn::ShiftRight<23>(hn::BitCast(du, z)), hn::Set(du, 255u));
    none = hn::Or(none, hn::RebindMask(di, hn::Or(hn::Eq(ez, hn::Zero(du)), hn::Eq(ez, hn::Set(du, 255u)))));
    // pyr_depth_flush: a product whose exponent field is 0 keeps only its sign bit.
    const auto flush = [&](VF v) {
        const VU bits = hn::BitCast(du, v);
        const MI subnormal = hn::RebindMask(di, hn::Eq(hn::And(bits, hn::Set(du, 0x7f800000u)), hn::Zero(du)));
        return hn::BitCast(
            df, hn::IfThenElse(hn::RebindMask(du, subnormal), hn::And(bits, hn::Set(du, 0x80000000u)), bits));
    };
    const VF x = flush(hn::Mul(z, hn::LoadU(df, ku)));
    const VF y = flush(hn::Mul(z, hn::Set(df, kv)));
    const VF nan = hn::BitCast(df, hn::Set(du, PYR_DEPTH_NAN));
    const auto nonef = hn::RebindMask(df, none);
    hn::StoreInterleaved3(hn::IfThenElse(nonef, nan, x), hn::IfThenElse(nonef, nan, y), hn::IfThenElse(nonef, nan, z),
                          df, out);
}

void depth_row(const void* samples, std::uint32_t format, std::uint32_t w, float scale, const float* ku, float kv,
               float* out) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    const bool u16 = format == PYR_DEPTH_U16;
    const auto* bytes = static_cast<const unsigned char*>(samples);
    const std::size_t sample = u16 ? 2 : 4;
    const auto value_at = [&](std::size_t x) {
        std::uint32_t v = 0;
        if (u16) {
            std::uint16_t d = 0;
            std::memcpy(&d, bytes + 2 * x, 2);  // rows may start at any byte
            v = d;
        } else {
            std::memcpy(&v, bytes + 4 * x, 4);
        }
        return v;
    };
    const auto scalar = [&](std::size_t x) {
        const PyrFVec3 p = kernels::pyr_depth_point(value_at(x), format, scale, ku[x], kv);
        out[3 * x] = p.x;
        out[3 * x + 1] = p.y;
        out[3 * x + 2] = p.z;
    };
    // A row that does not start on its samples' alignment is read sample by sample (the vector loads below go
    // through typed pointers).
    if (w < n || reinterpret_cast<std::uintptr_t>(samples) % sample != 0) {
        for (std::size_t x = 0; x < w; ++x) scalar(x);
        return;
    }
    for (std::size_t x = 0;; x += n) {
        x = std::min(x, std::size_t(w) - n);
        VU value;
        if (u16) {
            const hn::Rebind<std::uint16_t, DU> d16;
            value = hn::PromoteTo(du, hn::LoadU(d16, static_cast<const std::uint16_t*>(samples) + x));
        } else {
            value = hn::LoadU(du, static_cast<const std::uint32_t*>(samples) + x);
        }
        depth_vector(value, u16, scale, ku + x, kv, out + 3 * x);
        if (x + n >= w) break;
    }
}

// ---- Mip (shaders/pyr_mip.h)

void mip_row(const std::uint8_t* child_top, std::uint32_t child_width, std::uint32_t parent_width, std::uint8_t* out) {
    if (child_top == nullptr) {
        std::memset(out, 0, parent_width);
        return;
    }
    const hn::ScalableTag<std::uint8_t> d8;
    const std::size_t n = hn::Lanes(d8);
    // Texels 0 .. full - 1 have both child columns; a texel past them (odd child width) is 0.
    const std::size_t full = child_width / 2;
    const std::uint8_t* bottom = child_top + child_width;
    std::size_t done = 0;
    if (full >= n) {
        const auto one = hn::Set(d8, std::uint8_t{PYR_MASK_FILLABLE});
        for (std::size_t x = 0;; x += n) {
            x = std::min(x, full - n);
            hn::Vec<decltype(d8)> te, to, be, bo;  // NOLINT(readability-isolate-declaration)
            hn::LoadInterleaved2(d8, child_top + 2 * x, te, to);
            hn::LoadInterleaved2(d8, bottom + 2 * x, be, bo);
            hn::StoreU(hn::And(hn::And(hn::And(te, to), hn::And(be, bo)), one), d8, out + x);
            if (x + n >= full) break;
        }
        done = full;
    }
    for (std::size_t x = done; x < full; ++x) {
        out[x] = std::uint8_t(child_top[2 * x] & child_top[2 * x + 1] & bottom[2 * x] & bottom[2 * x + 1] &
                              PYR_MASK_FILLABLE);
    }
    for (std::size_t x = full; x < parent_width; ++x) out[x] = 0;
}

// ---- Step 5's label init (shaders/pyr_labels.h, PYR_INIT_INHERIT) and step 6c's edges (shaders/pyr_edges.h)

// ORs n mask bits for pixels x .. x + n - 1 into the pixel bitmap (n <= 64; SVE's lane counts need not divide 64).
HWY_INLINE void or_bits(std::uint64_t* words, std::size_t x, std::uint64_t bits, std::size_t n) {
    if (n < 64) bits &= (std::uint64_t{1} << n) - 1;
    const std::size_t shift = x % 64;
    words[x / 64] |= bits << shift;
    if (shift != 0 && shift + n > 64) words[x / 64 + 1] |= bits >> (64 - shift);
}

// A mask of at most 64 lanes as the low bits of a word, lane i in bit i, and back: Highway stores mask bits as
// bytes, and lanes are little-endian bits on every target.
template <class D, class M>
HWY_INLINE std::uint64_t mask_to_bits(D d, M mask) {
    std::uint8_t bytes[8] = {};
    hn::StoreMaskBits(d, mask, bytes);
    std::uint64_t bits = 0;
    std::memcpy(&bits, bytes, sizeof bits);
    return bits;
}

template <class D>
HWY_INLINE auto bits_to_mask(D d, std::uint64_t bits) {
    std::uint8_t bytes[8] = {};
    std::memcpy(bytes, &bits, sizeof bits);
    return hn::LoadMaskBits(d, bytes);
}

// ORs the lanes of `mask` (pixels x .. x + Lanes(d) - 1) into the pixel bitmap.
template <class D, class M>
HWY_INLINE void or_mask_bits(D d, M mask, std::uint64_t* words, std::size_t x) {
    or_bits(words, x, mask_to_bits(d, mask), hn::Lanes(d));
}

bool inherit_row(const std::uint8_t* mask, const std::uint32_t* parent, std::uint32_t w, std::uint32_t* out,
                 std::uint64_t* unlabelled) {
    if (unlabelled != nullptr) std::memset(unlabelled, 0, (std::size_t(w) + 63) / 64 * sizeof(std::uint64_t));
    bool any = false;
    std::size_t x = 0;
#if HWY_TARGET != HWY_SCALAR
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8;
    const hn::Repartition<std::uint64_t, DU> d64;
    const hn::Rebind<std::uint32_t, decltype(d64)> dhalf;
    const std::size_t n = hn::Lanes(du);
    const VU one = hn::Set(du, 1u);
    if (n <= 64) {
        for (; x + n <= w; x += n) {
            // Each parent label twice: widened to 64 bits, its copy shifted into the upper half (lanes are
            // little-endian on every target).
            const auto p64 = hn::PromoteTo(d64, hn::LoadU(dhalf, parent + x / 2));
            const VU p = hn::BitCast(du, hn::Or(p64, hn::ShiftLeft<32>(p64)));
            const auto fillable = hn::Ne(hn::And(hn::PromoteTo(du, hn::LoadU(d8, mask + x)), one), hn::Zero(du));
            const VU v = hn::IfThenElseZero(fillable, p);
            hn::StoreU(v, du, out + x);
            if (unlabelled == nullptr) continue;
            const auto hole = hn::And(fillable, hn::Eq(v, hn::Zero(du)));
            if (hn::AllFalse(du, hole)) continue;
            or_mask_bits(du, hole, unlabelled, x);
            any = true;
        }
    }
#endif
    for (; x < w; ++x) {
        const bool fillable = (mask[x] & PYR_MASK_FILLABLE) != 0;
        out[x] = fillable ? parent[x / 2] : 0u;
        if (unlabelled != nullptr && fillable && out[x] == 0) {
            unlabelled[x / 64] |= std::uint64_t{1} << (x % 64);
            any = true;
        }
    }
    return any;
}

// Step 6c's vector loop over pixels 1 .. w - 2, shared by edge_row and edge_row_from_candidates: vectors of mask
// bytes with no valid non-fillable pixel (most of a frame) are skipped, and so is each part of one, as wide as a
// vector of labels, that has none (on fragmented masks most vectors of bytes have one, few parts do). Calls
// part(s, is_edge) for the others (s: the part's first pixel; is_edge: a mask of its lanes) and returns the first
// pixel it did not cover, from which the caller goes on one pixel at a time.
template <class Part>
HWY_INLINE std::size_t for_each_edge_part(const std::uint8_t* mask, const std::uint8_t* valid, std::uint32_t w,
                                          const Part& part) {
    const hn::ScalableTag<std::uint8_t> d8;
    const DU du;
    const std::size_t n8 = hn::Lanes(d8);
    const std::size_t n = hn::Lanes(du);
    std::size_t x = 1;
    if (n8 % n != 0 || n8 > 64) return x;
    const auto fillable_bit = hn::Set(d8, std::uint8_t{PYR_MASK_FILLABLE});
    const std::uint64_t lanes = n >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n) - 1;
    for (; x + n8 + 1 <= w; x += n8) {
        const auto not_fillable = hn::Eq(hn::And(hn::LoadU(d8, mask + x), fillable_bit), hn::Zero(d8));
        const auto invalid = hn::Eq(hn::LoadU(d8, valid + x), hn::Zero(d8));
        const auto edge = hn::AndNot(invalid, not_fillable);
        if (hn::AllFalse(d8, edge)) continue;
        std::uint64_t edges = mask_to_bits(d8, edge);
        for (std::size_t s = x; s < x + n8; s += n, edges >>= n % 64) {
            const std::uint64_t bits = edges & lanes;
            if (bits != 0) part(s, bits_to_mask(du, bits));
        }
    }
    return x;
}

// The edge label of pixel x of the row (edge_row's rule), one pixel at a time: the image's borders and the tails.
std::uint32_t edge_pixel(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
                         const std::uint32_t* above, const std::uint32_t* labels, const std::uint32_t* below,
                         const std::uint8_t* valid, std::uint32_t w, std::uint32_t x) {
    const std::uint32_t own = labels[x];
    if ((mask[x] & PYR_MASK_FILLABLE) != 0 || valid[x] == 0) return own;
    // Labels minus 1 (0 wraps to the largest value): the minimum then skips 0, and adding 1 back gives 0 for none.
    std::uint32_t best = own - 1u;
    const auto take = [&](std::uint8_t m, std::uint32_t l) {
        if ((m & PYR_MASK_FILLABLE) != 0) best = std::min(best, l - 1u);
    };
    if (x > 0) take(mask[x - 1], labels[x - 1]);
    if (x + 1 < w) take(mask[x + 1], labels[x + 1]);
    if (above != nullptr) take(mask_above[x], above[x]);
    if (below != nullptr) take(mask_below[x], below[x]);
    return best + 1u;
}

void edge_row(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
              const std::uint32_t* above, std::uint32_t* labels, const std::uint32_t* below, const std::uint8_t* valid,
              std::uint32_t w) {
    const auto scalar = [&](std::size_t x) {
        labels[x] = edge_pixel(mask_above, mask, mask_below, above, labels, below, valid, w, std::uint32_t(x));
    };
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8q;
    const VU one = hn::Set(du, 1u);
    // Labels minus 1 of fillable neighbours, the largest value for the others (see edge_pixel).
    const auto candidate = [&](const std::uint32_t* l, const std::uint8_t* m) {
        const VU not_fillable = hn::Sub(hn::And(hn::PromoteTo(du, hn::LoadU(d8q, m)), one), one);
        return hn::Or(hn::Sub(hn::LoadU(du, l), one), not_fillable);
    };
    const std::size_t x = for_each_edge_part(mask, valid, w, [&](std::size_t s, auto is_edge) {
        const VU own = hn::LoadU(du, labels + s);
        VU best = hn::Min(hn::Sub(own, one),
                          hn::Min(candidate(labels + s - 1, mask + s - 1), candidate(labels + s + 1, mask + s + 1)));
        if (above != nullptr) best = hn::Min(best, candidate(above + s, mask_above + s));
        if (below != nullptr) best = hn::Min(best, candidate(below + s, mask_below + s));
        hn::StoreU(hn::IfThenElse(is_edge, hn::Add(best, one), own), du, labels + s);
    });
    if (w > 0) scalar(0);
    for (std::size_t i = x; i < w; ++i) scalar(i);
}

// Round `round` of step 6c with several rounds (pyr_edge_label) on one row (cpu_simd.hpp): the same minimum over
// candidates as edge_row, where a neighbour is a candidate when it is fillable or its mask holds an earlier round.
// Only the pixels that take a label are written (few: a round labels the edge pixels next to the last one's).
bool edge_round_row(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
                    const std::uint32_t* above, const std::uint32_t* labels, const std::uint32_t* below,
                    const std::uint8_t* valid, std::uint32_t w, std::uint32_t round, std::uint32_t* out,
                    std::uint64_t* changed) {
    std::memset(changed, 0, (std::size_t(w) + 63) / 64 * sizeof(std::uint64_t));
    bool any = false;
    const auto usable = [&](std::uint8_t m) {
        const std::uint32_t labelled_round = std::uint32_t(m) >> PYR_MASK_EDGE_SHIFT;
        return (m & PYR_MASK_FILLABLE) != 0 || (labelled_round != 0 && labelled_round < round);
    };
    const auto scalar = [&](std::size_t x) {
        if ((mask[x] & PYR_MASK_FILLABLE) != 0 || labels[x] != 0 || valid[x] == 0) return;
        // Labels minus 1 (0 wraps to the largest value): the minimum then skips 0, and adding 1 back gives 0 for none.
        std::uint32_t best = ~0u;
        const auto take = [&](std::uint8_t m, std::uint32_t l) {
            if (usable(m)) best = std::min(best, l - 1u);
        };
        if (x > 0) take(mask[x - 1], labels[x - 1]);
        if (x + 1 < w) take(mask[x + 1], labels[x + 1]);
        if (above != nullptr) take(mask_above[x], above[x]);
        if (below != nullptr) take(mask_below[x], below[x]);
        if (best == ~0u) return;
        out[x] = best + 1u;
        changed[x / 64] |= std::uint64_t{1} << (x % 64);
        any = true;
    };
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8q;
    const VU one = hn::Set(du, 1u);
    const VU none = hn::Set(du, ~0u);
    const VU fillable_bit = hn::Set(du, PYR_MASK_FILLABLE);
    const VU this_round = hn::Set(du, round);
    // Labels minus 1 of usable neighbours, the largest value for the others.
    const auto candidate = [&](const std::uint32_t* l, const std::uint8_t* m) {
        const VU bits = hn::PromoteTo(du, hn::LoadU(d8q, m));
        const VU labelled_round = hn::ShiftRight<PYR_MASK_EDGE_SHIFT>(bits);
        const auto use = hn::Or(hn::Ne(hn::And(bits, fillable_bit), hn::Zero(du)),
                                hn::And(hn::Ne(labelled_round, hn::Zero(du)), hn::Lt(labelled_round, this_round)));
        return hn::IfThenElse(use, hn::Sub(hn::LoadU(du, l), one), none);
    };
    const std::size_t x = for_each_edge_part(mask, valid, w, [&](std::size_t s, auto is_edge) {
        const auto open = hn::And(is_edge, hn::Eq(hn::LoadU(du, labels + s), hn::Zero(du)));
        if (hn::AllFalse(du, open)) return;
        VU best = hn::Min(candidate(labels + s - 1, mask + s - 1), candidate(labels + s + 1, mask + s + 1));
        if (above != nullptr) best = hn::Min(best, candidate(above + s, mask_above + s));
        if (below != nullptr) best = hn::Min(best, candidate(below + s, mask_below + s));
        const auto takes = hn::And(open, hn::Ne(best, none));
        if (hn::AllFalse(du, takes)) return;
        hn::StoreU(hn::Add(best, one), du, out + s);
        or_mask_bits(du, takes, changed, s);
        any = true;
    });
    if (w > 0) scalar(0);
    for (std::size_t i = x; i < w; ++i) scalar(i);
    return any;
}

// Step 6c's candidates of a row (cpu_simd.hpp): label - 1 where fillable (0 wraps to the largest value), the largest
// value elsewhere, so that an edge pixel's label is one minimum of its neighbours' candidates.
void edge_candidates(const std::uint8_t* mask, const std::uint32_t* labels, std::uint32_t w, std::uint32_t* out) {
    std::size_t x = 0;
#if HWY_TARGET != HWY_SCALAR
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8q;
    const std::size_t n = hn::Lanes(du);
    const VU one = hn::Set(du, 1u);
    for (; x + n <= w; x += n) {
        const VU not_fillable = hn::Sub(hn::And(hn::PromoteTo(du, hn::LoadU(d8q, mask + x)), one), one);
        hn::StoreU(hn::Or(hn::Sub(hn::LoadU(du, labels + x), one), not_fillable), du, out + x);
    }
#endif
    for (; x < w; ++x) out[x] = (mask[x] & PYR_MASK_FILLABLE) != 0 ? labels[x] - 1u : ~0u;
}

// edge_row from the rows' candidates (edge_candidates): the same labels with five loads and four minima a vector.
void edge_row_from_candidates(const std::uint32_t* above, const std::uint32_t* row, const std::uint32_t* below,
                              const std::uint8_t* mask, const std::uint8_t* valid, std::uint32_t* labels,
                              std::uint32_t w) {
    const auto scalar = [&](std::size_t x) {
        if ((mask[x] & PYR_MASK_FILLABLE) != 0 || valid[x] == 0) return;
        std::uint32_t best = labels[x] - 1u;
        if (x > 0) best = std::min(best, row[x - 1]);
        if (x + 1 < w) best = std::min(best, row[x + 1]);
        if (above != nullptr) best = std::min(best, above[x]);
        if (below != nullptr) best = std::min(best, below[x]);
        labels[x] = best + 1u;
    };
    const DU du;
    const VU one = hn::Set(du, 1u);
    const VU none = hn::Set(du, ~0u);
    const std::size_t x = for_each_edge_part(mask, valid, w, [&](std::size_t s, auto is_edge) {
        const VU own = hn::LoadU(du, labels + s);
        const VU vertical = hn::Min(above != nullptr ? hn::LoadU(du, above + s) : none,
                                    below != nullptr ? hn::LoadU(du, below + s) : none);
        const VU best = hn::Min(hn::Min(hn::Sub(own, one), vertical),
                                hn::Min(hn::LoadU(du, row + s - 1), hn::LoadU(du, row + s + 1)));
        hn::StoreU(hn::IfThenElse(is_edge, hn::Add(best, one), own), du, labels + s);
    });
    if (w > 0) scalar(0);
    for (std::size_t i = x; i < w; ++i) scalar(i);
}

// Step 6b's column step on one row's marked pixels (cpu_simd.hpp): a marked pixel takes the label of the pixel
// next to it in the row the sweep comes from when that one is fillable and labelled (pyr_fill_step, once).
bool column_step(const std::uint8_t* from_mask, const std::uint32_t* from, std::uint32_t* row, std::uint64_t* marked,
                 std::uint32_t w) {
    bool any = false;
    const std::size_t words = (std::size_t(w) + 63) / 64;
    for (std::size_t i = 0; i < words; ++i) {
        const std::uint64_t bits = marked[i];
        if (bits == 0) continue;
        const std::size_t base = i * 64;
        std::uint64_t took = 0;
#if HWY_TARGET != HWY_SCALAR
        const DU du;
        const hn::Rebind<std::uint8_t, DU> d8;
        const std::size_t n = hn::Lanes(du);
        if (n < 64 && 64 % n == 0 && base + 64 <= w) {
            // Whole words a vector at a time, without a branch on the pixels (taking or not is as good as random).
            const VU one = hn::Set(du, 1u);
            const std::uint64_t lanes = (std::uint64_t{1} << n) - 1;
            for (std::size_t k = 0; k < 64; k += n) {
                const std::uint64_t part = (bits >> k) & lanes;
                if (part == 0) continue;
                const VU label = hn::LoadU(du, from + base + k);
                const VU fillable = hn::And(hn::PromoteTo(du, hn::LoadU(d8, from_mask + base + k)), one);
                const auto take = hn::And(bits_to_mask(du, part),
                                          hn::And(hn::Ne(fillable, hn::Zero(du)), hn::Ne(label, hn::Zero(du))));
                if (hn::AllFalse(du, take)) continue;
                hn::StoreU(hn::IfThenElse(take, label, hn::LoadU(du, row + base + k)), du, row + base + k);
                took |= (mask_to_bits(du, take) & lanes) << k;
            }
        } else
#endif
        {
            for (std::uint64_t rest = bits; rest != 0; rest &= rest - 1) {
                const auto k = unsigned(std::countr_zero(rest));
                const std::size_t x = base + k;
                if ((from_mask[x] & PYR_MASK_FILLABLE) != 0 && from[x] != 0) {
                    row[x] = from[x];
                    took |= std::uint64_t{1} << k;
                }
            }
        }
        if (took == 0) continue;
        marked[i] = bits & ~took;
        any = true;
    }
    return any;
}

// Whether this target's BlendedStore writes only the lanes its mask selects. On NEON (and Highway's SSE4, SSSE3
// and emulated targets) it loads the whole vector, blends and stores it back: lanes past a run would be written
// again, past the row (another thread's row: its new labels lost) and past the buffer.
#if HWY_TARGET == HWY_NEON || HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_SSSE3 || HWY_TARGET == HWY_EMU128 || \
    HWY_TARGET == HWY_SCALAR
constexpr bool kMaskedStores = false;
#else
constexpr bool kMaskedStores = true;  // AVX2, AVX-512: masked moves; SVE: predicated stores
#endif

// count copies of value from p on, nothing past them.
HWY_INLINE void fill_run(std::uint32_t* p, std::size_t count, std::uint32_t value) {
    if constexpr (kMaskedStores) {
        const DU du;
        const std::size_t n = hn::Lanes(du);
        const VU v = hn::Set(du, value);
        std::size_t k = 0;
        for (; k + n <= count; k += n) hn::StoreU(v, du, p + k);
        if (k < count) hn::BlendedStore(v, hn::FirstN(du, count - k), du, p + k);
    } else {
        std::fill_n(p, count, value);
    }
}

// Step 6a on one row (cpu_simd.hpp), run by run: on noisy masks a row has hundreds of runs, short ones, so nothing
// branches on a run's pixels or neighbours (which neighbour gives the label, whether one does, how long the run is).
bool row_runs(const std::uint8_t* mask, std::uint32_t* row, std::uint64_t* marked, std::uint32_t w) {
    const std::size_t words = (std::size_t(w) + 63) / 64;
    bool remain = false;
    std::size_t i = 0;
    std::uint64_t word = words != 0 ? marked[0] : 0;
    for (;;) {
        while (word == 0) {
            if (++i == words) return remain;
            word = marked[i];
        }
        const std::size_t x = i * 64 + std::size_t(std::countr_zero(word));
        // The run's end: the first unmarked pixel after x, maybe in a later word.
        std::size_t j = i;
        std::uint64_t unmarked = ~word & (~std::uint64_t{0} << (x % 64));
        while (unmarked == 0 && ++j < words) unmarked = ~marked[j];
        const std::size_t end =
            j < words ? std::min(std::size_t(w), j * 64 + std::size_t(std::countr_zero(unmarked))) : w;
        // The pixels next to the run; at the row's ends the run's own first one, which is unlabelled.
        const std::size_t before = x > 0 ? x - 1 : x;
        const std::size_t after = end < w ? end : x;
        const std::uint32_t left = (mask[before] & PYR_MASK_FILLABLE) != 0 ? row[before] : 0u;
        const std::uint32_t right = (mask[after] & PYR_MASK_FILLABLE) != 0 ? row[after] : 0u;
        const std::uint32_t label = left != 0 ? left : right;
        fill_run(row + x, end - x, label);  // the run is unlabelled: 0 leaves it as it is
        const std::uint64_t keep = label != 0 ? 0 : ~std::uint64_t{0};
        if (j == i) {
            const std::size_t length = end - x;
            const std::uint64_t run = (length == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1) << (x % 64);
            marked[i] &= ~run | keep;
        } else if (keep == 0) {
            for (std::size_t k = i; k <= j && k < words; ++k) {
                const std::size_t lo = std::max(x, k * 64);
                const std::size_t hi = std::min(end, k * 64 + 64);
                const std::size_t length = hi - lo;
                marked[k] &= ~((length == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1) << (lo % 64));
            }
        }
        remain |= label == 0;
        if (end >= w) return remain;
        i = end / 64;
        word = marked[i] & (~std::uint64_t{0} << (end % 64));
    }
}

// Compaction's lookup over a row (cpu_simd.hpp): a vector of one run's label (most of a frame) is one store, any
// other a gather, so that no branch follows where runs end (it mispredicts on fragmented masks).
void compact_row(const std::uint32_t* raw, const std::uint32_t* lut, std::uint32_t w, std::uint32_t* out) {
    std::size_t x = 0;
#if HWY_TARGET != HWY_SCALAR
    const DU du;
    const DI di;
    const std::size_t n = hn::Lanes(du);
    std::uint32_t last_raw = 0;  // lut[0] is 0
    VU last = hn::Zero(du);
    for (; x + n <= w; x += n) {
        const VU v = hn::LoadU(du, raw + x);
        if (hn::AllTrue(du, hn::Eq(v, hn::Set(du, last_raw)))) {
            hn::StoreU(last, du, out + x);
            continue;
        }
        hn::StoreU(hn::GatherIndex(du, lut, hn::BitCast(di, v)), du, out + x);
        last_raw = raw[x + n - 1];
        last = hn::Set(du, lut[last_raw]);
    }
#endif
    for (; x < w; ++x) out[x] = lut[raw[x]];
}

#include "backends/cpu/simd/robust_rows-inl.h"  // NOLINT(bugprone-suspicious-include)

// This target's row functions: constant data, so that nothing compiled for the target runs before it is chosen.
constexpr RowKernels kKernels = {"",
                                 HWY_TARGET,
                                 &normals_row,
                                 &quantize_row,
                                 &metric_row,
                                 &mip_row,
                                 &inherit_row,
                                 &edge_row,
                                 &normals_to_row,
                                 &depth_row,
                                 &column_step,
                                 &compact_row,
                                 &row_runs,
                                 &split_points_row,
                                 &normals_quant_row,
                                 &quantize_quant_row,
                                 &metric_quant_row,
                                 &edge_round_row,
                                 &robust_texels_row,
                                 &robust_range_row,
                                 &robust_normals_row,
                                 &metric_robust_row,
                                 &edge_candidates,
                                 &edge_row_from_candidates};

// Only returns the address of constant data; see available_targets.
const RowKernels* get_kernels() {
    return &kKernels;
}

}  // namespace HWY_NAMESPACE
}  // namespace pyrseg::cpu::simd
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace pyrseg::cpu::simd {

HWY_EXPORT(get_kernels);

namespace {

std::string lower_name(std::int64_t target) {
    if (target == HWY_SCALAR) return "hwy_scalar";  // "scalar" is the shared scalar functions
    std::string name = hwy::TargetName(target);
    for (char& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return name;
}

struct Registry {
    std::vector<RowKernels> kernels;  // best first
    std::vector<std::string> names;   // the storage of kernels[i].name
};

// Every entry of the dispatch table that this CPU runs. Calling an entry only returns the address of its target's
// constant table (no vector instruction), so entries are called before their target is known to be supported.
const Registry& registry() {
    static const Registry r = [] {
        Registry out;
        const std::int64_t supported = hwy::SupportedTargets();
        for (const auto entry : HWY_DISPATCH_TABLE(get_kernels)) {
            if (entry == nullptr) continue;
            const RowKernels* k = entry();
            if ((k->target & supported) == 0) continue;
#if HWY_ARCH_ARM_V7
            // 32-bit Arm's NEON flushes subnormal floats to zero: not the IEEE arithmetic the passes need.
            if (k->target == HWY_NEON) continue;
#endif
            const bool seen = std::any_of(out.kernels.begin(), out.kernels.end(),
                                          [&](const RowKernels& e) { return e.target == k->target; });
            if (!seen) out.kernels.push_back(*k);
        }
        // Highway's better targets have the lower bits.
        std::sort(out.kernels.begin(), out.kernels.end(),
                  [](const RowKernels& a, const RowKernels& b) { return a.target < b.target; });
        out.names.reserve(out.kernels.size());
        for (RowKernels& k : out.kernels) {
            out.names.push_back(lower_name(k.target));
            k.name = out.names.back().c_str();
        }
        return out;
    }();
    return r;
}

const RowKernels* by_target(std::int64_t target) {
    for (const RowKernels& k : registry().kernels) {
        if (k.target == target) return &k;
    }
    return nullptr;
}

}  // namespace

std::vector<const RowKernels*> available_targets() {
    std::vector<const RowKernels*> out;
    for (const RowKernels& k : registry().kernels) out.push_back(&k);
    return out;
}

std::vector<std::string> accepted_names() {
    std::vector<std::string> out = {"scalar"};
    for (const RowKernels& k : registry().kernels) out.emplace_back(k.name);
    return out;
}

const RowKernels* kernels_from_environment() {
    const char* env = std::getenv("PYRSEG_CPU_SIMD");
    const std::string want = env == nullptr ? "" : env;
    if (want == "scalar") return nullptr;
    if (want.empty() || want == "auto") {
        // Highway's own choice; it is always among the registry's (when not, or with none: the scalar path).
        const RowKernels* best = by_target(HWY_DYNAMIC_DISPATCH(get_kernels)()->target);
        if (best != nullptr || registry().kernels.empty()) return best;
        return &registry().kernels.front();
    }
    for (const RowKernels& k : registry().kernels) {
        if (want == k.name) return &k;
    }
    std::string names;
    for (const std::string& name : accepted_names()) names += (names.empty() ? "" : ", ") + name;
    throw Error(ErrorCode::invalid_argument,
                "PYRSEG_CPU_SIMD=" + want + " names no vector target of this build that this CPU runs; use one of: " +
                    names + " (or leave it unset for the best)");
}

}  // namespace pyrseg::cpu::simd
#endif  // HWY_ONCE
