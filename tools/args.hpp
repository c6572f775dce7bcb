#pragma once
// A small command-line parser: positional arguments, --flags, and --options with one value.
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace pyrseg::cli {

class Args {
public:
    // value_options take a value (--dt 5 or --dt=5); flag_options take none; short_flags name some of them by one
    // dash and a letter (-v for --verbose). Anything else is an error.
    Args(const std::vector<std::string>& argv, const std::set<std::string>& value_options,
         const std::set<std::string>& flag_options, const std::map<std::string, std::string>& short_flags = {});

    [[nodiscard]] const std::vector<std::string>& positional() const { return positional_; }
    [[nodiscard]] bool flag(const std::string& name) const { return flags_.count(name) != 0; }
    [[nodiscard]] std::optional<std::string> value(const std::string& name) const;
    [[nodiscard]] std::optional<double> number(const std::string& name) const;
    [[nodiscard]] std::optional<int> integer(const std::string& name) const;

private:
    std::vector<std::string> positional_;
    std::set<std::string> flags_;
    std::map<std::string, std::string> values_;
};

// A usage error: printed with a hint to run --help, exit status 2.
struct UsageError {
    std::string message;
};

}  // namespace pyrseg::cli
