// One test per backend pyrseg knows: skipped, with the backend's own reason, where it cannot run here (the
// conformance suites are instantiated only for the backends that can); otherwise it must create a Segmenter.
#include <gtest/gtest.h>

#include "pyrseg/segmenter.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

class Availability : public ::testing::TestWithParam<std::string> {};

TEST_P(Availability, BackendRunsHereOrSaysWhyNot) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    Segmenter s(16, 16, {}, GetParam());
    EXPECT_EQ(s.backend_name(), GetParam());
}

INSTANTIATE_TEST_SUITE_P(Backends, Availability, ::testing::ValuesIn(all_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
