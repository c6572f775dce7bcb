#pragma once
#include <vector>

#include "core/executor.hpp"
#include "core/plan.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::core {

enum class InputKind { cloud_with_normals, cloud_without_normals, depth, mask };

// Runs the contract's passes in order on `executor`; times each pass (host wall time) into `timings`.
// with_color: the frame came with a colour image (PassExecutor::bind_color), which the colour edge term uses.
void run_pipeline(const Plan& plan, InputKind input, bool with_color, PassExecutor& executor,
                  std::vector<PassTiming>& timings);

}  // namespace pyrseg::core
