#include "file_util.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <system_error>

namespace pyrseg::io::detail {

namespace {

struct FileCloser {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

std::string errno_text(int err) {
    return std::error_code(err, std::generic_category()).message();
}

}  // namespace

void fail(ErrorCode code, const std::filesystem::path& path, std::string_view what) {
    throw Error(code, path.string() + ": " + std::string(what));
}

std::string printable(std::string_view bytes) {
    std::string shown(bytes);
    for (char& c : shown) {
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    }
    return shown;
}

void check_image_size(const std::filesystem::path& path, std::string_view kind, std::uint64_t width,
                      std::uint64_t height) {
    if (width == 0 || height == 0 || width > kMaxImageSide || height > kMaxImageSide ||
        width * height > kMaxImagePixels) {
        fail(ErrorCode::format, path,
             std::string(kind) + " size " + std::to_string(width) + " x " + std::to_string(height) +
                 " is not an image size pyrseg reads (at most " + std::to_string(kMaxImageSide) + " on a side and " +
                 std::to_string(kMaxImagePixels) + " pixels)");
    }
}

InputFile::InputFile(const std::filesystem::path& path) : path_(path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        fail(ErrorCode::io, path, "cannot open: " + (ec ? ec.message() : errno_text(ENOENT)));
    }
    if (std::filesystem::is_directory(status)) fail(ErrorCode::io, path, "cannot read: is a directory");
    if (!std::filesystem::is_regular_file(status)) fail(ErrorCode::io, path, "cannot read: not a regular file");
    errno = 0;
    file_.reset(std::fopen(path.c_str(), "rb"));
    if (!file_) fail(ErrorCode::io, path, "cannot open: " + errno_text(errno));
    // The size of what was opened, not of what the name points to by now.
    struct stat st {};
    if (::fstat(::fileno(file_.get()), &st) != 0 || st.st_size < 0) {
        fail(ErrorCode::io, path, "cannot read its size: " + errno_text(errno));
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
}

std::size_t InputFile::read_some_nothrow(void* out, std::size_t n) noexcept {
    std::size_t done = 0;
    while (done < n) {
        const std::size_t got = std::fread(static_cast<unsigned char*>(out) + done, 1, n - done, file_.get());
        if (got == 0) break;
        done += got;
    }
    return done;
}

std::size_t InputFile::read_some(void* out, std::size_t n) {
    const std::size_t got = read_some_nothrow(out, n);
    if (got < n && std::ferror(file_.get())) fail(ErrorCode::io, path_, "read error: " + errno_text(errno));
    return got;
}

void InputFile::read_exact(void* out, std::size_t n, std::string_view what) {
    if (read_some(out, n) != n) {
        fail(ErrorCode::format, path_, "the file ends before " + std::string(what) + " (truncated file?)");
    }
}

void InputFile::seek(std::uint64_t offset) {
    if (offset > static_cast<std::uint64_t>(std::numeric_limits<off_t>::max()) ||
        ::fseeko(file_.get(), static_cast<off_t>(offset), SEEK_SET) != 0) {
        fail(ErrorCode::io, path_, "cannot seek to byte " + std::to_string(offset));
    }
}

namespace {
constexpr std::size_t kLineBlock = std::size_t{1} << 20;
}  // namespace

LineReader::LineReader(InputFile& file, std::uint64_t start, std::size_t max_line)
    : file_(file), max_line_(max_line), buffer_(kLineBlock) {
    file_.seek(start);
}

bool LineReader::next(std::string_view& line) {
    for (;;) {
        const char* begin = buffer_.data() + begin_;
        if (const void* nl = std::memchr(begin, '\n', end_ - begin_)) {
            line = std::string_view(begin, static_cast<std::size_t>(static_cast<const char*>(nl) - begin));
            begin_ += line.size() + 1;
            return true;
        }
        if (eof_) {
            if (begin_ == end_ || too_long_) return false;
            line = std::string_view(begin, end_ - begin_);
            begin_ = end_;
            return true;
        }
        refill();
    }
}

void LineReader::refill() {
    if (end_ - begin_ > max_line_) {
        too_long_ = true;
        eof_ = true;
        return;
    }
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
    if (buffer_.size() - end_ < kLineBlock) buffer_.resize(end_ + kLineBlock);
    const std::size_t got = file_.read_some(buffer_.data() + end_, buffer_.size() - end_);
    end_ += got;
    if (got == 0) eof_ = true;
}

std::vector<unsigned char> read_head(InputFile& file, std::size_t max_bytes) {
    std::vector<unsigned char> head(static_cast<std::size_t>(std::min<std::uint64_t>(max_bytes, file.size())));
    head.resize(file.read_some(head.data(), head.size()));
    return head;
}

std::vector<unsigned char> read_file(const std::filesystem::path& path, std::uint64_t max_bytes) {
    return guard_reader(path, [&] {
        InputFile file(path);
        if (file.size() > max_bytes) {
            fail(ErrorCode::format, path,
                 "the file has " + std::to_string(file.size()) + " bytes, more than the " + std::to_string(max_bytes) +
                     " this reader accepts");
        }
        // The size at opening bounds the read: a file that grows meanwhile cannot make it grow without end.
        std::vector<unsigned char> bytes(static_cast<std::size_t>(file.size()));
        bytes.resize(file.read_some(bytes.data(), bytes.size()));
        return bytes;
    });
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& temporary)>& write_to) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (std::filesystem::is_directory(status)) fail(ErrorCode::io, path, "cannot open for writing: is a directory");
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
        write_to(path);
        return;
    }
    // Through a symbolic link the file it names is replaced, not the link.
    std::filesystem::path target = path;
    if (std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) {
        const std::filesystem::path resolved = std::filesystem::weakly_canonical(path, ec);
        if (!ec) target = resolved;
    }
    // Beside the target, so that the rename stays within one file system; pid and a counter keep concurrent
    // writers (threads, processes) of the same target apart.
    static std::atomic<unsigned> counter{0};
    std::filesystem::path temporary = target;
    std::string name = ".";
    name += target.filename().string();
    name += ".pyrseg-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1)) + ".tmp";
    temporary.replace_filename(name);
    try {
        write_to(temporary);
    } catch (...) {
        std::filesystem::remove(temporary, ec);
        throw;
    }
    std::filesystem::rename(temporary, target, ec);
    if (ec) {
        std::error_code ignored;
        std::filesystem::remove(temporary, ignored);
        fail(ErrorCode::io, path, "cannot replace the file: " + ec.message());
    }
}

