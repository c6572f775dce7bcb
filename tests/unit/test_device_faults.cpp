// Devices that fail (issue 18): an out-of-memory or a lost device at each stage of a frame, injected through
// core/gpu/device_fault.hpp into every GPU backend's own error path, must reach the caller as a pyrseg::Error in the
// API's words; the Segmenter must stay destructible and the next one must segment correctly. Frames too large for
// the device and a kernel program that does not build are provoked for real.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "core/gpu/device_fault.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

#if PYRSEG_TEST_VULKAN_INTERNALS
#include "backends/vulkan/vulkan_runtime.hpp"
#endif

namespace pyrseg::test {
namespace {

using gpu::DeviceOp;
using gpu::Fault;

constexpr int kWidth = 96;
constexpr int kHeight = 72;

const synthetic::Scene& scene() {
    static const synthetic::Scene s = [] {
        synthetic::SceneOptions o;
        o.width = kWidth;
        o.height = kHeight;
        o.seed = 3;
        o.threads = 1;
        return synthetic::generate(o);
    }();
    return s;
}

CloudView view() {
    return CloudView{scene().points.data(), nullptr, kWidth, kHeight};
}

const std::vector<std::uint32_t>& cpu_labels() {
    static const std::vector<std::uint32_t> labels = Segmenter(kWidth, kHeight, {}, "cpu").segment(view()).labels;
    return labels;
}

// Why `name` cannot run here; empty when it can.
std::string unavailable(const std::string& name) {
    for (const BackendInfo& b : list_backends()) {
        if (b.name == name) return b.available ? "" : b.reason;
    }
    return "not a backend of this build";
}

// Each API's own name for the faults, as its users know them. A backend without a row (a new one, until it has its
// line here) is held to the form every backend's message has (core/gpu/api_error.hpp: "<API>: <what> failed: ...").
struct ApiWords {
    const char* backend;
    const char* out_of_memory;
    const char* device_lost;
};
constexpr ApiWords kApiWords[] = {
    {"cuda", "cudaErrorMemoryAllocation", "cudaErrorLaunchFailure"},
    {"vulkan", "VK_ERROR_OUT_OF_DEVICE_MEMORY", "VK_ERROR_DEVICE_LOST"},
    {"opencl", "CL_MEM_OBJECT_ALLOCATION_FAILURE", "CL_OUT_OF_RESOURCES"},
};
std::string api_error(const std::string& backend, Fault fault) {
    for (const ApiWords& words : kApiWords) {
        if (backend == words.backend) return fault == Fault::out_of_memory ? words.out_of_memory : words.device_lost;
    }
    return " failed: ";
}
ErrorCode expected_code(Fault fault) {
    return fault == Fault::out_of_memory ? ErrorCode::out_of_memory : ErrorCode::backend_unavailable;
}

// What the injected call was, in the message: FaultyDevice names it, a dispatch by its kernel.
const char* op_words(DeviceOp op) {
    switch (op) {
        case DeviceOp::allocate:
            return "allocating the buffers";
        case DeviceOp::upload:
            return "an upload";
        case DeviceOp::zero:
            return "a buffer fill";
        case DeviceOp::dispatch:
            return "pyr_k_";
        case DeviceOp::finish:
            return "waiting for the frame";
        case DeviceOp::download:
            return "a download";
        case DeviceOp::count:
            break;
    }
    return "?";
}
const char* op_name(DeviceOp op) {
    constexpr const char* kNames[] = {"allocate", "upload", "zero", "dispatch", "finish", "download"};
    return kNames[std::size_t(op)];
}

// Clears the plan however the test ends: later tests must get plain devices.
struct PlanScope {
    explicit PlanScope(const gpu::FaultPlan& plan) { gpu::set_fault_plan(plan); }
    ~PlanScope() { gpu::set_fault_plan(std::nullopt); }
    PlanScope(const PlanScope&) = delete;
    PlanScope& operator=(const PlanScope&) = delete;
};

// `op`: the call that failed, when it is the planned one (a lost device fails the next frame at its first call).
void expect_fault(const std::string& backend, std::optional<DeviceOp> op, Fault fault,
                  const std::function<void()>& call) {
    try {
        call();
        ADD_FAILURE() << "expected a pyrseg::Error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.code(), expected_code(fault)) << what;
        EXPECT_NE(what.find(api_error(backend, fault)), std::string::npos) << what;
        if (op) {
            EXPECT_NE(what.find(op_words(*op)), std::string::npos) << what;
        }
        EXPECT_NE(what.find("[injected]"), std::string::npos) << what;
    }
}

void expect_cpu_labels(Segmenter& s, const char* which) {
    const Result r = s.segment(view());
    EXPECT_GT(r.segment_count, 1u) << which;
    EXPECT_TRUE(r.labels == cpu_labels()) << which << ": labels differ from the CPU backend's";
}

// Every GPU backend pyrseg knows, built or not (those that cannot run here skip).
std::vector<std::string> gpu_backend_names() {
    std::vector<std::string> names = backend_names();
    std::erase(names, "cpu");
    return names;
}

using FaultCase = std::tuple<std::string, DeviceOp, Fault>;

class DeviceFaults : public ::testing::TestWithParam<FaultCase> {
protected:
    void SetUp() override {
        if (const std::string why = unavailable(std::get<0>(GetParam())); !why.empty()) GTEST_SKIP() << why;
    }
};

// A lost device stays lost: the same Segmenter keeps failing with the same clear error, frame after frame, and the
// caller makes a new one. An out-of-memory fails its frame only: the next frame on the same Segmenter starts
// afresh (GpuExecutor::start_frame, Device::begin_frame drop what the failed one left) and is correct.
TEST_P(DeviceFaults, BecomeErrorsInTheApisWordsAndTheNextSegmenterWorks) {
    const std::string backend = std::get<0>(GetParam());
    const DeviceOp op = std::get<1>(GetParam());
    const Fault fault = std::get<2>(GetParam());
    // The third call: a dispatch in the middle of the passes; the other operations have fewer calls a frame.
    const gpu::FaultPlan plan{op, op == DeviceOp::dispatch ? 3u : 1u, fault};
    if (op == DeviceOp::allocate) {
        const PlanScope scope(plan);
        expect_fault(backend, op, fault, [&] { Segmenter(kWidth, kHeight, {}, backend); });
    } else {
        auto failing = [&] {
            const PlanScope scope(plan);
            return std::make_unique<Segmenter>(kWidth, kHeight, Params{}, backend);
        }();
        Result result;
        expect_fault(backend, op, fault, [&] { failing->segment(view(), result); });
        if (fault == Fault::device_lost) {
            expect_fault(backend, std::nullopt, fault, [&] { failing->segment(view(), result); });
        } else {
            expect_cpu_labels(*failing, "the same Segmenter, next frame");
        }
        failing.reset();
    }
    Segmenter next(kWidth, kHeight, {}, backend);
    expect_cpu_labels(next, "a new Segmenter");
}

std::vector<FaultCase> fault_cases() {
    std::vector<FaultCase> cases;
    for (const std::string& backend : gpu_backend_names()) {
        for (int op = 0; op < int(DeviceOp::count); ++op) {
            for (const Fault fault : {Fault::out_of_memory, Fault::device_lost})
                cases.emplace_back(backend, DeviceOp(op), fault);
        }
    }
    return cases;
}

std::string case_name(const ::testing::TestParamInfo<FaultCase>& param_info) {
    const auto& [backend, op, fault] = param_info.param;
    return backend + "_" + op_name(op) + "_" + (fault == Fault::out_of_memory ? "out_of_memory" : "device_lost");
}

INSTANTIATE_TEST_SUITE_P(Injected, DeviceFaults, ::testing::ValuesIn(fault_cases()), case_name);

#if PYRSEG_TEST_VULKAN_INTERNALS
// A lost VkDevice never comes back, and every Segmenter of the process shares one per physical device: the
// Segmenters made after a loss must get a new one, not the cached runtime.
TEST(LostDevice, VulkanSegmentersMadeAfterTheLossGetANewDevice) {
    if (const std::string why = unavailable("vulkan"); !why.empty()) GTEST_SKIP() << why;
    const std::shared_ptr<vulkan::Runtime> before = vulkan::runtime_for(vulkan::choose_device());
    {
        auto failing = [] {
            const PlanScope scope({DeviceOp::dispatch, 1, Fault::device_lost});
            return std::make_unique<Segmenter>(kWidth, kHeight, Params{}, "vulkan");
        }();
        Result result;
        EXPECT_THROW(failing->segment(view(), result), Error);
    }
    EXPECT_TRUE(before->lost);
    const std::shared_ptr<vulkan::Runtime> after = vulkan::runtime_for(vulkan::choose_device());
    EXPECT_NE(after.get(), before.get());
    EXPECT_FALSE(after->lost);
}
#endif

class TooLargeForTheDevice : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        if (const std::string why = unavailable(GetParam()); !why.empty()) GTEST_SKIP() << why;
    }
};

