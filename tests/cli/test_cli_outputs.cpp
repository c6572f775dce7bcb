// `pyrseg segment` outputs all or nothing (issue 18): on a full disk (/dev/full, or a file-size limit like a quota)
// a frame's outputs are an error with exit status 1, and none of them is left behind, truncated or whole; a batch
// reports the frame and goes on with the next.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_runner.hpp"
#include "pyrseg/io.hpp"

namespace {

namespace fs = std::filesystem;

using pyrseg::cli_test::CliRun;

// The CLI in a child process whose files may not grow past `bytes` (RLIMIT_FSIZE, as a quota or a full disk would
// stop them); SIGXFSZ ignored, so that a write past the limit fails with EFBIG instead of killing the process.
CliRun run_with_file_size_limit(rlim_t bytes, const std::string& args) {
    const std::string command = std::string(PYRSEG_CLI_PATH) + " " + args + " 2>&1";
    std::array<int, 2> pipe_fds{};
    if (::pipe(pipe_fds.data()) != 0) return {-1, "pipe failed"};
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(pipe_fds[0]);
        ::dup2(pipe_fds[1], STDOUT_FILENO);
        const rlimit limit{bytes, bytes};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        std::signal(SIGXFSZ, SIG_IGN);
        ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    ::close(pipe_fds[1]);
    std::string out;
    std::array<char, 4096> buffer{};
    for (ssize_t n = 0; (n = ::read(pipe_fds[0], buffer.data(), buffer.size())) > 0;) out.append(buffer.data(), n);
    ::close(pipe_fds[0]);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

class CliOutputs : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pyrseg_cli_outputs_test_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "out");
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }

    // A synthetic frame (mm, no normals) as a binary PCD: at 160 x 120 its PLY and PCD outputs are over 300 KB,
    // its labels 77 KB, its PNG a few KB.
    fs::path frame(const std::string& name, int width, int height) const {
        fs::path path = dir_ / name;
        pyrseg::io::write_pcd(path, pyrseg::cli_test::scene_cloud(width, height, 5, 4),
                              pyrseg::io::PcdEncoding::binary);
        return path;
    }

    // Every file in out/, temporary ones included (none may be left behind).
    std::vector<std::string> written() const {
        std::vector<std::string> names;
        for (const fs::directory_entry& e : fs::directory_iterator(dir_ / "out")) {
            if (!e.is_symlink()) names.push_back(e.path().filename().string());
        }
        std::sort(names.begin(), names.end());
        return names;
    }

    [[nodiscard]] std::string out(const std::string& name) const { return (dir_ / "out" / name).string(); }

    fs::path dir_;
};

using Names = std::vector<std::string>;

TEST_F(CliOutputs, PlyToAFullDeviceIsAnErrorAndLeavesNoOtherOutput) {
    const fs::path input = frame("frame.pcd", 160, 120);
    fs::create_symlink("/dev/full", dir_ / "out" / "full.ply");
    const CliRun r = pyrseg::cli_test::run("segment " + input.string() + " --backend cpu --png " + out("a.png") +
                                           " --ply " + out("full.ply"));
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("full.ply: write error"), std::string::npos) << r.output;
    EXPECT_EQ(written(), Names{}) << r.output;
}

TEST_F(CliOutputs, PlyCutShortByAFileSizeLimitIsAnErrorAndLeavesNothing) {
    const fs::path input = frame("frame.pcd", 160, 120);
    const CliRun r = run_with_file_size_limit(
        150 << 10, "segment " + input.string() + " --backend cpu --png " + out("a.png") + " --ply " + out("a.ply"));
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("a.ply: write error"), std::string::npos) << r.output;
    EXPECT_EQ(written(), Names{}) << r.output;
}

TEST_F(CliOutputs, ALaterOutputFailingRemovesTheFramesEarlierOnes) {
    const fs::path input = frame("frame.pcd", 160, 120);
    const CliRun r = run_with_file_size_limit(150 << 10, "segment " + input.string() + " --backend cpu --labels " +
                                                             out("a.npy") + " --png " + out("a.png") + " --stats " +
                                                             out("a.json") + " --pcd " + out("a.pcd"));
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("a.pcd: write error"), std::string::npos) << r.output;
    EXPECT_EQ(written(), Names{}) << r.output;

    // The same outputs with room for them: all four, and nothing else.
    const CliRun ok = run_with_file_size_limit(4 << 20, "segment " + input.string() + " --backend cpu --labels " +
                                                            out("a.npy") + " --png " + out("a.png") + " --stats " +
                                                            out("a.json") + " --pcd " + out("a.pcd"));
    EXPECT_EQ(ok.status, 0) << ok.output;
    EXPECT_EQ(written(), (Names{"a.json", "a.npy", "a.pcd", "a.png"})) << ok.output;
    EXPECT_EQ(pyrseg::io::read_npy(out("a.npy")).shape, (std::vector<std::size_t>{120, 160}));
}

TEST_F(CliOutputs, ABatchReportsTheFrameWhoseOutputsFailedAndGoesOn) {
    // The first frame's PLY (1.5 MB) does not fit under the limit, its labels (300 KB) would; the second's all fit.
    const fs::path big = frame("big.pcd", 320, 240);
    const fs::path small = frame("small.pcd", 64, 48);
    const CliRun r = run_with_file_size_limit(500 << 10, "segment " + big.string() + " " + small.string() +
                                                             " --backend cpu --progress lines --write labels,png,ply"
                                                             " --out-dir " +
                                                             (dir_ / "out").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("failed: pyrseg: " + out("big.ply") + ": write error"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("2 frames, 1 segmented, 1 failed"), std::string::npos) << r.output;
    EXPECT_EQ(written(), (Names{"small.labels.npy", "small.ply", "small.png"})) << r.output;
}

}  // namespace
