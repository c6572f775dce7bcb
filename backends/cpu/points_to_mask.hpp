#pragma once
// The CPU backend's fused front end: normals (paper metric, when estimated), quantize and the paper metric as one
// pass over bands of rows. Each thread produces a row's quantized pixels just before the metric of the row above
// reads them, in a window of a few rows that stays in its L2 cache, so the frame's normals and quantized pixels
// need never travel to memory and back (the separate passes write and re-read 12 bytes a pixel twice); estimated
// normals go from their integer form straight to quantize's words (RowKernels::normals_to_row). The row functions
// are the vector kernels of backends/cpu/simd: the bytes are those of the separate passes.
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "backends/cpu/cpu_kernels.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "backends/cpu/thread_pool.hpp"

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
    void run(ThreadPool& pool, const simd::RowKernels& kernels, const PointsToMaskFrame& frame);

private:
    struct Scratch {
        std::vector<std::uint32_t> window;  // consecutive rows of quantized pixels
    };
    // Each running chunk takes a free scratch; at most pool.size() run at once. Allocated on the first frame.
    Scratch& acquire(std::size_t& slot);
    void release(std::size_t slot);
    void run_rows(const simd::RowKernels& kernels, const PointsToMaskFrame& f, std::uint32_t y0, std::uint32_t y1,
                  Scratch& s) const;

    std::size_t window_rows_ = 0;
    std::vector<Scratch> scratch_;
    std::vector<bool> busy_;
    std::mutex mutex_;
};

}  // namespace pyrseg::cpu
