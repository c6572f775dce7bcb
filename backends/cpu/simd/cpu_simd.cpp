// The CPU backend's vector row passes (cpu_simd.hpp): the families of rows in the *-inl.h files next to this one,
// compiled once per Highway target (foreach_target.h includes this file again for each target, with HWY_NAMESPACE
// naming that target's namespace), each target's table of them, and the registry that HWY_EXPORT /
// HWY_DYNAMIC_DISPATCH and PYRSEG_CPU_SIMD pick one from at run time.
//
// Bit-identity with the shared scalar functions (shaders/pyr_*.h), which every backend and the reference match:
//  - every float operation is the scalar code's: IEEE add, sub, mul, div and sqrt are correctly rounded on every
//    Highway target; no MulAdd (the project compiles with -ffp-contract=off); Min/Max, in the lanes whose result is
//    used, only on operands that are finite or +infinity, never NaN or zeros of both signs (they then equal the
//    scalar code's comparisons); Round is round-half-to-even like nearbyint in the default rounding mode;
//  - integer arithmetic is the scalar code's, in lanes of the same width; every bound the scalar code states (no
//    int32 overflow) holds in every lane, including lanes whose result is thrown away (those are kept in range on
//    purpose, so that Highway's one-lane target, which uses plain C++ integers, has no undefined behaviour);
//  - the two operations with no exact vector instruction, pyr_isqrt and the division of pyr_unit_component, are
//    computed as a float estimate proven to be within 1 of the exact integer result, then corrected by one integer
//    comparison each way: the exact result, which is what the scalar code computes (the proofs are at
//    isqrt_floor and unit_component, normals_rows-inl.h);
//  - pixels whose neighbour tests differ from the interior's (image borders) call the shared scalar function;
//  - subnormals are IEEE on every target used (x86 without FTZ/DAZ, AArch64 NEON and SVE with FPCR.FZ clear, as
//    Linux starts processes); 32-bit Arm NEON, which flushes them, is left out (registry below).
// tests/unit/test_cpu_simd.cpp checks every target this CPU runs against the scalar functions and the reference.
#include "backends/cpu/simd/cpu_simd.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "pyrseg/error.hpp"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "backends/cpu/simd/cpu_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
// (foreach_target.h must come before highway.h)
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace pyrseg::cpu::simd {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MI = hn::Mask<DI>;

// The most lanes of any vector here; buffers on the stack are sized with it.
constexpr std::size_t kMaxLanes = hn::MaxLanes(DF());

// The row families, in this order (each uses helpers of those before it, so the list is not sorted).
// clang-format off
#include "backends/cpu/simd/point_loads-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/normals_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/points_to_mask_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/quantize_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/metric_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/depth_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/mip_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/pixel_bits-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/labels_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/edges_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/fill_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/compact_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/robust_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
#include "backends/cpu/simd/stats_rows-inl.h"  // NOLINT(bugprone-suspicious-include)
// clang-format on

// This target's row functions: constant data, so that nothing compiled for the target runs before it is chosen.
constexpr VectorRows kRows = {"",
                              HWY_TARGET,
                              &normals_row,
                              &quantize_row,
                              &metric_row,
                              &mip_row,
                              &inherit_row,
                              &edge_row,
                              &normals_to_row,
                              &depth_row,
                              &column_step,
                              &compact_row,
                              &row_runs,
                              &split_points_row,
                              &normals_quant_row,
                              &quantize_quant_row,
                              &metric_quant_row,
                              &edge_round_row,
                              &robust_texels_row,
                              &robust_range_row,
                              &robust_normals_row,
                              &metric_robust_row,
                              &edge_candidates,
                              &edge_row_from_candidates,
                              &stats_sums};

// Only returns the address of constant data; see available_targets.
const VectorRows* get_rows() {
    return &kRows;
}

}  // namespace HWY_NAMESPACE
}  // namespace pyrseg::cpu::simd
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace pyrseg::cpu::simd {

HWY_EXPORT(get_rows);

namespace {

std::string lower_name(std::int64_t target) {
    if (target == HWY_SCALAR) return "hwy_scalar";  // "scalar" is the shared scalar functions
    std::string name = hwy::TargetName(target);
    for (char& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return name;
}

struct Registry {
    std::vector<VectorRows> rows;    // best first
    std::vector<std::string> names;  // the storage of rows[i].name
};

// Every entry of the dispatch table that this CPU runs. Calling an entry only returns the address of its target's
// constant table (no vector instruction), so entries are called before their target is known to be supported.
const Registry& registry() {
    static const Registry r = [] {
        Registry out;
        const std::int64_t supported = hwy::SupportedTargets();
        for (const auto entry : HWY_DISPATCH_TABLE(get_rows)) {
            if (entry == nullptr) continue;
            const VectorRows* k = entry();
            if ((k->target & supported) == 0) continue;
#if HWY_ARCH_ARM_V7
            // 32-bit Arm's NEON flushes subnormal floats to zero: not the IEEE arithmetic the passes need.
            if (k->target == HWY_NEON) continue;
#endif
            const bool seen = std::any_of(out.rows.begin(), out.rows.end(),
                                          [&](const VectorRows& e) { return e.target == k->target; });
            if (!seen) out.rows.push_back(*k);
        }
        // Highway's better targets have the lower bits.
        std::sort(out.rows.begin(), out.rows.end(),
                  [](const VectorRows& a, const VectorRows& b) { return a.target < b.target; });
        out.names.reserve(out.rows.size());
        for (VectorRows& k : out.rows) {
            out.names.push_back(lower_name(k.target));
            k.name = out.names.back().c_str();
        }
        return out;
    }();
    return r;
}

const VectorRows* by_target(std::int64_t target) {
    for (const VectorRows& k : registry().rows) {
        if (k.target == target) return &k;
    }
    return nullptr;
}

}  // namespace

std::vector<const VectorRows*> available_targets() {
    std::vector<const VectorRows*> out;
    for (const VectorRows& k : registry().rows) out.push_back(&k);
    return out;
}

std::vector<std::string> accepted_names() {
    std::vector<std::string> out = {"scalar"};
    for (const VectorRows& k : registry().rows) out.emplace_back(k.name);
    return out;
}

const VectorRows* rows_from_environment() {
    const char* env = std::getenv("PYRSEG_CPU_SIMD");
    const std::string want = env == nullptr ? "" : env;
    if (want == "scalar") return nullptr;
    if (want.empty() || want == "auto") {
        // Highway's own choice; it is always among the registry's (when not, or with none: the scalar path).
        const VectorRows* best = by_target(HWY_DYNAMIC_DISPATCH(get_rows)()->target);
        if (best != nullptr || registry().rows.empty()) return best;
        return &registry().rows.front();
    }
    for (const VectorRows& k : registry().rows) {
        if (want == k.name) return &k;
    }
    std::string names;
    for (const std::string& name : accepted_names()) names += (names.empty() ? "" : ", ") + name;
    throw Error(ErrorCode::invalid_argument,
                "PYRSEG_CPU_SIMD=" + want + " names no vector target of this build that this CPU runs; use one of: " +
                    names + " (or leave it unset for the best)");
}

}  // namespace pyrseg::cpu::simd
#endif  // HWY_ONCE
