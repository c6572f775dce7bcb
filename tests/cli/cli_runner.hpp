#pragma once
// Runs the pyrseg command-line tool as a user runs it (PYRSEG_CLI_PATH), for the CLI tests.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace pyrseg::cli_test {

struct CliRun {
    int status;
    std::string output;  // stdout and stderr together
};

// `env` is prefixed to the command line as the shell reads it ("VAR=value ").
inline CliRun run_with_env(const std::string& env, const std::string& args) {
    const std::string command = env + std::string(PYRSEG_CLI_PATH) + " " + args + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) return {-1, "popen failed"};
    std::string out;
    std::array<char, 4096> buffer{};
    while (const std::size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
    const int status = pclose(pipe);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

inline CliRun run(const std::string& args) {
    return run_with_env("", args);
}

}  // namespace pyrseg::cli_test
