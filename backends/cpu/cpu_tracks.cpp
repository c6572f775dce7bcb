// Tracks' overlap counts (docs/algorithm.md section 11) with the GPUs' function (shaders/pyr_track.h): each row's
// runs of one (previous label, label) pair counted into the pair table at once, in the slots the two frames' segment
// counts can need (pyr_track_slots, as every backend); the host reads the table's slots as a GPU's. The same walk
// keeps the frame's labels as the previous ones.
#include <algorithm>

#include "backends/cpu/cpu_executor.hpp"
#include "backends/cpu/cpu_pair_table.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::track_overlaps() {
    const PyrLevel lv = plan_.full();
    const size_t width = lv.width;
    const bool count = previous_count_ != 0 && segment_count_ != 0;
    track_slots_ = count ? pyr_track_slots(previous_count_, segment_count_, plan_.track_slots) : 0u;
    const uint32_t slots = track_slots_;
    const size_t words = size_t(PYR_TRACK_SLOT_WORDS) * slots;
    if (track_words_.size() < words) track_words_.resize(words);  // grows with the largest frame
    std::fill_n(track_words_.begin(), words, 0u);
    PassContext c = context();
    c.merge = track_words_.data();
    const uint32_t* lut = lut_.data();
    rows(lv.height, [&](size_t y) {
        const uint32_t* raw = labels_.data() + lv.offset + y * width;
        uint32_t* previous = previous_labels_.data() + y * width;
        uint32_t run_previous = 0;
        uint32_t run_label = 0;
        uint32_t run = 0;
        for (size_t x = 0; x < width; ++x) {
            const uint32_t k = lut[raw[x]];
            const uint32_t j = previous[x];
            previous[x] = k;
            if (j == run_previous && k == run_label) {
                ++run;
                continue;
            }
            if (count) pixel::pyr_track_count(c, run_previous, run_label, run, 0u, slots - 1);
            run_previous = j;
            run_label = k;
            run = 1;
        }
        if (count) pixel::pyr_track_count(c, run_previous, run_label, run, 0u, slots - 1);
    });
    previous_count_ = segment_count_;
}

const uint32_t* CpuExecutor::track_pairs(uint32_t& count) const {
    count = track_slots_;
    return track_words_.data();
}

}  // namespace pyrseg::cpu
