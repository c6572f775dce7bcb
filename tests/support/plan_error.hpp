#pragma once
// The message core::make_plan refuses a Params with (a 64 x 48 frame), "" when it accepts it; a refusal must be
// invalid_parameter.
#include <gtest/gtest.h>

#include <string>

#include "core/plan.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/params.hpp"

namespace pyrseg::test {

inline std::string plan_error(const Params& p) {
    try {
        (void)core::make_plan(64, 48, p);
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::invalid_parameter) << e.what();
        return e.what();
    }
    return "";
}

}  // namespace pyrseg::test
