#pragma once
// What the CPU backend's tests share: the Highway targets this CPU runs (backends/cpu/simd/cpu_simd.hpp), and an
// environment variable set for a scope (a Segmenter reads PYRSEG_CPU_SIMD and PYRSEG_THREADS when it is made).
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends/cpu/simd/cpu_simd.hpp"

namespace pyrseg::test {

inline std::vector<std::string> target_names() {
    std::vector<std::string> names;
    for (const cpu::simd::VectorRows* k : cpu::simd::available_targets()) names.emplace_back(k->name);
    return names;
}

inline const cpu::simd::VectorRows& rows_named(const std::string& name) {
    for (const cpu::simd::VectorRows* k : cpu::simd::available_targets()) {
        if (name == k->name) return *k;
    }
    throw std::runtime_error("no target " + name);
}

class ScopedEnv {
public:
    ScopedEnv(const char* name, const std::string& value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        setenv(name, value.c_str(), 1);
    }
    ~ScopedEnv() {
        if (old_) {
            setenv(name_, old_->c_str(), 1);
        } else {
            unsetenv(name_);
        }
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
    const char* name_;
    std::optional<std::string> old_;
};

}  // namespace pyrseg::test
