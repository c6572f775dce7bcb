// The paper metric's normals (shaders/pyr_normals.h, pyr_normal_q), with their quantize words when asked for. The
// integer helpers here (msb, shift_magnitude, normal_direction, ...) are the robust normals' too (robust_rows-inl.h).
// Triples of vectors are out-parameters, not structs: SVE's sizeless vectors cannot be members or array elements.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

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
        const PyrIVec3 q = pixel::pyr_normal_q(c, w, h, x, y, r);
        float v[3];
        store_normal(q, v);
        if (normals != nullptr) std::copy_n(v, 3, normals + 3 * std::size_t(x));
        if (quant == nullptr) return;
        const float* p = c.points + std::size_t(y) * c.row_floats + std::size_t(x) * c.point_floats;
        const PyrQuant pq = pixel::pyr_quantize(p[0], p[1], p[2], v[0], v[1], v[2]);
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

// NOLINTEND(llvm-header-guard)
