#pragma once
#include <set>
#include <string>
#include <vector>

#include "pyrseg/params.hpp"
#include "tools/args.hpp"

namespace pyrseg::cli {

// Each command returns the process exit status: 0 success, 1 failure, 2 usage error.
int cmd_segment(const std::vector<std::string>& args);
int cmd_backends(const std::vector<std::string>& args);
int cmd_demo(const std::vector<std::string>& args);

// Parameters shared by the commands that segment: --ct --dt --unit-mm --bridge-levels --unjoinable-gap
// --normal-radius --no-label-edges --raw.
extern const char* const kParameterHelp;
extern const std::set<std::string> kParameterValueOptions;
extern const std::set<std::string> kParameterFlagOptions;
[[nodiscard]] Params parse_params(const Args& args);

}  // namespace pyrseg::cli
