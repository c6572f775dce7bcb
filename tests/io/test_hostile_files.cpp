// Hostile files (issue 18): small or sparse files that lie about their contents. Every reader must answer each
// with a pyrseg::Error naming the file, and must neither crash, hang, nor allocate what the file cannot hold.
// Each read runs in a forked child, so that a crash or a hang fails one test instead of the whole run, and so that
// the child's peak address space (VmPeak, reset by fork) measures what the reader asked for; the child's address
// space is also capped, so that a reader that does ask for gigabytes fails fast instead of swapping.
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <new>
#include <sstream>

#include "io_test_util.hpp"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PYRSEG_HOSTILE_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define PYRSEG_HOSTILE_SANITIZED 1
#endif
#endif
#ifndef PYRSEG_HOSTILE_SANITIZED
#define PYRSEG_HOSTILE_SANITIZED 0
#endif

namespace pyrseg::io::test {
namespace {

constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
// What a reader may add to its address space for a file of a few hundred bytes (or a sparse file of zeros).
constexpr std::uint64_t kGrowthAllowed = 256 * kMiB;
// The child's address space cap above what it uses at the fork: beyond kGrowthAllowed, so that the peak still
// shows an allocation a reader should not have made, and small enough that such an allocation fails fast.
constexpr std::uint64_t kCap = 3072 * kMiB;
constexpr unsigned kTimeoutSeconds = 60;

struct Outcome {
    enum Kind { returned, pyrseg_error, other_exception, crashed, timed_out } kind = crashed;
    int code = -1;                  // the ErrorCode of a pyrseg_error
    std::uint64_t peak_growth = 0;  // VmPeak at the end minus VmSize at the start, bytes
    int signal = 0;                 // crashed: the signal
    std::string message;            // what() of the exception
};

// A /proc/self/status field in bytes (VmSize, VmPeak).
std::uint64_t vm_field(const char* name) {
    std::ifstream in("/proc/self/status");
    std::string line;
    const std::string key = std::string(name) + ":";
    while (std::getline(in, line)) {
        if (line.rfind(key, 0) == 0) return std::stoull(line.substr(key.size())) * 1024;
    }
    return 0;
}

void write_all(int fd, const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n <= 0) return;
        done += static_cast<std::size_t>(n);
    }
}

Outcome run_isolated(const std::function<void()>& read) {
    int fds[2];
    if (::pipe(fds) != 0) return {};
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(fds[0]);
        ::alarm(kTimeoutSeconds);
        const std::uint64_t start = vm_field("VmSize");
        if (!PYRSEG_HOSTILE_SANITIZED) {
            const rlimit cap{static_cast<rlim_t>(start + kCap), static_cast<rlim_t>(start + kCap)};
            ::setrlimit(RLIMIT_AS, &cap);
        }
        Outcome o;
        try {
            read();
            o.kind = Outcome::returned;
        } catch (const Error& e) {
            o.kind = Outcome::pyrseg_error;
            o.code = static_cast<int>(e.code());
            o.message = e.what();
        } catch (const std::exception& e) {
            o.kind = Outcome::other_exception;
            o.message = std::string(typeid(e).name()) + ": " + e.what();
        } catch (...) {
            o.kind = Outcome::other_exception;
            o.message = "an exception of unknown type";
        }
        const std::uint64_t peak = vm_field("VmPeak");
        write_all(fds[1], std::to_string(static_cast<int>(o.kind)) + " " + std::to_string(o.code) + " " +
                              std::to_string(peak > start ? peak - start : 0) + "\n" + o.message);
        ::_exit(0);
    }
    ::close(fds[1]);
    std::string text;
    char buffer[4096];
    for (;;) {
        const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
        if (n <= 0) break;
        text.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(fds[0]);
    int status = 0;
    ::waitpid(pid, &status, 0);
    Outcome o;
    if (WIFSIGNALED(status)) {
        o.signal = WTERMSIG(status);
        o.kind = o.signal == SIGALRM ? Outcome::timed_out : Outcome::crashed;
        return o;
    }
    std::istringstream in(text);
    int kind = 0;
    in >> kind >> o.code >> o.peak_growth;
    o.kind = static_cast<Outcome::Kind>(kind);
    in.get();
    std::getline(in, o.message, '\0');
    return o;
}

