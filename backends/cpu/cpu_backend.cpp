// The CPU backend in the registry: its executor, made once its buffers are known to fit in this machine's memory.
#include "backends/cpu/cpu_backend.hpp"

#include <unistd.h>

#include <algorithm>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "backends/cpu/cpu_executor.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::cpu {
namespace {

using std::size_t;
using std::uint32_t;

size_t physical_memory_bytes() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long page = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? size_t(pages) * size_t(page) : 0;
}

// Bytes a CpuExecutor allocates (estimated normals counted: they are allocated on the first frame without normals).
size_t memory_needed(const core::Plan& plan, unsigned threads) {
    const size_t pixels = plan.pixel_count();
    return pixels * (kQuantWords * sizeof(uint32_t) + 1 + 3 * sizeof(float)) +      // quant, validity, normals
           size_t(plan.total_texels) * (sizeof(std::uint8_t) + sizeof(uint32_t)) +  // masks, labels
           (size_t(plan.max_label) + 1) * sizeof(uint32_t) +                        // compaction table
           CpuExecutor::fill_scratch_size(plan) * sizeof(uint32_t) +                // union-find
           plan.stats_words() * sizeof(uint32_t) +                                  // statistics
           (plan.params.metric == Metric::robust ? pixels * (sizeof(PyrRobustTexel) + 1) : 0) +  // texels, rest bits
           (plan.params.edge_rounds > 1 ? pixels * sizeof(std::uint32_t) + pixels / 8 + 8 * size_t(plan.height)
                                        : 0) +                                 // labels, bits
           PointsToMask::scratch_bytes(plan.width, plan.params.normal_radius,  // its rows, per thread
                                       threads) +
           (plan.params.metric == Metric::robust
                ? RobustWindows::scratch_bytes(plan.width, std::uint32_t(plan.params.normal_window), threads)
                : 0);  // the windows' rings, per thread
}

}  // namespace

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan, const ThreadSetting& threads) {
    const size_t needed = memory_needed(plan, ThreadPool(threads).size());  // a bad setting throws here
    const size_t available = physical_memory_bytes();
    const auto mib = [](size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; };
    const std::string what = "a " + std::to_string(plan.width) + " x " + std::to_string(plan.height) +
                             " image needs about " + mib(needed) + " on the CPU backend";
    // Checked up front: an allocation this large may succeed on paper and then get the process killed.
    if (available != 0 && needed > available) {
        throw Error(ErrorCode::out_of_memory, what + ", more than this machine's " + mib(available));
    }
    try {
        return std::make_unique<CpuExecutor>(plan, threads);
    } catch (const std::bad_alloc&) {
        throw Error(ErrorCode::out_of_memory, what + ", and allocating it failed");
    }
}

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    return make_executor(plan, ThreadSetting{});
}

namespace {
std::vector<std::string> describe_host(std::string* /*why_none*/, bool* available) {
    *available = true;
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    return {"host CPU, " + std::to_string(threads) + " hardware threads"};
}
}  // namespace

const core::BackendEntry kBackend = {describe_host, make_executor};

}  // namespace pyrseg::cpu
