// `pyrseg segment` against a hostile caller (issue 32): no silent mistake, no hang, no crash, no lost file. Every
// output path kind (a FIFO, a device, a folder, another input, the same file twice), control characters in names,
// a full stdout, and what the run says (--quiet, -v, the first frame's warm-up).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "cli/cli_runner.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/synthetic.hpp"

namespace {

namespace fs = std::filesystem;

using pyrseg::cli_test::CliRun;
using pyrseg::cli_test::run;
using pyrseg::cli_test::run_split;
using pyrseg::cli_test::SplitRun;

std::string bytes_of(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class CliHostile : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pyrseg_cli_hostile_test_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "out");
        fs::create_directories(dir_ / "tmp");
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }

    // A synthetic frame (mm, no normals) as a binary PCD.
    fs::path cloud_frame(const std::string& name, int width = 64, int height = 48, std::uint64_t seed = 5) const {
        fs::path path = dir_ / name;
        pyrseg::io::write_pcd(path, pyrseg::cli_test::scene_cloud(width, height, seed, 4),
                              pyrseg::io::PcdEncoding::binary);
        return path;
    }

    // The same kind of frame as a NumPy cloud (H x W x 3 float32).
    fs::path npy_frame(const std::string& name) const {
        const pyrseg::io::PointCloud cloud = pyrseg::cli_test::scene_cloud(64, 48, 7, 4);
        fs::path path = dir_ / name;
        pyrseg::io::write_npy(path, cloud.points.data(), cloud.height, cloud.width, 3);
        return path;
    }

    // A 16-bit depth image in millimetres; `intrinsics` is the option that back-projects it.
    fs::path depth_frame(const std::string& name, std::string& intrinsics) const {
        pyrseg::synthetic::SceneOptions o;
        o.width = 64;
        o.height = 48;
        const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(o);
        std::vector<std::uint16_t> mm(std::size_t(o.width) * std::size_t(o.height));
        for (std::size_t i = 0; i < mm.size(); ++i) {
            const float z = scene.points[3 * i + 2];
            mm[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : std::uint16_t(0);
        }
        fs::path path = dir_ / name;
        pyrseg::io::write_png_gray16(path, mm.data(), o.width, o.height);
        intrinsics = " --intrinsics " + std::to_string(scene.fx) + "," + std::to_string(scene.fy) + "," +
                     std::to_string(scene.cx) + "," + std::to_string(scene.cy);
        return path;
    }

    [[nodiscard]] std::string out(const std::string& name) const { return (dir_ / "out" / name).string(); }
    [[nodiscard]] std::string err_file() const { return (dir_ / "stderr.txt").string(); }

    // Every file in `folder` (none may be a temporary one left behind).
    static std::vector<std::string> files_in(const fs::path& folder) {
        std::vector<std::string> names;
        for (const fs::directory_entry& e : fs::directory_iterator(folder)) names.push_back(e.path().filename());
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path dir_;
};

using Names = std::vector<std::string>;

// Item 1: a FIFO nobody reads is an error at once (it once blocked forever in open, its temporary file left behind
// when the process was killed); one with a reader gets the whole file; /dev/null keeps working.
TEST_F(CliHostile, AFifoOutputWithNoReaderIsAnErrorNotAHang) {
    const fs::path input = cloud_frame("frame.pcd");
    ASSERT_EQ(::mkfifo(out("fifo.npy").c_str(), 0600), 0);
    const CliRun r = pyrseg::cli_test::run_with_env(
        "TMPDIR=" + (dir_ / "tmp").string() + " timeout -s KILL 20 ",
        "segment " + input.string() + " --backend cpu --labels " + out("fifo.npy") + " --png " + out("a.png"));
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find(out("fifo.npy") + ": is a FIFO with no reader"), std::string::npos) << r.output;
    EXPECT_EQ(files_in(dir_ / "out"), Names{"fifo.npy"}) << r.output;
    EXPECT_EQ(files_in(dir_ / "tmp"), Names{}) << r.output;

    // With a reader: the whole .npy arrives through the FIFO.
    std::string received;
    std::thread reader([&] { received = bytes_of(out("fifo.npy")); });
    const CliRun ok = pyrseg::cli_test::run_with_env(
        "timeout -s KILL 20 ", "segment " + input.string() + " --backend cpu --labels " + out("fifo.npy"));
    if (ok.status != 0) {  // the reader still waits for a writer: give it one, so that the thread ends
        std::ofstream unblock(out("fifo.npy"));
    }
    reader.join();
    EXPECT_EQ(ok.status, 0) << ok.output;
    ASSERT_GT(received.size(), 128u);
    EXPECT_EQ(received.substr(1, 5), "NUMPY");

    // A device is written in place, as before.
    fs::create_symlink("/dev/null", dir_ / "out" / "null.npy");
    const CliRun null = run("segment " + input.string() + " --backend cpu --labels " + out("null.npy"));
    EXPECT_EQ(null.status, 0) << null.output;
}

