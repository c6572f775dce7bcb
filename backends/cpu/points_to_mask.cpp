#include "backends/cpu/points_to_mask.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

namespace pyrseg::cpu {
namespace {

using std::size_t;
using std::uint32_t;

// Chunks of rows per thread: enough to balance the threads. oneTBB runs a thread's chunks in row order unless
// another thread steals some, and a chunk that follows its thread's last one takes the rows that one made, so the
// rows a chunk makes again at its top (the metric's neighbours, the normals' point rows) are paid only where a
// chunk was stolen: at 640x480 with 2 threads, making them for every chunk cost points to mask about 20%.
constexpr size_t kChunksPerThread = 4;

// Each array of the scratch starts on a cache line and holds the row rounded up to whole cache lines.
constexpr size_t kAlignBytes = 64;
constexpr size_t kLineElements = kAlignBytes / sizeof(float);
static_assert(sizeof(float) == sizeof(std::int32_t));

size_t array_elements(uint32_t w) {
    return (size_t(w) + kLineElements - 1) / kLineElements * kLineElements;
}

// The window's arrays a row: qx, qy, qz, validity and the four sums (integers), depth (floats).
constexpr size_t kWindowRows = 3;
constexpr size_t kQuantIntArrays = 8;
constexpr size_t kQuantFloatArrays = 1;

// The point rows a thread keeps for estimated normals: 2r + 1 of them, row j in slot j % (2r + 1), so that rows y - r,
// y and y + r fall in different slots and each row is split once, as long as they fit in about this many bytes
// (next to the window, in a core's L2 cache of 1-2 MiB); else three, one for each of the three rows a normal reads
// (each row is then split three times: at 4128x3088 with radius 4, 54 ms for points to mask against 43 with the
// ring, whose 594 KiB did not fit a budget of 512 KiB).
constexpr size_t kPointRowsBytes = size_t(1024) << 10;
constexpr uint32_t kNoRow = std::numeric_limits<uint32_t>::max();

size_t point_slots(uint32_t w, uint32_t r) {
    const size_t ring = 2 * size_t(r) + 1;
    return ring * 4 * sizeof(float) * array_elements(w) <= kPointRowsBytes ? ring : 3;
}

// The first element of v on a cache line (v holds kLineElements more than it needs).
template <class T>
T* aligned(std::vector<T>& v) {
    const auto address = reinterpret_cast<std::uintptr_t>(v.data());
    const size_t skip = (kAlignBytes - address % kAlignBytes) % kAlignBytes / sizeof(T);
    return v.data() + skip;
}

}  // namespace

size_t PointsToMask::scratch_bytes(uint32_t width, uint32_t normal_radius, size_t threads) {
    const size_t slots = point_slots(width, normal_radius);
    const size_t arrays = kWindowRows * (kQuantIntArrays + kQuantFloatArrays) + 4 * slots;
    return threads * (arrays * array_elements(width) + 2 * kLineElements) * sizeof(float);
}

void PointsToMask::allocate(Scratch& s, uint32_t width, uint32_t normal_radius) const {
    const size_t n = array_elements(width);
    const size_t slots = point_slots(width, normal_radius);
    s.ints.resize((kWindowRows * kQuantIntArrays + slots) * n + kLineElements);
    s.floats.resize((kWindowRows * kQuantFloatArrays + 3 * slots) * n + kLineElements);
    std::int32_t* ints = aligned(s.ints);
    float* floats = aligned(s.floats);
    const auto next_int = [&] { return std::exchange(ints, ints + n); };
    const auto next_float = [&] { return std::exchange(floats, floats + n); };
    for (simd::QuantRow& row : s.window) {
        for (std::int32_t*& q : row.q) q = next_int();
        row.valid = next_int();
        row.z = next_float();
        for (std::int32_t*& sum : row.sum) sum = next_int();
    }
    s.points.resize(slots);
    for (simd::PointRow& p : s.points) {
        p.x = next_float();
        p.y = next_float();
        p.z = next_float();
        p.valid = next_int();
    }
    s.point_rows.assign(slots, kNoRow);
}

void PointsToMask::run(ThreadPool& pool, const simd::VectorRows& vector_rows, const PointsToMaskFrame& frame) {
    const size_t threads = pool.size();
    scratch_.reserve(threads, [&](Scratch& s) { allocate(s, frame.width, frame.normal_radius); });
    scratch_.for_each([](Scratch& s) {  // rows of the last frame
        std::fill(std::begin(s.window_rows), std::end(s.window_rows), kNoRow);
        std::fill(s.point_rows.begin(), s.point_rows.end(), kNoRow);
    });
    const size_t rows = frame.height;
    const size_t grain = std::max<size_t>(1, (rows + threads * kChunksPerThread - 1) / (threads * kChunksPerThread));
    pool.parallel_for(rows, grain, [&](size_t y0, size_t y1) {
        scratch_.with([&](Scratch& s) { run_rows(vector_rows, frame, uint32_t(y0), uint32_t(y1), s); });
    });
}

// Rows y0 .. y1 - 1 of the mask. The metric of row y reads the quantized rows y - 1 .. y + 1 that exist; row j is
// made into window[j % 3] once the metric of row j - 2 is done with the row there before it.
void PointsToMask::run_rows(const simd::VectorRows& vector_rows, const PointsToMaskFrame& f, uint32_t y0, uint32_t y1,
                            Scratch& s) const {
    const size_t w = f.width;
    const uint32_t h = f.height;
    const uint32_t r = f.normal_radius;
    const PassContext& c = f.points;
    const size_t slots = s.points.size();
    const bool ring = slots == 2 * size_t(r) + 1;
    // Point row j, split (role: 0, 1, 2 for the rows y - r, y, y + r of a normal).
    const auto point_row = [&](uint32_t j, size_t role) -> const simd::PointRow& {
        const size_t slot = ring ? j % slots : role;
        if (s.point_rows[slot] != j) {
            vector_rows.split_points_row(c.points + size_t(j) * c.row_floats, c.point_floats, f.width, s.points[slot]);
            s.point_rows[slot] = j;
        }
        return s.points[slot];
    };
    const auto own = [&](uint32_t y) { return y >= y0 && y < y1; };
    // The bytes of a row of points (or normals) in the cloud's layout, its last point's padding left out.
    const size_t row_bytes = ((w - 1) * c.point_floats + 3) * sizeof(float);
    const bool writes =
        f.quant_out != nullptr || f.valid_out != nullptr || (f.normals_out != nullptr && f.given_normals == nullptr);
    const auto produce = [&](uint32_t y) {
        const size_t at_window = y % kWindowRows;
        // Made by this thread's last chunk: taken as it is, unless this chunk owns the row and must write its outputs.
        if (s.window_rows[at_window] == y && (s.window_written[at_window] || !own(y) || !writes)) return;
        s.window_rows[at_window] = y;
        s.window_written[at_window] = own(y);
        const simd::QuantRow& out = s.window[at_window];
        // Rows of the neighbouring chunks are recomputed here but their outputs written only by their own chunk.
        std::uint32_t* quant = f.quant_out != nullptr && own(y) ? f.quant_out + kQuantWords * size_t(y) * w : nullptr;
        std::uint8_t* valid = f.valid_out != nullptr && own(y) ? f.valid_out + size_t(y) * w : nullptr;
        if (f.given_normals != nullptr) {
            const size_t at = size_t(y) * c.row_floats;
            vector_rows.quantize_quant_row(c.points + at, c.point_floats, f.given_normals + at, c.point_floats, f.width,
                                           quant, valid, out);
            return;
        }
        float* normals = f.normals_out != nullptr && own(y) ? f.normals_out + 3 * size_t(y) * w : nullptr;
        const simd::PointRow& row = point_row(y, 1);
        const simd::PointRow& up = y >= r ? point_row(y - r, 0) : row;
        const simd::PointRow& down = size_t(y) + r < h ? point_row(y + r, 2) : row;
        // The next row made (up to row y1) splits the points r rows below it.
        simd::ReadAhead ahead;
        if (y < y1 && size_t(y) + 1 + r < h) {
            ahead.at[0] = c.points + (size_t(y) + 1 + r) * c.row_floats;
            ahead.bytes = row_bytes;
        }
        vector_rows.normals_quant_row(c, up, row, down, f.width, h, y, r, normals, quant, valid, out, ahead);
    };
    uint32_t next = y0 > 0 ? y0 - 1 : 0;  // the next row to make
    for (uint32_t y = y0; y < y1; ++y) {
        const uint32_t needed = std::min(h, y + 2);
        while (next < needed) produce(next++);
        const simd::QuantRow* above = y > 0 ? &s.window[(y - 1) % kWindowRows] : nullptr;
        const simd::QuantRow* below = y + 1 < h ? &s.window[(y + 1) % kWindowRows] : nullptr;
        // Given normals: the next row made reads its points and normals (estimated ones read ahead themselves).
        simd::ReadAhead ahead;
        if (f.given_normals != nullptr && y + 1 < y1 && next < h) {
            const size_t at = size_t(next) * c.row_floats;
            ahead.at[0] = c.points + at;
            ahead.at[1] = f.given_normals + at;
            ahead.bytes = row_bytes;
        }
        vector_rows.metric_quant_row(above, s.window[y % kWindowRows], below, f.width, f.curvature, f.depth,
                                     f.mask_out + size_t(y) * w, ahead);
    }
}

}  // namespace pyrseg::cpu
