#pragma once
// File reads and writes with pyrseg::Error messages that name the file, shared by the format readers.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io::detail {

// "<path>: <what>", the shape every io message takes.
[[noreturn]] void fail(ErrorCode code, const std::filesystem::path& path, std::string_view what);

// A file's bytes quoted in a message: control and non-ASCII bytes as '?', so that a message stays one line of text.
// (File names are the CLI's to print, tools/printable.hpp: they keep UTF-8 and escape control characters.)
std::string printable(std::string_view bytes);

// The path's extension in lower case (".png", ".csv"), which picks a format whatever its case.
std::string lower_extension(const std::filesystem::path& path);

// The largest image any reader decodes: 65536 on a side and 2^28 pixels in all (16384 x 16384, 1 GiB of float depth),
// far beyond any camera. Compressed image data can expand far beyond its size in the file (deflate 1032-fold), so the
// file's size alone does not bound what a reader allocates.
constexpr std::uint64_t kMaxImageSide = std::uint64_t{1} << 16;
constexpr std::uint64_t kMaxImagePixels = std::uint64_t{1} << 28;
// ErrorCode::format naming the file (`kind`: "TIFF", "PNG") when width x height is not an image size the readers take;
// called with the header's size, before anything is allocated for the pixels.
void check_image_size(const std::filesystem::path& path, std::string_view kind, std::uint64_t width,
                      std::uint64_t height);

// read_file's default limit: what is read whole (a calibration file) is small; the readers of large formats (PCD,
// PLY, PNG, TIFF, .npy) read from an InputFile instead, bounded by what the header claims and the file holds.
inline constexpr std::uint64_t kMaxWholeFile = std::uint64_t{1} << 30;

// A regular file open for reading (directories, FIFOs and devices are refused: they would fail or never end), and
// its size at opening. Readers check a format's magic and header from its first bytes before reading more, and
// bound every read by what the file holds, so that a lying header or a huge sparse file costs an error, not memory.
class InputFile {
public:
    explicit InputFile(const std::filesystem::path& path);

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    [[nodiscard]] std::uint64_t size() const { return size_; }
    [[nodiscard]] std::FILE* get() const { return file_.get(); }

    // Up to `n` bytes from the current position; fewer only at the end of the file. Throws ErrorCode::io on a read
    // error; read_some_nothrow returns fewer bytes then (ferror(get()) tells), for callbacks of C libraries that must
    // not be left by an exception.
    std::size_t read_some(void* out, std::size_t n);
    std::size_t read_some_nothrow(void* out, std::size_t n) noexcept;
    // Exactly `n` bytes, or ErrorCode::format: "the file ends before <what> (truncated file?)".
    void read_exact(void* out, std::size_t n, std::string_view what);
    void seek(std::uint64_t offset);

private:
    struct Closer {
        void operator()(std::FILE* f) const noexcept { std::fclose(f); }
    };
    std::filesystem::path path_;
    std::unique_ptr<std::FILE, Closer> file_;
    std::uint64_t size_ = 0;
};

// The lines of a file from byte `start` on, read a block at a time: a line longer than `max_line` bytes ends the
// reading (too_long() tells) rather than being buffered whole (a sparse file of zeros is one line of gigabytes).
class LineReader {
public:
    LineReader(InputFile& file, std::uint64_t start, std::size_t max_line);

    // The next line without its '\n' (valid until the next call); false at the end of the file or of a too long line.
    bool next(std::string_view& line);
    [[nodiscard]] bool too_long() const { return too_long_; }

private:
    void refill();

    InputFile& file_;
    std::size_t max_line_;
    std::vector<char> buffer_;
    std::size_t begin_ = 0, end_ = 0;
    bool eof_ = false, too_long_ = false;
};

// The first `max_bytes` bytes of the file (all of it when shorter).
std::vector<unsigned char> read_head(InputFile& file, std::size_t max_bytes);

// The whole content of a regular file of at most `max_bytes` bytes (ErrorCode::format naming the file otherwise).
std::vector<unsigned char> read_file(const std::filesystem::path& path, std::uint64_t max_bytes = kMaxWholeFile);

// Runs a reader's body so that nothing but a pyrseg::Error naming the file leaves it: std::bad_alloc becomes
// ErrorCode::out_of_memory, any other exception (from a library the reader calls) ErrorCode::format.
template <typename Body>
auto guard_reader(const std::filesystem::path& path, Body&& body) -> decltype(body()) {
    try {
        return body();
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        fail(ErrorCode::out_of_memory, path, "out of memory reading the file");
    } catch (const std::length_error&) {
        fail(ErrorCode::out_of_memory, path, "the file asks for more memory than can be addressed");
    } catch (const std::exception& e) {
        fail(ErrorCode::format, path, std::string("cannot read: ") + e.what());
    } catch (...) {
        fail(ErrorCode::format, path, "cannot read: unknown error");
    }
}

// read_npy, calling `check` with the array's header (dtype and shape; no bytes yet) before its data is read, so
// that a caller's limits on the shape apply before the data costs memory.
NpyArray read_npy(const std::filesystem::path& path, const std::function<void(const NpyArray& header)>& check);

// Writes into a temporary file beside `path` and renames it over `path` once complete, so that a failure (a full
// disk, an exception, a crash) leaves either the old file or none, never a partial one.
void write_file(const std::filesystem::path& path, const void* data, std::size_t size);

// The same for writers that open the file themselves (PCL's): `write_to` writes the temporary file it is given and
// throws on failure; the temporary file is removed then, and renamed over `path` otherwise. Existing targets that
// are not regular files (/dev/null, a FIFO) cannot be replaced: the temporary file is then written in the temporary
// folder and its bytes copied into the target (write_in_place).
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& temporary)>& write_to);

// Writes `size` bytes into an existing file that cannot be replaced (a device such as /dev/null, a FIFO), every
// step checked. A FIFO is opened without blocking: with no reader that is ErrorCode::io "<path>: is a FIFO with no
// reader" at once, never a hang; with one, the bytes are written as to any pipe. The one home of this rule: the
// library's writers and the CLI's outputs both write non-regular files through it.
// Exported (not installed): the pyrseg tool writes its outputs through it, also against the shared libpyrseg_io.
PYRSEG_IO_EXPORT void write_in_place(const std::filesystem::path& path, const void* data, std::size_t size);

// What a cloud writer needs of its cloud: a positive size that fits int, 3 point values per pixel, and 0 or 3
// normal values per pixel. ErrorCode::invalid_argument naming the file otherwise.
void check_cloud_to_write(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace pyrseg::io::detail
