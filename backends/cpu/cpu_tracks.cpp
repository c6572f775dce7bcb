// Tracks' overlap counts (docs/algorithm.md section 11) with the GPUs' functions (shaders/pyr_track.h): each row's
// runs of one (previous label, label) pair counted into the pair table at once, then the pairs gathered, in the
// slots the two frames' segment counts can need (pyr_track_slots, as every backend). The same walk keeps the frame's
// labels as the previous ones.
#include <algorithm>

#include "backends/cpu/cpu_executor.hpp"
#include "backends/cpu/cpu_pair_table.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::track_overlaps() {
    const PyrLevel lv = plan_.full();
    const size_t width = lv.width;
    if (previous_labels_.size() != plan_.pixel_count()) previous_labels_.assign(plan_.pixel_count(), 0u);
    const bool count = previous_count_ != 0 && segment_count_ != 0;
    const uint32_t slots = count ? pyr_track_slots(previous_count_, segment_count_, plan_.track_slots) : 1u;
    const size_t list = 1 + size_t(PYR_TRACK_SLOT_WORDS) * slots;
    const size_t words = list + size_t(PYR_TRACK_SLOT_WORDS) * (slots / 2);
    if (track_words_.size() < words) track_words_.resize(words);
    std::fill_n(track_words_.begin(), list, 0u);
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
            if (count) pixel::pyr_track_count(c, run_previous, run_label, run, 1u, slots - 1);
            run_previous = j;
            run_label = k;
            run = 1;
        }
        if (count) pixel::pyr_track_count(c, run_previous, run_label, run, 1u, slots - 1);
    });
    if (count) {
        for (uint32_t s = 0; s < slots; ++s) pixel::pyr_track_gather(c, 1u, s, uint32_t(list), 0u);
    }
    track_list_ = list;
    previous_count_ = segment_count_ == 0 ? 0 : segment_count_;
}

const uint32_t* CpuExecutor::track_pairs(uint32_t& count) const {
    count = track_words_.empty() ? 0 : track_words_[0];
    return track_words_.empty() ? nullptr : track_words_.data() + track_list_;
}

}  // namespace pyrseg::cpu