std::string describe(const Outcome& o) {
    switch (o.kind) {
        case Outcome::returned:
            return "the reader returned (accepted the file)";
        case Outcome::pyrseg_error:
            return "pyrseg::Error: " + o.message;
        case Outcome::other_exception:
            return "a non-pyrseg exception escaped: " + o.message;
        case Outcome::crashed:
            return "the reader crashed with signal " + std::to_string(o.signal);
        case Outcome::timed_out:
            return "the reader did not finish within " + std::to_string(kTimeoutSeconds) + " s";
    }
    return "?";
}

// The read must fail with a pyrseg::Error naming the file, without growing the address space by more than
// kGrowthAllowed; `expected_text`, when given, must appear in the message.
void expect_refused(const std::function<void()>& read, const fs::path& file, const std::string& expected_text = {}) {
    const Outcome o = run_isolated(read);
    ASSERT_EQ(o.kind, Outcome::pyrseg_error) << describe(o);
    EXPECT_NE(o.message.find(file.string()), std::string::npos) << o.message;
    if (!expected_text.empty()) {
        EXPECT_NE(o.message.find(expected_text), std::string::npos) << o.message;
    }
    if (!PYRSEG_HOSTILE_SANITIZED) {
        EXPECT_LE(o.peak_growth, kGrowthAllowed)
            << "the reader's address space grew by " << o.peak_growth / kMiB << " MiB: " << o.message;
    }
}

// ---- PLY

#if PYRSEG_HAVE_PLY

// A 2 x 2 organized binary PLY of `vertices` vertices whose range_grid cells hold the indices `cells`.
std::string range_grid_ply(bool big_endian, const std::vector<std::vector<std::int32_t>>& cells, int vertices = 2) {
    std::string s = xyz_header(big_endian ? "binary_big_endian" : "binary_little_endian", vertices, grid_lines(2, 2),
                               range_grid_lines(cells.size()));
    for (int v = 0; v < vertices; ++v) {
        for (float f : {float(v), float(-v), 1.0f + float(v)}) put(s, f, big_endian);
    }
    for (const auto& cell : cells) {
        s += static_cast<char>(cell.size());
        for (const std::int32_t i : cell) put(s, i, big_endian);
    }
    return s;
}

std::string range_grid_ply_ascii(const std::vector<std::string>& cells) {
    std::string s = xyz_header("ascii", 2, grid_lines(2, 2), range_grid_lines(cells.size())) + "0 0 1\n1 -1 2\n";
    for (const std::string& c : cells) s += c + "\n";
    return s;
}

// The report's kind of file: a range_grid index past the two vertices. PCL 1.13 checks index * point_step +
// point_step against its data in 32-bit unsigned arithmetic, so an index whose product wraps past 2^32 passes the
// check and the copy reads 4 GB away: SIGSEGV. (Indices whose product does not wrap fail inside PCL.)
TEST(HostileFiles, PlyRangeGridIndexFarPastTheVertices) {
    ScratchDir dir;
    const fs::path file = dir / "far.ply";
    write_bytes(file, range_grid_ply(false, {{0}, {1}, {1431655765}, {}}));  // * 12 = 2^34 - 4
    expect_refused([&] { (void)read_ply(file); }, file, "range_grid");
    const fs::path clean = dir / "far_clean.ply";
    write_bytes(clean, range_grid_ply(false, {{0}, {1}, {100000000}, {}}));
    expect_refused([&] { (void)read_ply(clean); }, clean, "range_grid");
}

TEST(HostileFiles, PlyRangeGridNegativeIndex) {
    ScratchDir dir;
    const fs::path file = dir / "negative.ply";
    write_bytes(file, range_grid_ply(true, {{0}, {-1}, {1}, {}}));
    expect_refused([&] { (void)read_ply(file); }, file, "range_grid");
}

