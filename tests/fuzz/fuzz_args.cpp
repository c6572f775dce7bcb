// The CLI's option parsing as `pyrseg segment` does it (tools/cmd_segment.cpp): Args over the command's options, the
// typed accessors, --sensor, the segmentation parameters and the input options' checks. The input is the argument
// list, one argument per line. UsageError and pyrseg::Error are the CLI's answers to a bad command line.
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "pyrseg/error.hpp"
#include "tests/fuzz/fuzz_input.hpp"
#include "tools/args.hpp"
#include "tools/commands.hpp"

namespace {

using pyrseg::cli::Args;

// cmd_segment's output options live in its own file's anonymous namespace: these are their names.
const std::set<std::string> kOutputOptions = {"labels", "png",     "mask-png", "figure",  "ply",   "pcd",
                                              "stats",  "pcl-png", "backend",  "out-dir", "write", "progress"};

std::vector<std::string> split_lines(const std::uint8_t* data, std::size_t size) {
    std::vector<std::string> argv;
    std::string current;
    for (std::size_t i = 0; i < size; ++i) {
        if (data[i] == '\n') {
            argv.push_back(current);
            current.clear();
        } else {
            current.push_back(static_cast<char>(data[i]));
        }
    }
    if (!current.empty()) argv.push_back(current);
    return argv;
}

template <class Step>
void tolerate_usage_errors(Step&& step) {
    try {
        step();
    } catch (const pyrseg::cli::UsageError&) {
    } catch (const pyrseg::Error&) {
    }
}

void exercise(const Args& args, const std::set<std::string>& values) {
    for (const std::string& name : values) {
        (void)args.value(name);
        tolerate_usage_errors([&] { (void)args.number(name); });
        tolerate_usage_errors([&] { (void)args.integer(name); });
    }
    tolerate_usage_errors([&] { (void)pyrseg::cli::parse_sensor(args); });
    tolerate_usage_errors([&] { (void)pyrseg::cli::parse_params(args); });
    tolerate_usage_errors([&] { pyrseg::cli::check_input_options(args); });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::set<std::string> values = [] {
        std::set<std::string> v = pyrseg::cli::kParameterValueOptions;
        v.insert(pyrseg::cli::kInputValueOptions.begin(), pyrseg::cli::kInputValueOptions.end());
        v.insert(kOutputOptions.begin(), kOutputOptions.end());
        return v;
    }();
    static const std::set<std::string> flags = [] {
        std::set<std::string> f = pyrseg::cli::kParameterFlagOptions;
        f.insert("help");
        return f;
    }();
    tolerate_usage_errors([&] {
        const Args args(split_lines(data, size), values, flags);
        (void)args.positional();
        (void)args.flag("help");
        exercise(args, values);
    });
    return 0;
}
