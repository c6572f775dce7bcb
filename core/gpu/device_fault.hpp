#pragma once
// Test-only fault injection for every GPU backend (tests/unit/test_device_faults.cpp). A lost device, a device out
// of memory or a kernel build that fails cannot be had on demand from a real driver, yet each must reach the caller
// as a pyrseg::Error in the API's own words, leave the Segmenter destructible and the next one usable. With a plan
// set, make_gpu_executor wraps each new Segmenter's device in a FaultyDevice that fails the plan's n-th call through
// the backend's own error path (Device::fail_like). Without one nothing is wrapped: normal frames pay nothing, and
// Segmenters made before a plan is set keep their plain device.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/gpu/device.hpp"

namespace pyrseg::gpu {

// The device calls a plan can fail: allocate runs in the Segmenter's constructor, the others in segment().
enum class DeviceOp : std::uint8_t { allocate, upload, zero, dispatch, finish, download, count };

struct FaultPlan {
    DeviceOp op = DeviceOp::dispatch;
    std::uint32_t nth = 1;  // the n-th call of `op` on each wrapped device fails (1: the first)
    Fault fault = Fault::device_lost;
    // A lost device stays lost: every call after the n-th fails too. An out-of-memory fails that one call only.
    [[nodiscard]] bool sticky() const { return fault == Fault::device_lost; }
};

namespace detail {
struct FaultHooks {
    std::mutex mutex;
    std::optional<FaultPlan> plan;
    std::optional<std::string> kernel_source;
};
inline FaultHooks& fault_hooks() {
    static FaultHooks hooks;
    return hooks;
}
}  // namespace detail

// For tests only: the plan for the GPU Segmenters created from now on (std::nullopt: none).
inline void set_fault_plan(std::optional<FaultPlan> plan) {
    detail::FaultHooks& h = detail::fault_hooks();
    const std::lock_guard lock(h.mutex);
    h.plan = plan;
}

// For tests only: a kernel program that backends compiling at run time (OpenCL) build instead of their own, uncached,
// for the runtimes created from now on (std::nullopt: their own).
inline void set_test_kernel_source(std::optional<std::string> source) {
    detail::FaultHooks& h = detail::fault_hooks();
    const std::lock_guard lock(h.mutex);
    h.kernel_source = std::move(source);
}
[[nodiscard]] inline std::optional<std::string> test_kernel_source() {
    detail::FaultHooks& h = detail::fault_hooks();
    const std::lock_guard lock(h.mutex);
    return h.kernel_source;
}

// Forwards every call to the real device but the planned one, which fails as the real API would.
class FaultyDevice final : public Device {
public:
    FaultyDevice(std::unique_ptr<Device> inner, const FaultPlan& plan) : inner_(std::move(inner)), plan_(plan) {}

    [[nodiscard]] std::string description() const override { return inner_->description(); }
    [[nodiscard]] DeviceLimits limits() const override { return inner_->limits(); }
    void allocate(const BufferSizes& sizes, std::uint32_t image_width) override {
        maybe_fail(DeviceOp::allocate, "allocating the buffers");
        inner_->allocate(sizes, image_width);
    }
    void upload(Buffer b, std::size_t offset, const void* src, std::size_t bytes) override {
        maybe_fail(DeviceOp::upload, "an upload");
        inner_->upload(b, offset, src, bytes);
    }
    void download(Buffer b, std::size_t offset, void* dst, std::size_t bytes) override {
        maybe_fail(DeviceOp::download, "a download");
        inner_->download(b, offset, dst, bytes);
    }
    void zero(Buffer b, std::size_t offset, std::size_t bytes) override {
        maybe_fail(DeviceOp::zero, "a buffer fill");
        inner_->zero(b, offset, bytes);
    }
    void dispatch(Kernel k, std::uint32_t nx, std::uint32_t ny, const Args& args) override {
        maybe_fail(DeviceOp::dispatch, kernel_entry_name(k));
        inner_->dispatch(k, nx, ny, args);
    }
    void mark(const char* pass) override { inner_->mark(pass); }
    void finish() override {
        maybe_fail(DeviceOp::finish, "waiting for the frame");
        inner_->finish();
    }
    bool pass_times(std::vector<PassTiming>& timings) override { return inner_->pass_times(timings); }
    void begin_frame() override { inner_->begin_frame(); }
    void fail_like(Fault fault, const char* what) const override { inner_->fail_like(fault, what); }

private:
    void maybe_fail(DeviceOp op, const char* what) {
        const bool now = ++calls_[std::size_t(op)] == plan_.nth && op == plan_.op;
        if (now || (failed_ && plan_.sticky())) {
            failed_ = true;
            inner_->fail_like(plan_.fault, (std::string(what) + " [injected]").c_str());
        }
    }

    std::unique_ptr<Device> inner_;
    FaultPlan plan_;
    std::array<std::uint32_t, std::size_t(DeviceOp::count)> calls_{};
    bool failed_ = false;
};

// `device`, wrapped when a plan is set.
[[nodiscard]] inline std::unique_ptr<Device> with_fault_plan(std::unique_ptr<Device> device) {
    detail::FaultHooks& h = detail::fault_hooks();
    const std::lock_guard lock(h.mutex);
    if (!h.plan) return device;
    return std::make_unique<FaultyDevice>(std::move(device), *h.plan);
}

}  // namespace pyrseg::gpu