// Ctrl-C or a SIGTERM while a frame's outputs are being written leaves none of their hidden temporary files (it once
// left ".a.pyrseg-out-PID-N.png" beside a.png). The run is held in the middle of its outputs by a FIFO whose reader
// takes nothing: the labels' 160 x 120 x 4 bytes fill the pipe, and a.png waits, staged, for its rename.
TEST_F(CliHostile, ATerminationSignalMidOutputLeavesNoTemporaryFile) {
    const fs::path input = cloud_frame("frame.pcd", 160, 120);
    for (const int signal_number : {SIGTERM, SIGINT}) {
        SCOPED_TRACE("signal " + std::to_string(signal_number));
        fs::remove_all(dir_ / "out");
        fs::create_directories(dir_ / "out");
        const std::string fifo = out("fifo.npy");
        ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
        const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
        ASSERT_GE(reader, 0);
        std::fflush(nullptr);
        const pid_t pid = ::fork();
        if (pid == 0) {
            // A child of the test's shell would inherit a SIGINT ignored; the CLI must see it as a terminal sends it.
            std::signal(SIGINT, SIG_DFL);
            const std::string tmp = "TMPDIR=" + (dir_ / "tmp").string();
            ::putenv(const_cast<char*>(tmp.c_str()));
            ::execl(PYRSEG_CLI_PATH, PYRSEG_CLI_PATH, "segment", input.c_str(), "--backend", "cpu", "--labels",
                    fifo.c_str(), "--png", out("a.png").c_str(), "-q", static_cast<char*>(nullptr));
            ::_exit(127);
        }
        ASSERT_GT(pid, 0);
        // Held once the pipe is full (64 KiB on Linux, the labels 76,928 bytes): the writer waits on the reader.
        int queued = 0;
        for (int i = 0; i < 2000 && queued < 65536; ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
            if (::ioctl(reader, FIONREAD, &queued) != 0) queued = 0;
        }
        EXPECT_GE(queued, 65536) << "the run never filled the FIFO";
        bool staged = false;
        for (const std::string& name : files_in(dir_ / "out")) staged |= name.starts_with(".a.pyrseg-out-");
        EXPECT_TRUE(staged) << "a.png's temporary file was not there while the run was held";
        ::kill(pid, signal_number);
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        ::close(reader);
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number)
            << "the run should end by the signal, as without a handler";
        EXPECT_EQ(files_in(dir_ / "out"), Names{"fifo.npy"});
        EXPECT_EQ(files_in(dir_ / "tmp"), Names{});
    }
}

// The library's writers have the same promise: a FIFO with no reader is a pyrseg::Error(io), never a hang.
TEST_F(CliHostile, TheLibrarysWritersRefuseAFifoWithNoReader) {
    ASSERT_EQ(::mkfifo(out("fifo.npy").c_str(), 0600), 0);
    ASSERT_EQ(::mkfifo(out("fifo.png").c_str(), 0600), 0);
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::alarm(20);
        const std::vector<std::uint16_t> pixels(16 * 8, 7);
        const std::vector<std::uint32_t> labels(16 * 8, 7);
        int refused = 0;
        for (const char* name : {"fifo.npy", "fifo.png"}) {
            try {
                const fs::path path = out(name);
                if (path.extension() == ".npy") {
                    pyrseg::io::write_npy(path, labels.data(), 8, 16);
                } else {
                    pyrseg::io::write_png_gray16(path, pixels.data(), 16, 8);
                }
            } catch (const pyrseg::Error& e) {
                if (e.code() == pyrseg::ErrorCode::io &&
                    std::string(e.what()).find(std::string(name) + ": is a FIFO with no reader") != std::string::npos)
                    ++refused;
            }
        }
        ::_exit(refused == 2 ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
        << (WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status)) + " (a hang)"
                                : "exit " + std::to_string(WEXITSTATUS(status)) + " (not the FIFO error)");
    // A symbolic link to /dev/null is still written in place.
    fs::create_symlink("/dev/null", dir_ / "out" / "null.npy");
    const std::vector<std::uint32_t> labels(16 * 8, 3);
    EXPECT_NO_THROW(pyrseg::io::write_npy(out("null.npy"), labels.data(), 8, 16));
}

