#pragma once
// The CPU backend's fused front end: normals (paper metric, when estimated), quantize and the paper metric as one
// pass over bands of rows. Each thread produces a row's quantized pixels just before the metric of the row above
// reads them, in a window of three rows that stays in its L2 cache, so the frame's normals and quantized pixels
// need never travel to memory and back (the separate passes write and re-read 12 bytes a pixel twice); estimated
// normals go from their integer form straight to quantized pixels. The window's rows are unpacked (simd::QuantRow:
// structures of arrays, with the sums the metric's neighbourhoods share), so that each row is unpacked once, not
// once for each of the three metric rows that read it; estimated normals read the point rows split the same way
// (simd::PointRow), each point row split once, not deinterleaved for each of the five normals that read it. The row
// functions are the vector rows of backends/cpu/simd: the bytes are those of the separate passes.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "backends/cpu/thread_pool.hpp"
#include "backends/cpu/thread_scratch.hpp"

namespace pyrseg::cpu {

struct PointsToMaskFrame {
    PassContext points;                    // points, row_floats, point_floats (the cloud's layout)
    const float* given_normals = nullptr;  // the caller's normals in the points' layout, or null: estimate
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::uint32_t normal_radius = 1;
    std::int32_t curvature = 0;          // Tc
    float depth = 0.0f;                  // dt in the points' unit
    float* normals_out = nullptr;        // estimated normals, 3 floats a pixel, or null when not returned
    std::uint32_t* quant_out = nullptr;  // kQuantWords a pixel, or null when nothing reads them later
    std::uint8_t* mask_out = nullptr;    // level N, width * height bytes
    std::uint8_t* valid_out = nullptr;   // validity, a byte a pixel (edge labelling reads it)
};

class PointsToMask {
public:
    void run(ThreadPool& pool, const simd::VectorRows& vector_rows, const PointsToMaskFrame& frame);

    // Bytes of the per-thread scratch run allocates on the first frame, for `threads` threads.
    [[nodiscard]] static std::size_t scratch_bytes(std::uint32_t width, std::uint32_t normal_radius,
                                                   std::size_t threads);

private:
    struct Scratch {
        std::vector<std::int32_t> ints;  // the window's integer arrays, then the point rows' validity
        std::vector<float> floats;       // the window's depths, then the point rows' components
        simd::QuantRow window[3];        // row y in window[y % 3]
        // The row each window row holds in this frame (kNoRow: none), and whether its outputs were written: a chunk
        // that starts where the same thread's last chunk ended takes the rows that chunk made instead of making
        // them again.
        std::uint32_t window_rows[3] = {};
        bool window_written[3] = {};
        std::vector<simd::PointRow> points;
        std::vector<std::uint32_t> point_rows;  // the row each of `points` holds in this frame (kNoRow: none)
    };
    void allocate(Scratch& s, std::uint32_t width, std::uint32_t normal_radius) const;
    void run_rows(const simd::VectorRows& vector_rows, const PointsToMaskFrame& f, std::uint32_t y0, std::uint32_t y1,
                  Scratch& s) const;

    ThreadScratch<Scratch> scratch_;  // one per thread, allocated on the first frame
};

}  // namespace pyrseg::cpu