void write_file(const std::filesystem::path& path, const void* data, std::size_t size) {
    write_atomically(path, [&](const std::filesystem::path& temporary) {
        errno = 0;
        File file(std::fopen(temporary.c_str(), "wb"));
        // Named by the target: the temporary file is an implementation detail.
        if (!file) fail(ErrorCode::io, path, "cannot open for writing: " + errno_text(errno));
        if (size > 0 && std::fwrite(data, 1, size, file.get()) != size) {
            fail(ErrorCode::io, path, "write error: " + errno_text(errno));
        }
        // Buffered data only reaches the disk at fclose, so a full disk shows up here.
        if (std::fclose(file.release()) != 0) fail(ErrorCode::io, path, "write error: " + errno_text(errno));
    });
}

void check_cloud_to_write(const std::filesystem::path& path, const PointCloud& cloud) {
    if (cloud.width <= 0 || cloud.height <= 0 ||
        static_cast<long long>(cloud.width) * cloud.height > static_cast<long long>(INT_MAX)) {
        fail(ErrorCode::invalid_argument, path,
             "cannot write a " + std::to_string(cloud.width) + " x " + std::to_string(cloud.height) + " cloud");
    }
    const auto n = static_cast<std::size_t>(cloud.width) * static_cast<std::size_t>(cloud.height);
    if (cloud.points.size() != 3 * n) {
        fail(ErrorCode::invalid_argument, path,
             "cloud has " + std::to_string(cloud.points.size()) + " point values, expected 3 x " +
                 std::to_string(cloud.width) + " x " + std::to_string(cloud.height) + " = " + std::to_string(3 * n));
    }
    if (!cloud.normals.empty() && cloud.normals.size() != 3 * n) {
        fail(ErrorCode::invalid_argument, path,
             "cloud has " + std::to_string(cloud.normals.size()) + " normal values, expected 0 or " +
                 std::to_string(3 * n));
    }
}

}  // namespace pyrseg::io::detail
