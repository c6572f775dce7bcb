#pragma once
// A frame's host side of the GPU executor's transfers: a caller's cloud copied into packed xyz for the upload (in
// one memcpy when it is packed already, point by point when it is strided: PCL point types, interleaved normals),
// and the layout of the results it downloads in one copy and unpacks into the Result. The staging memory these
// bytes pass through is core/gpu/staging.hpp's.
#include <cstddef>
#include <cstring>

#include <cstdint>

#include "core/cloud_layout.hpp"
#include "pyrseg/cloud.hpp"
#include "pyrseg/result.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::gpu {

// `data` is cloud.points or cloud.normals (same layout); dst holds 3 * width * height floats.
inline void pack_xyz(const CloudView& cloud, const float* data, float* dst) {
    const std::size_t w = std::size_t(cloud.width);
    const std::size_t h = std::size_t(cloud.height);
    const core::CloudLayout layout = core::cloud_layout(cloud);
    if (layout.packed(w)) {
        std::memcpy(dst, data, 3 * w * h * sizeof(float));
        return;
    }
    for (std::size_t y = 0; y < h; ++y) {
        for (std::size_t x = 0; x < w; ++x)
            std::memcpy(dst + 3 * (y * w + x), data + layout.at(x, y), 3 * sizeof(float));
    }
}

// Whether pack_xyz would only copy (the backend may then upload straight from the caller's memory).
inline bool is_packed_xyz(const CloudView& cloud) {
    return core::cloud_layout(cloud).packed(std::size_t(cloud.width));
}

// Where a frame's results lie in a backend's download staging memory (bytes from its start): labels, raw labels,
// the fillable mask (4 bytes per pixel: one byte used, or one uint32 per texel) and normals.
struct StagedResults {
    static constexpr std::size_t kLabels = 0;
    static constexpr std::size_t kRawLabels = 4;  // times the pixel count, as below
    static constexpr std::size_t kMask = 8;
    static constexpr std::size_t kNormals = 12;
    static constexpr std::size_t kBytesPerPixel = 24;
};

// Copies the staged results into `out` (the Result's buffers are sized once and reused). mask_as_uint32: the
// device wrote one uint32 per texel rather than one byte.
inline void unstage_results(const unsigned char* staged, std::size_t pixels, bool mask_as_uint32,
                            const Outputs& outputs, bool have_normals, Result& out) {
    out.labels.resize(pixels);
    std::memcpy(out.labels.data(), staged + StagedResults::kLabels * pixels, 4 * pixels);
    out.raw_labels.clear();
    if (outputs.raw_labels) {
        out.raw_labels.resize(pixels);
        std::memcpy(out.raw_labels.data(), staged + StagedResults::kRawLabels * pixels, 4 * pixels);
    }
    out.fillable_mask.clear();
    if (outputs.fillable_mask) {
        out.fillable_mask.resize(pixels);
        const unsigned char* mask = staged + StagedResults::kMask * pixels;
        if (mask_as_uint32) {
            for (std::size_t i = 0; i < pixels; ++i) {
                std::uint32_t v = 0;
                std::memcpy(&v, mask + 4 * i, 4);
                out.fillable_mask[i] = static_cast<std::uint8_t>(v & PYR_MASK_FILLABLE);
            }
        } else {
            // Bit 0 is B; edge labelling's rounds live in the bits above it.
            for (std::size_t i = 0; i < pixels; ++i) out.fillable_mask[i] = mask[i] & PYR_MASK_FILLABLE;
        }
    }
    out.normals.clear();
    if (outputs.normals && have_normals) {
        out.normals.resize(3 * pixels);
        std::memcpy(out.normals.data(), staged + StagedResults::kNormals * pixels, 12 * pixels);
    }
}

}  // namespace pyrseg::gpu
