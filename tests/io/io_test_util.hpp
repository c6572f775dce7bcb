#pragma once
// Shared helpers for the io tests: a scratch folder per test, raw file access, clouds to round-trip, and a PCD
// builder that can produce what pyrseg's writer never does (F 8, I/U fields, padding, COUNT > 1).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "io/lzf_block.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io::test {

namespace fs = std::filesystem;

// A fresh folder under the system temp dir, removed at the end of the test.
class ScratchDir {
public:
    ScratchDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name =
            std::string("pyrseg_io_") + info->test_suite_name() + "_" + info->name() + "_" + std::to_string(::getpid());
        for (char& c : name) {
            if (c == '/') c = '_';
        }
        dir_ = fs::temp_directory_path() / name;
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    ~ScratchDir() {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    [[nodiscard]] fs::path operator/(const std::string& file) const { return dir_ / file; }
    [[nodiscard]] const fs::path& path() const { return dir_; }

private:
    fs::path dir_;
};

inline std::string read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The names of the entries of `dir` (a write must leave no temporary file behind).
inline std::vector<fs::path> files_in(const fs::path& dir) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path().filename());
    std::sort(files.begin(), files.end());
    return files;
}

inline void write_bytes(const fs::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(out.good()) << path;
}

// How `write` ends in a child process whose files may not grow past 64 KiB, as a full disk would stop it (the
// limit is process-wide, hence the child): "no error", "io error naming <name>", or "other error".
inline std::string outcome_of_write_past_size_limit(const std::function<void()>& write, const std::string& name) {
    const pid_t child = ::fork();
    if (child < 0) return "fork failed";
    if (child == 0) {
        std::signal(SIGXFSZ, SIG_IGN);  // the write then fails with EFBIG instead of killing the process
        const rlimit limit{rlim_t{64} * 1024, rlim_t{64} * 1024};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        try {
            write();
        } catch (const Error& e) {
            const bool named = std::string(e.what()).find(name) != std::string::npos;
            ::_exit(e.code() == ErrorCode::io && named ? 3 : 4);
        }
        ::_exit(0);
    }
    int status = 0;
    if (::waitpid(child, &status, 0) != child || !WIFEXITED(status)) return "child did not exit";
    switch (WEXITSTATUS(status)) {
        case 0:
            return "no error";
        case 3:
            return "io error naming " + name;
        default:
            return "other error";
    }
}

// `value`'s bytes appended to `out`, in host (little-endian) or big-endian order.
template <typename T>
void put(std::string& out, T value, bool big_endian = false) {
    char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    if (big_endian) std::reverse(bytes, bytes + sizeof value);
    out.append(bytes, sizeof value);
}

// PLY headers: x y z float vertices with `extra` lines before the vertex element and `after` lines after it.
inline std::string xyz_header(const std::string& format, int vertices, const std::string& extra,
                              const std::string& after = "") {
    return "ply\nformat " + format + " 1.0\n" + extra + "element vertex " + std::to_string(vertices) +
           "\nproperty float x\nproperty float y\nproperty float z\n" + after + "end_header\n";
}

inline std::string grid_lines(int w, int h) {
    return "obj_info num_cols " + std::to_string(w) + "\nobj_info num_rows " + std::to_string(h) + "\n";
}

// PCL's range_grid element: one list of vertex indices per grid cell.
inline std::string range_grid_lines(std::size_t cells) {
    return "element range_grid " + std::to_string(cells) + "\nproperty list uchar int vertex_indices\n";
}

// A small organized cloud: a tilted plane with a few NaN points (and NaN normals at the same pixels).
inline PointCloud make_cloud(int width, int height, bool normals) {
    PointCloud c;
    c.width = width;
    c.height = height;
    const auto n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    c.points.resize(3 * n);
    if (normals) c.normals.resize(3 * n);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t i = 0; i < n; ++i) {
        const float x = static_cast<float>(i % static_cast<std::size_t>(width)) * 0.01f - 0.3f;
        const std::size_t row = i / static_cast<std::size_t>(width);
        const float y = static_cast<float>(row) * 0.013f - 0.2f;
        const bool invalid = i % 7 == 3;
        c.points[3 * i] = invalid ? nan : x;
        c.points[3 * i + 1] = invalid ? nan : y;
        c.points[3 * i + 2] = invalid ? nan : 1.5f + 0.1f * x - 0.37f * y + 1e-7f * static_cast<float>(i);
        if (normals) {
            c.normals[3 * i] = invalid ? nan : 0.0990147543f;
            c.normals[3 * i + 1] = invalid ? nan : -0.366354591f;
            c.normals[3 * i + 2] = invalid ? nan : -0.925188f;
        }
    }
    return c;
}

// Equal values, NaN matching NaN.
inline void expect_same_floats(const std::vector<float>& a, const std::vector<float>& b, const char* what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::isnan(a[i]) || std::isnan(b[i])) {
            EXPECT_TRUE(std::isnan(a[i]) && std::isnan(b[i]))
                << what << " value " << i << ": " << a[i] << " vs " << b[i];
        } else {
            EXPECT_EQ(a[i], b[i]) << what << " value " << i;
        }
    }
}

inline void expect_same_cloud(const PointCloud& a, const PointCloud& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    expect_same_floats(a.points, b.points, "points");
    expect_same_floats(a.normals, b.normals, "normals");
}

// ---- building arbitrary PCD files

struct FieldSpec {
    std::string name;
    char type = 'F';
    int size = 4;
    int count = 1;
};

