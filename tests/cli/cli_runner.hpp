#pragma once
// Runs the pyrseg command-line tool as a user runs it (PYRSEG_CLI_PATH), and makes the clouds the CLI tests feed it.
#include <sys/wait.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>

#include "pyrseg/io.hpp"
#include "pyrseg/synthetic.hpp"

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

// The CLI's stdout and stderr apart; `redirect` is what the shell does with stdout (empty: it is read as well).
struct SplitRun {
    int status;
    std::string out;  // stdout
    std::string err;  // stderr
};

inline SplitRun run_split(const std::string& args, const std::string& err_file, const std::string& redirect = "") {
    const std::string command = std::string(PYRSEG_CLI_PATH) + " " + args + " 2>'" + err_file + "' " + redirect;
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) return {-1, "popen failed", ""};
    std::string out;
    std::array<char, 4096> buffer{};
    while (const std::size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
    const int status = pclose(pipe);
    std::string err;
    if (FILE* f = std::fopen(err_file.c_str(), "rb")) {
        while (const std::size_t n = fread(buffer.data(), 1, buffer.size(), f)) err.append(buffer.data(), n);
        std::fclose(f);
    }
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out, err};
}

// A synthetic bin-picking frame as a cloud file holds it: points in millimetres, no normals (the CLI estimates them).
inline io::PointCloud scene_cloud(int width, int height, std::uint64_t seed, int object_count = 12) {
    synthetic::SceneOptions o;
    o.width = width;
    o.height = height;
    o.seed = seed;
    o.object_count = object_count;
    io::PointCloud cloud;
    cloud.width = width;
    cloud.height = height;
    cloud.points = synthetic::generate(o).points;
    return cloud;
}

}  // namespace pyrseg::cli_test
