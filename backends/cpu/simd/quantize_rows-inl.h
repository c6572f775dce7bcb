// Quantize (shaders/pyr_quantize.h), into the quant words and, for the fused front end, into a QuantRow.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

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
        const PyrQuant v = pixel::pyr_quantize(p[0], p[1], p[2], q[0], q[1], q[2]);
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

// NOLINTEND(llvm-header-guard)
