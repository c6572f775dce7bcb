#pragma once
#include <memory>

#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::cpu {

// The CPU backend: the shared pass functions run over the image on a thread pool. `plan` must outlive it.
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan);

}  // namespace pyrseg::cpu
