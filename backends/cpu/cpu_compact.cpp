// Step 7: the labels present marked in the compaction table (mark_labels, or label_edges row by row), then counted
// and numbered; read_back renumbers through the table.
#include <algorithm>
#include <atomic>

#include "backends/cpu/cpu_executor.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::mark_labels(int level) {
    const PyrLevel lv = plan_.level(level);
    std::fill(lut_.begin(), lut_.end(), 0u);
    rows(lv.height, [&](size_t y) { mark_row_labels(labels_.data() + lv.offset + y * lv.width, lv.width); });
}

void CpuExecutor::compact(bool apply) {
    lut_[0] = 0;  // mark_row_labels marks 0 as well
    uint32_t count = 0;
    for (uint32_t& entry : lut_) {
        if (entry != 0) entry = ++count;
    }
    segment_count_ = count;
    compacted_ = apply;
}

// Marks the labels of row y of the full level in the compaction table (concurrent rows write the same value).
void CpuExecutor::mark_row(size_t y) {
    mark_row_labels(labels_.data() + plan_.full().offset + y * size_t(plan_.width), plan_.width);
}

// lut_[0] is set too: compact clears it. A label is stored once per run of it and only while unmarked: the
// other stores go to a local instead of a branch on it (which mispredicts on fragmented masks), and not to the
// table, whose lines would then move between the threads' caches for every label both of them see.
void CpuExecutor::mark_row_labels(const uint32_t* row, size_t w) {
    uint32_t previous = 0;
    uint32_t sink = 0;
    for (size_t x = 0; x < w; ++x) {
        const uint32_t l = row[x];
        const bool unmarked = std::atomic_ref<uint32_t>(lut_[l]).load(std::memory_order_relaxed) == 0;
        uint32_t* entry = l != previous && unmarked ? &lut_[l] : &sink;
        std::atomic_ref<uint32_t>(*entry).store(1u, std::memory_order_relaxed);
        previous = l;
    }
}

}  // namespace pyrseg::cpu