// An index equal to the vertex count reads the cell PCL zero-filled: the file loaded, with a point at (0, 0, 0).
// The same grids with indices in range load.
TEST(HostileFiles, PlyRangeGridIndexOnePastTheEnd) {
    ScratchDir dir;
    const fs::path binary = dir / "one_past.ply";
    write_bytes(binary, range_grid_ply(false, {{0}, {1}, {2}, {}}));
    expect_refused([&] { (void)read_ply(binary); }, binary, "range_grid");
    const fs::path ascii = dir / "one_past_ascii.ply";
    write_bytes(ascii, range_grid_ply_ascii({"1 0", "1 1", "0", "1 2"}));
    expect_refused([&] { (void)read_ply(ascii); }, ascii, "range_grid");

    const fs::path valid = dir / "valid.ply";
    write_bytes(valid, range_grid_ply(true, {{1}, {}, {0}, {}}));
    const PointCloud c = read_ply(valid);
    ASSERT_EQ(c.width * c.height, 4);
    EXPECT_EQ(c.points[2], 2.0f);  // cell 0 is vertex 1: (1, -1, 2)
    EXPECT_TRUE(std::isnan(c.points[3]));
    EXPECT_EQ(c.points[8], 1.0f);  // cell 2 is vertex 0
    const fs::path valid_ascii = dir / "valid_ascii.ply";
    write_bytes(valid_ascii, range_grid_ply_ascii({"1 0", "1 1", "0", "0"}));
    EXPECT_EQ(read_ply(valid_ascii).points[5], 2.0f);
}

// PCL allocates point_step bytes for every grid cell, twice; a cell of an empty range_grid list takes one byte of
// the file. A vertex of 800 doubles and 200 x 200 empty cells: a 60 KiB file for which PCL would allocate 512 MB.
TEST(HostileFiles, PlyWideVertexOverAnEmptyGrid) {
    ScratchDir dir;
    const fs::path file = dir / "wide.ply";
    std::string s =
        "ply\nformat binary_little_endian 1.0\nobj_info num_cols 200\nobj_info num_rows 200\n"
        "element vertex 1\nproperty double x\nproperty double y\nproperty double z\n";
    for (int i = 0; i < 797; ++i) s += "property double p" + std::to_string(i) + "\n";
    s += "element range_grid 40000\nproperty list uchar int vertex_indices\nend_header\n";
    for (int i = 0; i < 800; ++i) put(s, 1.0);
    s.append(40000, '\0');
    write_bytes(file, s);
    expect_refused([&] { (void)read_ply(file); }, file);
}

#endif  // PYRSEG_HAVE_PLY

// ---- TIFF

struct TiffEntry {
    std::uint16_t tag, type;
    std::uint32_t count, value;
};

// A little-endian TIFF of one strip: an IFD of the given entries at offset 8, then `data`.
std::string tiff(std::uint32_t width, std::uint32_t height, std::uint16_t compression, std::uint32_t strip_bytes,
                 const std::string& data) {
    std::vector<TiffEntry> entries = {
        {256, 4, 1, width},        // ImageWidth
        {257, 4, 1, height},       // ImageLength
        {258, 3, 1, 32},           // BitsPerSample
        {259, 3, 1, compression},  // Compression
        {262, 3, 1, 1},            // Photometric: min is black
        {273, 4, 1, 0},            // StripOffsets (set below)
        {277, 3, 1, 1},            // SamplesPerPixel
        {278, 4, 1, height},       // RowsPerStrip
        {279, 4, 1, strip_bytes},  // StripByteCounts
        {339, 3, 1, 3},            // SampleFormat: IEEE float
    };
    const std::uint32_t data_offset = 8 + 2 + 12 * static_cast<std::uint32_t>(entries.size()) + 4;
    entries[5].value = data_offset;
    std::string s = "II";
    put(s, std::uint16_t{42});
    put(s, std::uint32_t{8});
    put(s, static_cast<std::uint16_t>(entries.size()));
    for (const TiffEntry& e : entries) {
        put(s, e.tag);
        put(s, e.type);
        put(s, e.count);
        if (e.type == 3) {
            put(s, static_cast<std::uint16_t>(e.value));
            put(s, std::uint16_t{0});
        } else {
            put(s, e.value);
        }
    }
    put(s, std::uint32_t{0});
    return s + data;
}