// 55000 x 55000 passes the 32-bit checks, and its points alone (34 GiB) exceed what any device here allocates:
// refused before anything is allocated, naming the buffer, the need and the device's limit.
TEST_P(TooLargeForTheDevice, IsOutOfMemoryNamingTheDeviceAndTheBytes) {
    try {
        Segmenter s(55000, 55000, {}, GetParam());
        FAIL() << "expected an error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.code(), ErrorCode::out_of_memory) << what;
        EXPECT_NE(what.find("55000 x 55000 image needs"), std::string::npos) << what;
        EXPECT_NE(what.find(" MiB"), std::string::npos) << what;
        std::string device;
        for (const BackendInfo& b : list_backends()) {
            if (b.name == GetParam() && !b.devices.empty()) device = b.devices.front();
        }
        // The description pyrseg lists first ("0:0 Platform: Device (...)", "0 llvmpipe (...)") is the one chosen.
        EXPECT_NE(what.find(device.substr(0, device.find(" ("))), std::string::npos) << what << "\ndevice: " << device;
    }
    Segmenter next(kWidth, kHeight, {}, GetParam());
    expect_cpu_labels(next, "a new Segmenter");
}

INSTANTIATE_TEST_SUITE_P(Backends, TooLargeForTheDevice, ::testing::ValuesIn(gpu_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

// A program the driver cannot build (a broken kernel source, as a driver bug or a bad toolchain would leave it):
// the Segmenter is refused with the driver's own error and build log, and the next one builds pyrseg's own.
TEST(KernelBuildFailure, OpenclNamesTheBuildErrorAndTheNextSegmenterWorks) {
    if (const std::string why = unavailable("opencl"); !why.empty()) GTEST_SKIP() << why;
    gpu::set_test_kernel_source("kernel void pyr_k_normals(global int* p) { p[0] = undeclared_name; }");
    try {
        Segmenter s(kWidth, kHeight, {}, "opencl");
        ADD_FAILURE() << "expected an error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("CL_BUILD_PROGRAM_FAILURE"), std::string::npos) << what;
        EXPECT_NE(what.find("undeclared_name"), std::string::npos) << "the build log: " << what;
    }
    gpu::set_test_kernel_source(std::nullopt);
    Segmenter next(kWidth, kHeight, {}, "opencl");
    expect_cpu_labels(next, "a new Segmenter");
}

}  // namespace
}  // namespace pyrseg::test
