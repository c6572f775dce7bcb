#pragma once
// A DepthView's per-frame constants (docs/algorithm.md section 1b), computed once on the host in double for every
// backend: the scale from sample units to the points' units and the per-column and per-row ray slopes.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pyrseg/depth.hpp"

namespace pyrseg::core {

struct DepthTables {
    float scale = 0;        // s: the points' units per sample unit
    std::vector<float> ku;  // W: (u - cx) / fx
    std::vector<float> kv;  // H: (v - cy) / fy
    // The samples, packed row after row as the devices read them: u16 two to a word (the lower half first), f32
    // one to a word.
    [[nodiscard]] static std::size_t sample_bytes(DepthFormat f) { return f == DepthFormat::u16 ? 2 : 4; }
};

// Validates the view (pointer, row step, metres_per_unit, intrinsics) and computes its tables for points in unit_mm.
// Throws pyrseg::Error naming the problem. `tables` is reused, so a frame allocates nothing once sized.
// samples_on_device: the samples are in a device buffer of the caller's (core/device_frame.hpp), and the view's
// pointer must be null.
void make_depth_tables(const DepthView& depth, double unit_mm, DepthTables& tables, bool samples_on_device = false);

// Copies the samples into `words` (W*H samples, packed as DepthTables describes), row after row.
void pack_depth(const DepthView& depth, std::vector<std::uint32_t>& words);

}  // namespace pyrseg::core