// values[i] holds point i's values in field order (count values per field), written in the field's type.
inline std::string pcd_header(const std::vector<FieldSpec>& fields, int width, int height, const std::string& data) {
    std::string names, sizes, types, counts;
    for (const auto& f : fields) {
        names += " " + f.name;
        sizes += " " + std::to_string(f.size);
        types += std::string(" ") + f.type;
        counts += " " + std::to_string(f.count);
    }
    return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS" + names + "\nSIZE" + sizes + "\nTYPE" +
           types + "\nCOUNT" + counts + "\nWIDTH " + std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
           "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(static_cast<long long>(width) * height) + "\nDATA " +
           data + "\n";
}

inline void append_value(std::string& out, const FieldSpec& f, double v) {
    auto put = [&](auto x) {
        char buf[sizeof x];
        std::memcpy(buf, &x, sizeof x);
        out.append(buf, sizeof x);
    };
    if (f.type == 'F') {
        if (f.size == 4)
            put(static_cast<float>(v));
        else
            put(v);
    } else if (f.type == 'I') {
        const auto i = static_cast<std::int64_t>(v);
        if (f.size == 1)
            put(static_cast<std::int8_t>(i));
        else if (f.size == 2)
            put(static_cast<std::int16_t>(i));
        else if (f.size == 4)
            put(static_cast<std::int32_t>(i));
        else
            put(i);
    } else {
        const auto u = static_cast<std::uint64_t>(v);
        if (f.size == 1)
            put(static_cast<std::uint8_t>(u));
        else if (f.size == 2)
            put(static_cast<std::uint16_t>(u));
        else if (f.size == 4)
            put(static_cast<std::uint32_t>(u));
        else
            put(u);
    }
}

inline std::string ascii_value(const FieldSpec& f, double v) {
    if (std::isnan(v)) return "nan";
    char buf[64];
    std::to_chars_result r{};
    if (f.type == 'F')
        r = std::to_chars(buf, buf + sizeof buf, v);
    else if (f.type == 'I')
        r = std::to_chars(buf, buf + sizeof buf, static_cast<std::int64_t>(v));
    else
        r = std::to_chars(buf, buf + sizeof buf, static_cast<std::uint64_t>(v));
    return std::string(buf, r.ptr);
}

inline std::string pcd_body(const std::vector<FieldSpec>& fields, const std::vector<std::vector<double>>& values,
                            const std::string& data) {
    std::string out;
    if (data == "ascii") {
        for (const auto& point : values) {
            std::size_t k = 0;
            for (const auto& f : fields) {
                for (int c = 0; c < f.count; ++c, ++k) {
                    if (k > 0) out += ' ';
                    out += ascii_value(f, point[k]);
                }
            }
            out += "\n";
        }
        return out;
    }
    if (data == "binary") {
        for (const auto& point : values) {
            std::size_t k = 0;
            for (const auto& f : fields) {
                for (int c = 0; c < f.count; ++c, ++k) append_value(out, f, point[k]);
            }
        }
        return out;
    }
    // binary_compressed: each field's values for all points, then LZF.
    std::string raw;
    std::size_t first = 0;
    for (const auto& f : fields) {
        for (const auto& point : values) {
            for (int c = 0; c < f.count; ++c) append_value(raw, f, point[first + static_cast<std::size_t>(c)]);
        }
        first += static_cast<std::size_t>(f.count);
    }
    const auto packed = detail::lzf_pack(raw.data(), raw.size());
    const auto c = static_cast<std::uint32_t>(packed.size());
    const auto u = static_cast<std::uint32_t>(raw.size());
    out.append(reinterpret_cast<const char*>(&c), 4);
    out.append(reinterpret_cast<const char*>(&u), 4);
    out.append(reinterpret_cast<const char*>(packed.data()), packed.size());
    return out;
}

inline std::string build_pcd(const std::vector<FieldSpec>& fields, int width, int height,
                             const std::vector<std::vector<double>>& values, const std::string& data) {
    return pcd_header(fields, width, height, data) + pcd_body(fields, values, data);
}

// Runs f and reports how it ended: "ok", "error" (pyrseg::Error) or, as a test failure, anything else.
inline std::string outcome(const std::function<void()>& f, std::string* message = nullptr, ErrorCode* code = nullptr) {
    try {
        f();
        return "ok";
    } catch (const Error& e) {
        if (message) *message = e.what();
        if (code) *code = e.code();
        return "error";
    } catch (const std::exception& e) {
        ADD_FAILURE() << "unexpected exception: " << e.what();
        return "other";
    } catch (...) {
        ADD_FAILURE() << "unexpected non-std exception";
        return "other";
    }
}

// Runs `load` on the file; expects a pyrseg::Error of the given code naming the file, and returns its message.
inline std::string expect_load_error(const fs::path& path, const std::function<void()>& load,
                                     ErrorCode expected_code = ErrorCode::format) {
    std::string message;
    ErrorCode code{};
    const std::string result = outcome(load, &message, &code);
    EXPECT_EQ(result, "error") << "loaded without error: " << read_bytes(path).substr(0, 300);
    if (result == "error") {
        EXPECT_EQ(code, expected_code) << message;
        EXPECT_NE(message.find(path.filename().string()), std::string::npos) << "message names no file: " << message;
    }
    return message;
}

inline void expect_load_error_containing(const fs::path& path, const std::function<void()>& load,
                                         const std::string& text) {
    const std::string message = expect_load_error(path, load);
    EXPECT_NE(message.find(text), std::string::npos) << "'" << text << "' not in: " << message;
}

inline const std::vector<std::string>& encodings() {
    static const std::vector<std::string> names = {"ascii", "binary", "binary_compressed"};
    return names;
}

inline PcdEncoding encoding_of(const std::string& name) {
    if (name == "ascii") return PcdEncoding::ascii;
    if (name == "binary") return PcdEncoding::binary;
    return PcdEncoding::binary_compressed;
}

}  // namespace pyrseg::io::test