// The report's 150-byte TIFF claiming 30000 x 30000 floats: 3.6 GB allocated before a byte of data is read.
TEST(HostileFiles, TiffClaimingAHugeImage) {
    ScratchDir dir;
    const fs::path file = dir / "huge.tif";
    const std::string bytes = tiff(30000, 30000, 1, 30000u * 30000u * 4u, std::string(4, '\0'));
    write_bytes(file, bytes);
    expect_refused([&] { (void)read_depth_image(file); }, file);
    const fs::path larger = dir / "larger.tiff";
    write_bytes(larger, tiff(65535, 65535, 1, 4, std::string(4, '\0')));
    expect_refused([&] { (void)read_depth_image(larger); }, larger);
}

// Deflate data (COMPRESSION_ADOBE_DEFLATE) of 12 bytes cannot hold 10000 x 10000 floats, nor can a strip that
// starts past the end of the file.
TEST(HostileFiles, TiffStripsTheFileCannotHold) {
    ScratchDir dir;
    const fs::path deflate = dir / "deflate.tif";
    write_bytes(deflate, tiff(10000, 10000, 8, 12, std::string(12, '\0')));
    expect_refused([&] { (void)read_depth_image(deflate); }, deflate);
    const fs::path missing = dir / "missing.tif";
    write_bytes(missing, tiff(8000, 8000, 1, 8000u * 8000u * 4u, ""));
    expect_refused([&] { (void)read_depth_image(missing); }, missing);
}

// ---- PNG