// Item 2: a batch's output may not replace another input of the batch (a.npy's labels are a.labels.npy, the second
// input; x.pcd's colour picture is x.png, a depth image of the batch). Refused before anything is read.
TEST_F(CliHostile, ABatchOutputThatIsAnotherInputIsRefused) {
    const fs::path a = npy_frame("a.npy");
    const fs::path a_labels = npy_frame("a.labels.npy");
    const std::string before = bytes_of(a_labels);
    SplitRun r = run_split("segment " + a.string() + " " + a_labels.string() + " --backend cpu --out-dir " +
                               dir_.string() + " --progress lines",
                           err_file());
    EXPECT_EQ(r.status, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("a.labels.npy"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("is an input of the batch"), std::string::npos) << r.err;
    EXPECT_EQ(bytes_of(a_labels), before);

    std::string k;
    const fs::path x_cloud = cloud_frame("x.pcd");
    const fs::path x_depth = depth_frame("x.png", k);
    const std::string depth_before = bytes_of(x_depth);
    r = run_split(
        "segment " + x_cloud.string() + " " + x_depth.string() + k + " --backend cpu --out-dir " + dir_.string(),
        err_file());
    EXPECT_EQ(r.status, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("x.png"), std::string::npos) << r.err;
    EXPECT_EQ(bytes_of(x_depth), depth_before);
}

// ... nor another frame's output: a.pcd's mask and a.mask.pcd's colour picture are both a.mask.png by the naming
// rule; one of them is renamed, and both are written.
TEST_F(CliHostile, BatchOutputsAreDistinctFromEachOther) {
    const fs::path a = cloud_frame("a.pcd");
    const fs::path a_mask = cloud_frame("a.mask.pcd", 64, 48, 9);
    const SplitRun r =
        run_split("segment " + a.string() + " " + a_mask.string() +
                      " --backend cpu --write png,mask --progress none --out-dir " + (dir_ / "out").string(),
                  err_file());
    EXPECT_EQ(r.status, 0) << r.out << r.err;
    EXPECT_EQ(files_in(dir_ / "out").size(), 4u) << r.out << r.err;
}

// Item 3: two outputs naming the same file: one would be lost. Refused before the input is read (it does not exist
// here), naming both options; also when the names are spelt differently.
TEST_F(CliHostile, TwoOutputsNamingTheSameFileAreRefused) {
    CliRun r =
        run("segment " + (dir_ / "missing.pcd").string() + " --labels " + out("o.png") + " --png " + out("o.png"));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--labels and --png name the same file"), std::string::npos) << r.output;
    const fs::path input = cloud_frame("frame.pcd");
    r = run("segment " + input.string() + " --backend cpu --mask-png " + out("o.png") + " --figure " +
            (dir_ / "out" / "." / "o.png").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--mask-png and --figure name the same file"), std::string::npos) << r.output;
    EXPECT_EQ(files_in(dir_ / "out"), Names{}) << r.output;
    // Relative names, one spelt with ./ (std::filesystem::weakly_canonical makes only that one absolute).
    r = run("segment " + input.string() + " --backend cpu --labels o.png --png ./o.png");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--labels and --png name the same file"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists("o.png"));
}

// Item 4: a batch mixing depth images and a cloud, with a depth image's option: the cloud frame fails like any
// failed frame, the frames after it are segmented, and the summary is printed.
TEST_F(CliHostile, AMixedBatchReportsTheFrameAnOptionDoesNotFitAndGoesOn) {
    std::string k;
    const fs::path d1 = depth_frame("d1.png", k);
    const fs::path cloud = cloud_frame("c.pcd");
    const fs::path d2 = depth_frame("d2.png", k);
    const SplitRun r = run_split("segment " + d1.string() + " " + cloud.string() + " " + d2.string() + k +
                                     " --backend cpu --progress lines --out-dir " + (dir_ / "out").string(),
                                 err_file());
    EXPECT_EQ(r.status, 1) << r.out << r.err;
    EXPECT_NE(r.out.find("batch: 3 frames, 2 segmented, 1 failed"), std::string::npos) << r.out << r.err;
    EXPECT_NE(r.out.find("c.pcd: --intrinsics applies to depth images"), std::string::npos) << r.out << r.err;
    EXPECT_TRUE(fs::exists(dir_ / "out" / "d2.labels.npy")) << r.out << r.err;
}

// Item 5: --quiet leaves stderr to errors and warnings (stdout keeps the results); the backend line is short, and
// -v gives its full reason.
TEST_F(CliHostile, QuietSaysNothingButErrorsAndTheBackendLineIsShort) {
    const fs::path input = cloud_frame("frame.pcd");
    SplitRun r = run_split("segment " + input.string(), err_file());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::size_t at = r.err.find("pyrseg: backend ");
    ASSERT_NE(at, std::string::npos) << r.err;
    const std::string line = r.err.substr(at, r.err.find('\n', at) - at);
    EXPECT_LE(line.size(), 80u) << line;
    r = run_split("segment " + input.string() + " -v", err_file());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("pyrseg: backend "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("auto: "), std::string::npos) << r.err;

    r = run_split("segment " + input.string() + " --quiet --labels " + out("a.npy"), err_file());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_NE(r.out.find("frame.pcd: PCD"), std::string::npos) << r.out;
    // A cloud in metres: the note saying so is not printed either.
    pyrseg::io::PointCloud metres = pyrseg::cli_test::scene_cloud(64, 48, 5, 4);
    for (float& v : metres.points) v /= 1000.0f;
    pyrseg::io::write_pcd(dir_ / "m.pcd", metres, pyrseg::io::PcdEncoding::binary);
    r = run_split(
        "segment " + (dir_ / "m.pcd").string() + " " + input.string() + " --quiet --out-dir " + (dir_ / "out").string(),
        err_file());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_NE(r.out.find("batch: 2 frames, 2 segmented"), std::string::npos) << r.out;
    // Errors still are.
    r = run_split("segment " + (dir_ / "missing.pcd").string() + " --quiet", err_file());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("missing.pcd"), std::string::npos) << r.err;
}

// Item 6: the first frame's time includes the warm-up (kernel builds, first-touch allocation) and is told apart.
TEST_F(CliHostile, TheFirstFramesTimeIsToldApartAsWarmUp) {
    const fs::path input = cloud_frame("frame.pcd");
    SplitRun r = run_split("segment " + input.string() + " --backend cpu", err_file());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find(" ms on cpu, including warm-up"), std::string::npos) << r.out;
    const fs::path second = cloud_frame("second.pcd");
    const fs::path third = cloud_frame("third.pcd");
    r = run_split("segment " + input.string() + " " + second.string() + " " + third.string() +
                      " --backend cpu --progress none --out-dir " + (dir_ / "out").string(),
                  err_file());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("segmentation: the first frame "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(" ms (warm-up), the others "), std::string::npos) << r.out;
}

