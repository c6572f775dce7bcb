// pyrseg: the command-line tool.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "io/temporary_files.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/version.hpp"
#include "tools/args.hpp"
#include "tools/commands.hpp"
#include "tools/printable.hpp"

namespace {

constexpr const char* kUsage =
    "pyrseg - fast bridgeless pyramid segmentation of organized point clouds\n"
    "\n"
    "Usage: pyrseg COMMAND [ARGS]   (pyrseg COMMAND --help for details)\n"
    "\n"
    "Commands:\n"
    "  segment INPUT ...   segment an organized point cloud (.pcd, .ply, .npy) or depth image (.png, .tif), or a\n"
    "                      batch of them: write labels, pictures, labelled clouds (PCD, PLY), statistics, or\n"
    "                      with no output option print the segments' count, sizes and time\n"
    "  demo                segment a built-in synthetic bin-picking scene (and the shared sample scans when\n"
    "                      present) with every available backend, check they agree, write figures, time them\n"
    "  eval                measure segmentation quality against ground truth on synthetic scenes: pyramid vs\n"
    "                      plain connected components, across noise levels and bridge widths; with --tabletop DIR\n"
    "                      on real RGB-D frames against a ground truth made from their depth\n"
    "  bench-report JSON   turn pyrseg_bench's JSON into a markdown report of ratios against memcpy and the peers\n"
    "                      (OpenCV, PCL), with plots (scripts/bench.sh runs both)\n"
    "  backends            list the backends and devices, and why any is unavailable\n"
    "  --version           print the version\n"
    "\n"
    "Environment: PYRSEG_BACKEND picks the backend when --backend is not given; PYRSEG_THREADS sets the CPU\n"
    "backend's thread count (unset: every core, as oneTBB threads shared with the process); PYRSEG_OPENCL_DEVICE\n"
    "and PYRSEG_VULKAN_DEVICE pick a device (an index or part of its name, as `pyrseg backends` lists them);\n"
    "PYRSEG_VULKAN_VALIDATION=1 turns the Vulkan validation layer on.\n";

// What is printed on stdout is the command's result: when it cannot all be written (a full disk, /dev/full), the
// run failed, whatever the command returned. Buffered output shows its error only at the flush.
int with_stdout_checked(int status) {
    errno = 0;
    if (std::fflush(stdout) == 0 && std::ferror(stdout) == 0) return status;
    const int err = errno;
    std::fprintf(stderr, "pyrseg: cannot write to standard output: %s\n",
                 err != 0 ? std::strerror(err) : "write error");
    return status == 0 ? 1 : status;
}

int run_command(const std::vector<std::string>& all) {
    if (all.empty() || all[0] == "--help" || all[0] == "-h" || all[0] == "help") {
        std::fputs(kUsage, stdout);
        return all.empty() ? 2 : 0;
    }
    if (all[0] == "--version") {
        std::printf("pyrseg %s\n", pyrseg::kVersion);
        return 0;
    }
    const std::vector<std::string> rest(all.begin() + 1, all.end());
    try {
        if (all[0] == "segment") return pyrseg::cli::cmd_segment(rest);
        if (all[0] == "demo") return pyrseg::cli::cmd_demo(rest);
        if (all[0] == "backends") return pyrseg::cli::cmd_backends(rest);
        if (all[0] == "eval") return pyrseg::cli::cmd_eval(rest);
        if (all[0] == "bench-report") return pyrseg::cli::cmd_bench_report(rest);
        std::fprintf(stderr, "pyrseg: unknown command '%s'\n\n%s", pyrseg::cli::printable(all[0]).c_str(), kUsage);
        return 2;
    } catch (const pyrseg::cli::UsageError& e) {
        const std::string command = pyrseg::cli::printable(all[0]);
        std::fprintf(stderr, "pyrseg %s: %s (see pyrseg %s --help)\n", command.c_str(),
                     pyrseg::cli::printable(e.message).c_str(), command.c_str());
        return 2;
    } catch (const pyrseg::Error& e) {
        // A library's message names files as given: a newline in a name must not split the line.
        std::fprintf(stderr, "%s\n", pyrseg::cli::printable(e.what()).c_str());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "pyrseg: %s\n", pyrseg::cli::printable(e.what()).c_str());
        return 1;
    }
}

}  // namespace

int main(int argc, char** argv) {
    // Ctrl-C or a SIGTERM in the middle of a frame leaves none of its hidden temporary outputs behind.
    pyrseg::io::detail::remove_temporaries_on_termination_signals();
    return with_stdout_checked(run_command(std::vector<std::string>(argv + 1, argv + argc)));
}
