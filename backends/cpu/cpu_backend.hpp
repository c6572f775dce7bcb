#pragma once
#include <memory>

#include "backends/cpu/thread_pool.hpp"
#include "core/backend_registry.hpp"
#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::cpu {

// The CPU backend: the shared pass functions run over the image on oneTBB's threads (backends/cpu/thread_pool.hpp).
// `plan` must outlive it. Throws pyrseg::Error(out_of_memory) when the buffers would not fit in this machine's
// memory, and for a bad thread setting.
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan, const ThreadSetting& threads);
// The registry's: the default setting.
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan);

// This backend in the registry (core/backend_registry.hpp).
extern const core::BackendEntry kBackend;

}  // namespace pyrseg::cpu