std::uint32_t crc32(const std::string& bytes) {
    std::uint32_t crc = 0xffffffffu;
    for (const char ch : bytes) {
        crc ^= static_cast<unsigned char>(ch);
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

void chunk(std::string& png, const std::string& type, const std::string& data, std::uint32_t claimed_length) {
    put(png, claimed_length, true);
    png += type + data;
    put(png, crc32(type + data), true);
}

std::string png_ihdr(std::uint32_t width, std::uint32_t height) {
    std::string png = "\x89PNG\r\n\x1a\n";
    std::string ihdr;
    put(ihdr, width, true);
    put(ihdr, height, true);
    ihdr += std::string("\x10\x00\x00\x00\x00", 5);  // 16-bit gray, deflate, no filter, no interlace
    chunk(png, "IHDR", ihdr, 13);
    return png;
}

// The report's 52-byte PNG: a tEXt chunk that claims 2 GiB; libpng allocated it all before reading it.
TEST(HostileFiles, PngTextChunkClaimingGigabytes) {
    ScratchDir dir;
    const fs::path file = dir / "text.png";
    std::string png = png_ihdr(4, 4);
    put(png, std::uint32_t{0x7ffffff0}, true);
    png += std::string("tEXtComment\0xyz", 15);  // 52 bytes in all
    write_bytes(file, png);
    expect_refused([&] { (void)read_png(file); }, file);
    // The depth reader reads PNG through the same reader.
    expect_refused([&] { (void)read_depth_image(file); }, file);
}

// The report's 810 KB PNG claiming 20000 x 20000 16-bit pixels: deflate could hold that much (800 MB of zeros), so
// the file's size let it through, and the reader grew to 2.7 GB before std::bad_alloc. The image size is refused from
// the header, as TIFF's is, before anything is allocated for the pixels; the IDAT here is never decoded.
TEST(HostileFiles, PngClaimingMorePixelsThanAnyCamera) {
    ScratchDir dir;
    const fs::path file = dir / "huge.png";
    std::string png = png_ihdr(20000, 20000);
    const std::string idat(810 * 1024, '\0');
    chunk(png, "IDAT", idat, std::uint32_t(idat.size()));
    chunk(png, "IEND", "", 0);
    write_bytes(file, png);
    expect_refused([&] { (void)read_png(file); }, file, "PNG size 20000 x 20000 is not an image size pyrseg reads");
    expect_refused([&] { (void)read_depth_image(file); }, file, "at most 65536 on a side and 268435456 pixels");
}

// ---- Whole-file reads of sparse files

constexpr std::uint64_t kSparseSize = std::uint64_t{40} << 30;

// `head` followed by zeros up to `size` bytes, as a sparse file; false where the file system would store the zeros
// (probed with 64 MiB first) or refuses the size.
bool make_sparse(const fs::path& file, const std::string& head, std::uint64_t size) {
    write_bytes(file, head);
    std::error_code ec;
    fs::resize_file(file, 64 * kMiB, ec);
    struct stat st {};
    if (ec || ::stat(file.c_str(), &st) != 0 || static_cast<std::uint64_t>(st.st_blocks) * 512 > 16 * kMiB) {
        fs::remove(file, ec);
        return false;
    }
    fs::resize_file(file, size, ec);
    if (ec) fs::remove(file, ec);
    return !ec;
}

// A 40 GB file of zeros costs no disk (it is sparse) but takes 40 GB to read whole: each reader must see from its
// first bytes that it is not its format.
TEST(HostileFiles, SparseFileOfZeros) {
    ScratchDir dir;
    for (const char* name : {"zeros.pcd", "zeros.npy", "zeros.png", "zeros.ply", "zeros.tif"}) {
        const fs::path file = dir / name;
        if (!make_sparse(file, "", kSparseSize)) GTEST_SKIP() << "no sparse files in " << dir.path();
        const std::string ext = file.extension().string();
        if (ext == ".pcd") expect_refused([&] { (void)read_pcd(file); }, file);
        if (ext == ".npy") {
            expect_refused([&] { (void)read_npy(file); }, file);
            expect_refused([&] { (void)read_npy_cloud(file); }, file);
        }
        if (ext == ".png") {
            expect_refused([&] { (void)read_png(file); }, file);
            expect_refused([&] { (void)read_depth_image(file); }, file);
        }
        if (ext == ".ply") expect_refused([&] { (void)read_ply(file); }, file);
        if (ext == ".tif") expect_refused([&] { (void)read_depth_image(file); }, file);
        std::error_code ec;
        fs::remove(file, ec);
    }
}

// Sparse files whose first bytes are a valid header: the header's claims are checked before the data is read.
TEST(HostileFiles, SparseFileWithAValidHeader) {
    ScratchDir dir;
    // ascii data whose first line is 40 GB of NUL bytes
    const fs::path pcd = dir / "ascii.pcd";
    if (!make_sparse(pcd,
                     "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1000\nHEIGHT 1000\n"
                     "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1000000\nDATA ascii\n",
                     kSparseSize)) {
        GTEST_SKIP() << "no sparse files in " << dir.path();
    }
    expect_refused([&] { (void)read_pcd(pcd); }, pcd);
    std::error_code ec;
    fs::remove(pcd, ec);
    // a cloud array too large for a frame, whose 42 GB of data the file does hold
    std::string npy = "\x93NUMPY\x01";
    npy += '\0';
    std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (100000, 35000, 3), }";
    dict.append(117 - dict.size(), ' ');  // 10 + 118 bytes: data 64-aligned
    dict += '\n';
    put(npy, static_cast<std::uint16_t>(dict.size()));
    npy += dict;
    const fs::path array = dir / "cloud.npy";
    ASSERT_TRUE(make_sparse(array, npy, 128 + std::uint64_t{100000} * 35000 * 12));
    expect_refused([&] { (void)read_npy_cloud(array); }, array);
    fs::remove(array, ec);
}

}  // namespace
}  // namespace pyrseg::io::test
