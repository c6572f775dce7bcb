#pragma once
// The passes of every GPU backend, once, over a gpu::Device (core/gpu/device.hpp).
#include <memory>

#include "core/executor.hpp"
#include "core/gpu/device.hpp"
#include "core/plan.hpp"

namespace pyrseg::gpu {

// The buffers a plan needs on a device with these limits (bytes per buffer, in binding order).
[[nodiscard]] BufferSizes buffer_sizes(const core::Plan& plan, const DeviceLimits& limits);

// Throws pyrseg::Error(out_of_memory) naming the image, the need and the device's limits when `sizes` do not fit.
void check_fits(const core::Plan& plan, const BufferSizes& sizes, const DeviceLimits& limits,
                const std::string& device);

// Checks the plan's buffers against the device, allocates them, and runs the passes on it. `plan` must outlive
// the executor.
[[nodiscard]] std::unique_ptr<core::PassExecutor> make_gpu_executor(const core::Plan& plan,
                                                                    std::unique_ptr<Device> device);

}  // namespace pyrseg::gpu
