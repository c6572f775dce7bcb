#include "backends/cpu/points_to_mask.hpp"

#include <algorithm>
#include <cstring>

namespace pyrseg::cpu {
namespace {

using std::size_t;
using std::uint32_t;

// The window of quantized rows a thread keeps: about this many bytes, so that it stays in a core's L2 cache next
// to the point rows the normals read (at least the metric's 3 rows and one more, so it can slide).
constexpr size_t kWindowBytes = size_t(512) << 10;
constexpr size_t kMinWindowRows = 4;
// Chunks of rows per thread: enough to balance the threads, few enough that the two rows each chunk recomputes
// at its top and bottom (the metric's neighbours) stay a small share.
constexpr size_t kChunksPerThread = 4;

// The validity of store_quant's words, a byte a pixel. Written as scalar loads and byte stores on purpose: GCC
// vectorises the plain loop by assembling vectors on the stack, where every load waits on a failed store
// forwarding (measured: 5 ms of a 2064x1544 frame, against about 1 ms this way).
void copy_validity(const uint32_t* quant, size_t w, std::uint8_t* valid) {
    for (size_t x = 0; x < w; ++x) {
        const uint32_t word = quant[kQuantWords * x + 1];
        valid[x] = std::uint8_t(word >> 16);
        asm("" : : "r"(word));  // keeps the loop scalar (see above)
    }
}

}  // namespace

PointsToMask::Scratch& PointsToMask::acquire(size_t& slot) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto free = std::find(busy_.begin(), busy_.end(), false);
    slot = size_t(free - busy_.begin());  // a free one exists: no more than pool.size() chunks run at once
    busy_[slot] = true;
    return scratch_[slot];
}

void PointsToMask::release(size_t slot) {
    const std::lock_guard<std::mutex> lock(mutex_);
    busy_[slot] = false;
}

void PointsToMask::run(ThreadPool& pool, const simd::RowKernels& kernels, const PointsToMaskFrame& frame) {
    const size_t w = frame.width;
    const size_t threads = pool.size();
    if (scratch_.size() != threads) {  // the first frame
        window_rows_ = std::max(kMinWindowRows, kWindowBytes / (kQuantWords * sizeof(uint32_t) * w));
        window_rows_ = std::min(window_rows_, size_t(frame.height) + 2);
        scratch_.resize(threads);
        for (Scratch& s : scratch_) s.window.resize(window_rows_ * kQuantWords * w);
        busy_.assign(threads, false);
    }
    const size_t rows = frame.height;
    const size_t grain = std::max<size_t>(1, (rows + threads * kChunksPerThread - 1) / (threads * kChunksPerThread));
    pool.parallel_for(rows, grain, [&](size_t y0, size_t y1) {
        size_t slot = 0;
        Scratch& s = acquire(slot);
        run_rows(kernels, frame, uint32_t(y0), uint32_t(y1), s);
        release(slot);
    });
}

// Rows y0 .. y1 - 1 of the mask. The window holds the quantized rows [first, filled) (window row 0 is row
// `first`); the metric of row y needs rows y - 1 .. y + 1 that exist, and sees the window as an image of
// filled - first rows, in which row y has a row above / below exactly where the frame does.
void PointsToMask::run_rows(const simd::RowKernels& kernels, const PointsToMaskFrame& f, uint32_t y0, uint32_t y1,
                            Scratch& s) const {
    const size_t w = f.width;
    const size_t row_words = kQuantWords * w;
    const PassContext& c = f.points;
    uint32_t* window = s.window.data();
    uint32_t first = y0 > 0 ? y0 - 1 : 0;
    uint32_t filled = first;
    const auto own = [&](uint32_t y) { return y >= y0 && y < y1; };
    const auto produce = [&](uint32_t y, uint32_t* out) {
        if (f.given_normals != nullptr) {
            kernels.quantize_row(c.points + size_t(y) * c.row_floats, c.point_floats,
                                 f.given_normals + size_t(y) * c.row_floats, c.point_floats, f.width, out);
        } else {
            // Rows of the neighbouring chunks are recomputed here but their normals written only by their own chunk.
            float* normals = f.normals_out != nullptr && own(y) ? f.normals_out + 3 * size_t(y) * w : nullptr;
            kernels.normals_to_row(c, f.width, f.height, y, f.normal_radius, normals, out);
        }
        if (!own(y)) return;
        std::uint8_t* valid = f.valid_out + size_t(y) * w;
        copy_validity(out, w, valid);
        if (f.quant_out != nullptr) std::memcpy(f.quant_out + size_t(y) * row_words, out, row_words * sizeof(uint32_t));
    };
    PassContext local;
    local.quant = window;
    for (uint32_t y = y0; y < y1; ++y) {
        const uint32_t needed = std::min(f.height, y + 2);
        while (filled < needed) {
            if (filled - first == window_rows_) {
                // Full (so y >= 1 and first <= y - 1): slide, keeping rows y - 1 .. filled - 1.
                const uint32_t keep = y - 1;
                std::memmove(window, window + size_t(keep - first) * row_words,
                             size_t(filled - keep) * row_words * sizeof(uint32_t));
                first = keep;
            }
            produce(filled, window + size_t(filled - first) * row_words);
            ++filled;
        }
        kernels.metric_row(local, f.width, filled - first, y - first, f.curvature, f.depth, f.mask_out + size_t(y) * w);
    }
}

}  // namespace pyrseg::cpu
