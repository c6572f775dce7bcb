#include "tools/args.hpp"

#include <cmath>
#include <cstdlib>

namespace pyrseg::cli {

Args::Args(const std::vector<std::string>& argv, const std::set<std::string>& value_options,
           const std::set<std::string>& flag_options, const std::map<std::string, std::string>& short_flags) {
    for (std::size_t i = 0; i < argv.size(); ++i) {
        const std::string& a = argv[i];
        if (const auto alias = short_flags.find(a); alias != short_flags.end()) {
            flags_.insert(alias->second);
            continue;
        }
        if (a.size() < 2 || a.rfind("--", 0) != 0) {
            positional_.push_back(a);
            continue;
        }
        std::string name = a.substr(2);
        std::optional<std::string> inline_value;
        if (const auto eq = name.find('='); eq != std::string::npos) {
            inline_value = name.substr(eq + 1);
            name = name.substr(0, eq);
        }
        if (flag_options.count(name) != 0) {
            if (inline_value) throw UsageError{"--" + name + " takes no value"};
            flags_.insert(name);
        } else if (value_options.count(name) != 0) {
            if (inline_value) {
                values_[name] = *inline_value;
            } else if (i + 1 < argv.size()) {
                values_[name] = argv[++i];
            } else {
                throw UsageError{"--" + name + " needs a value"};
            }
        } else {
            throw UsageError{"unknown option --" + name};
        }
    }
}

std::optional<std::string> Args::value(const std::string& name) const {
    const auto it = values_.find(name);
    if (it == values_.end()) return std::nullopt;
    return it->second;
}

std::optional<double> Args::number(const std::string& name) const {
    const auto v = value(name);
    if (!v) return std::nullopt;
    char* end = nullptr;
    const double d = std::strtod(v->c_str(), &end);
    if (v->empty() || end != v->c_str() + v->size() || std::isnan(d)) {
        throw UsageError{"--" + name + " expects a number, got '" + *v + "'"};
    }
    return d;
}

std::optional<int> Args::integer(const std::string& name) const {
    const auto v = value(name);
    if (!v) return std::nullopt;
    char* end = nullptr;
    const long n = std::strtol(v->c_str(), &end, 10);
    if (v->empty() || end != v->c_str() + v->size() || n < -1000000000L || n > 1000000000L) {
        throw UsageError{"--" + name + " expects an integer, got '" + *v + "'"};
    }
    return static_cast<int>(n);
}

}  // namespace pyrseg::cli
