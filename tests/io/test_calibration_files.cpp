// Hostile calibration files (issue 18): read_intrinsics on a few bytes that crashed (truncated XML prolog), hung
// (YAML !!binary) or let a foreign exception escape must end in a pyrseg::Error naming the file. Each read runs in a
// child process under alarm(), so that a crash or a hang fails its test instead of taking the suite with it.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io::test {
namespace {

enum class Outcome { error_naming_file, error_not_naming_file, foreign_exception, no_error, crashed, hung };

const char* to_string(Outcome o) {
    switch (o) {
        case Outcome::error_naming_file:
            return "a pyrseg::Error naming the file";
        case Outcome::error_not_naming_file:
            return "a pyrseg::Error without the file's name";
        case Outcome::foreign_exception:
            return "an exception that is not a pyrseg::Error";
        case Outcome::no_error:
            return "no error";
        case Outcome::crashed:
            return "a crash";
        case Outcome::hung:
            return "a hang (killed after 10 s)";
    }
    return "?";
}

// read_intrinsics(path, node) in a child process; what happened, as the child's exit status tells it.
Outcome read_in_child(const fs::path& path, const std::string& node = "") {
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::alarm(10);
        int status = 0;
        try {
            (void)read_intrinsics(path, node);
            status = 3;
        } catch (const Error& e) {
            status = std::string(e.what()).find(path.filename().string()) != std::string::npos ? 1 : 2;
        } catch (...) {
            status = 4;
        }
        ::_exit(status);
    }
    int status = 0;
    if (pid < 0 || ::waitpid(pid, &status, 0) != pid) return Outcome::crashed;
    if (WIFSIGNALED(status)) return WTERMSIG(status) == SIGALRM ? Outcome::hung : Outcome::crashed;
    switch (WEXITSTATUS(status)) {
        case 1:
            return Outcome::error_naming_file;
        case 2:
            return Outcome::error_not_naming_file;
        case 3:
            return Outcome::no_error;
        default:
            return Outcome::foreign_exception;
    }
}

struct HostileFile {
    const char* name;
    std::string bytes;
    const char* node = "";
};

void expect_errors(const std::vector<HostileFile>& files) {
    ScratchDir dir;
    for (const HostileFile& f : files) {
        write_bytes(dir / f.name, f.bytes);
        const Outcome o = read_in_child(dir / f.name, f.node);
        EXPECT_STREQ(to_string(o), to_string(Outcome::error_naming_file))
            << f.name << " (" << f.bytes.substr(0, 60) << "...)";
    }
}

TEST(CalibrationFiles, TruncatedXmlPrologIsAnErrorNotACrash) {
    // OpenCV 4.6's XML parser dereferenced NULL on the first of these.
    expect_errors({{"prolog.xml", "<?xml version="},
                   {"prolog2.xml", "<?xml version=\"1.0\""},
                   {"prolog3.xml", "<?xml"},
                   {"open.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>"},
                   {"empty.xml", ""},
                   {"nul.xml", std::string("<\0?xml", 6)}});
}

TEST(CalibrationFiles, YamlBinaryIsAnErrorNotAHang) {
    // base64 of a header of 24 spaces: OpenCV 4.6 decoded it forever.
    expect_errors({{"binary.yml", "%YAML:1.0\na: !!binary |\n  ICAgICAgICAgICAgICAgICAgICAgICAg\n"},
                   {"binary2.yml", "%YAML:1.0\n---\ncamera_matrix: !!binary |\n  MSAgICAgICAgICAgICAgICAgICAgICAg\n",
                    "camera_matrix"},
                   {"binary3.yml", "%YAML:1.0\na: !!binary\n"}});
}

