#pragma once
#include <memory>

#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::cpu {

// The CPU backend: the shared pass functions run over the image on a thread pool. `plan` must outlive it.
// Throws pyrseg::Error(out_of_memory) when the buffers would not fit in this machine's memory.
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan);

}  // namespace pyrseg::cpu
