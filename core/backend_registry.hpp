#pragma once
#include <memory>
#include <string_view>

#include "core/executor.hpp"
#include "core/plan.hpp"

namespace pyrseg::core {

// Creates the executor of a backend that resolve_backend_name() accepted. `plan` must outlive it.
[[nodiscard]] std::unique_ptr<PassExecutor> make_executor(std::string_view backend, const Plan& plan);

}  // namespace pyrseg::core
