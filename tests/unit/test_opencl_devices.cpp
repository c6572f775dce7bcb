// OpenCL device choice: PYRSEG_OPENCL_DEVICE by index or by name, and a clear error for one that matches nothing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg {
namespace {

const BackendInfo* opencl_info() {
    static const std::vector<BackendInfo> all = list_backends();
    for (const BackendInfo& b : all) {
        if (b.name == "opencl") return &b;
    }
    return nullptr;
}

class OpenclDevices : public ::testing::Test {
protected:
    void SetUp() override {
        const BackendInfo* info = opencl_info();
        if (info == nullptr || !info->available) {
            GTEST_SKIP() << "opencl unavailable: " << (info != nullptr ? info->reason : "unknown backend");
        }
    }
    void TearDown() override { unsetenv("PYRSEG_OPENCL_DEVICE"); }
};

TEST_F(OpenclDevices, ChosenByIndexOrByName) {
    ASSERT_EQ(setenv("PYRSEG_OPENCL_DEVICE", "0:0", 1), 0);
    EXPECT_EQ(Segmenter(16, 16, {}, "opencl").backend_name(), "opencl");
    // Part of the first device's name, as `pyrseg backends` prints it ("0:0 Platform: Device (...)").
    const std::string description = opencl_info()->devices.front();
    const std::string name = description.substr(description.find(": ") + 2, 8);
    ASSERT_EQ(setenv("PYRSEG_OPENCL_DEVICE", name.c_str(), 1), 0);
    EXPECT_EQ(Segmenter(16, 16, {}, "opencl").backend_name(), "opencl");
}

TEST_F(OpenclDevices, ADeviceThatMatchesNothingIsAnErrorListingTheDevices) {
    ASSERT_EQ(setenv("PYRSEG_OPENCL_DEVICE", "no such device", 1), 0);
    try {
        Segmenter s(16, 16, {}, "opencl");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::backend_unavailable);
        const std::string what = e.what();
        EXPECT_NE(what.find("no such device"), std::string::npos) << what;
        EXPECT_NE(what.find(opencl_info()->devices.front()), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace pyrseg