TEST(CalibrationFiles, MalformedNodesAreErrorsNamingTheFile) {
    expect_errors({
        {"no_dt.xml",
         "<?xml version=\"1.0\"?><opencv_storage><K type_id=\"opencv-matrix\"><rows>3</rows><cols>3</cols>"
         "<data>1 0 1 0 1 1 0 0 1</data></K></opencv_storage>",
         "K"},
        {"bad_dt.xml",
         "<?xml version=\"1.0\"?><opencv_storage><K type_id=\"opencv-matrix\"><rows>3</rows><cols>3</cols><dt>q</dt>"
         "<data>1 0 1 0 1 1 0 0 1</data></K></opencv_storage>",
         "K"},
        {"short_data.xml",
         "<?xml version=\"1.0\"?><opencv_storage><K type_id=\"opencv-matrix\"><rows>3</rows><cols>3</cols><dt>d</dt>"
         "<data>1 0 1</data></K></opencv_storage>"},
        {"text_fx.yml", "%YAML:1.0\n---\nfx: a\nfy: b\ncx: c\ncy: d\n"},
        {"map_fx.yml", "%YAML:1.0\n---\nK:\n  fx: {a: 1}\n  fy: 1\n  cx: 1\n  cy: 1\n", "K"},
        {"sequence.yml", "%YAML:1.0\n---\n- 1\n- 2\n", "K"},
        {"unclosed.yml", "%YAML:1.0\n---\nK: [1, 2\n"},
        {"deep.yml", "%YAML:1.0\n---\nK: " + std::string(100000, '[')},
        {"deep.json", "{\"K\": " + std::string(100000, '[')},
        {"deep.xml", "<?xml version=\"1.0\"?><opencv_storage>" + std::string(100000, '<') + "a>"},
        {"array.json", "[1, 2, 3]"},
        {"gzip.xml.gz", std::string("\x1f\x8b\x08\x00\x00\x00\x00\x00", 8)},
        {"binary.json", "{\"K\": \"\\u0000\"}", "K"},
    });
}

// Calibrations are kilobytes: a valid one padded to 8 MiB is refused rather than handed to a parser.
TEST(CalibrationFiles, TooLargeFileIsRefused) {
    expect_errors({{"huge.yml",
                    "%YAML:1.0\n---\nfx: 1\nfy: 1\ncx: 1\ncy: 1\n# " + std::string(std::size_t{8} << 20, 'x') + "\n"}});
}

// The layouts OpenCV writes, in all three formats, still give their intrinsics.
TEST(CalibrationFiles, OpenCvLayoutsInXmlYamlAndJson) {
    ScratchDir dir;
    write_bytes(dir / "k.yml",
                "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                "   data: [ 5.2e+02, 0., 3.2e+02, 0., 5.21e+02, 2.4e+02, 0., 0., 1. ]\n"
                "dist: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n");
    write_bytes(dir / "k.json",
                "{\n  \"camera_matrix\": {\"type_id\": \"opencv-matrix\", \"rows\": 3, \"cols\": 3, \"dt\": \"f\",\n"
                "    \"data\": [520.0, 0.0, 320.0, 0.0, 521.0, 240.0, 0.0, 0.0, 1.0]}\n}\n");
    write_bytes(dir / "k.xml",
                "\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<opencv_storage>\n<fx>520.</fx><fy>521.</fy><cx>320</cx>"
                "<cy>240</cy>\n</opencv_storage>\n");
    for (const char* name : {"k.yml", "k.json", "k.xml"}) {
        const Intrinsics k = read_intrinsics(dir / name);
        EXPECT_DOUBLE_EQ(k.fx, 520.0) << name;
        EXPECT_DOUBLE_EQ(k.fy, 521.0) << name;
        EXPECT_DOUBLE_EQ(k.cx, 320.0) << name;
        EXPECT_DOUBLE_EQ(k.cy, 240.0) << name;
    }
    EXPECT_DOUBLE_EQ(read_intrinsics(dir / "k.yml", "camera_matrix").fy, 521.0);
}

}  // namespace
}  // namespace pyrseg::io::test