// Item 7: an output folder that does not exist is named as such, before the input is read; an empty --out-dir is
// a usage error.
TEST_F(CliHostile, AMissingOutputFolderIsNamed) {
    const fs::path input = cloud_frame("frame.pcd");
    CliRun r = run("segment " + input.string() + " --backend cpu --labels " + (dir_ / "nope" / "a.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("the folder " + (dir_ / "nope").string() + " does not exist"), std::string::npos)
        << r.output;
    r = run("segment " + input.string() + " --out-dir ''");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--out-dir needs a folder name"), std::string::npos) << r.output;
    // A folder that is a file.
    r = run("segment " + input.string() + " --out-dir " + input.string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("is a file, not a folder"), std::string::npos) << r.output;
    // An output that is a folder: refused before the input is read.
    fs::create_directories(dir_ / "out" / "d.npy");
    r = run("segment " + (dir_ / "missing.pcd").string() + " --labels " + out("d.npy"));
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find(out("d.npy") + ": is a folder"), std::string::npos) << r.output;
}

// Item 8: a full stdout is an error, not exit status 0.
TEST_F(CliHostile, AFullStdoutIsAnError) {
    const fs::path input = cloud_frame("frame.pcd");
    SplitRun r = run_split("segment " + input.string() + " --backend cpu", err_file(), ">/dev/full");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("pyrseg: cannot write to standard output"), std::string::npos) << r.err;
    r = run_split("segment --help", err_file(), ">/dev/full");
    EXPECT_EQ(r.status, 1) << r.err;
}

// Item 9: a newline (or any control character) in a file name is printed escaped: a line is one line.
TEST_F(CliHostile, ControlCharactersInNamesArePrintedEscaped) {
    const fs::path input = cloud_frame("new\nline.pcd");
    SplitRun r = run_split("segment '" + input.string() + "' --backend cpu --labels " + out("a.npy"), err_file());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.find("new\nline"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("new\\nline.pcd"), std::string::npos) << r.out;
    r = run_split("segment '" + (dir_ / "gone\x1b[2Jaway.pcd").string() + "'", err_file());
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("gone\\x1b[2Jaway.pcd"), std::string::npos) << r.err;
    r = run_split(
        "segment '" + input.string() + "' --backend cpu --progress lines --out-dir " + (dir_ / "out").string(),
        err_file());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("new\nline"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("new\\nline.pcd"), std::string::npos) << r.err;
}

}  // namespace
