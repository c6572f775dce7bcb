#include "file_util.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <system_error>

#include "temporary_files.hpp"

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

std::string lower_extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
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

namespace {

// Closes the descriptor unless released; write_in_place's own close is checked.
struct Descriptor {
    int fd = -1;
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    explicit Descriptor(int f) : fd(f) {}
    ~Descriptor() {
        if (fd >= 0) ::close(fd);
    }
};

// A hidden name for a temporary copy of `target` in `folder`; pid and a counter keep concurrent writers (threads,
// processes) of the same target apart.
std::filesystem::path temporary_name(const std::filesystem::path& folder, const std::filesystem::path& target) {
    static std::atomic<unsigned> counter{0};
    std::string name = ".";
    name += target.filename().string();
    name += ".pyrseg-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1)) + ".tmp";
    return folder / name;
}

// The bytes a writer left in `temporary` (removed then), for a target that is written in place.
std::vector<unsigned char> take_temporary(const std::filesystem::path& temporary, const std::filesystem::path& path) {
    std::vector<unsigned char> bytes;
    {
        const File file(std::fopen(temporary.c_str(), "rb"));
        if (!file) fail(ErrorCode::io, path, "cannot read back the temporary file: " + errno_text(errno));
        unsigned char chunk[1 << 16];
        std::size_t n = 0;
        while ((n = std::fread(chunk, 1, sizeof chunk, file.get())) > 0) bytes.insert(bytes.end(), chunk, chunk + n);
        if (std::ferror(file.get())) fail(ErrorCode::io, path, "cannot read back the temporary file");
    }
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    return bytes;
}

// SIGPIPE blocked on this thread while it lives, and one it caused discarded: a reader that closes its end of the
// FIFO early costs the writer EPIPE (an error naming the file), not the whole process.
class SigpipeBlocked {
public:
    SigpipeBlocked() {
        sigemptyset(&pipe_);
        sigaddset(&pipe_, SIGPIPE);
        sigset_t pending;
        sigpending(&pending);
        was_pending_ = sigismember(&pending, SIGPIPE) == 1;
        pthread_sigmask(SIG_BLOCK, &pipe_, &old_);
    }
    SigpipeBlocked(const SigpipeBlocked&) = delete;
    SigpipeBlocked& operator=(const SigpipeBlocked&) = delete;
    ~SigpipeBlocked() {
        sigset_t pending;
        sigpending(&pending);
        if (!was_pending_ && sigismember(&pending, SIGPIPE) == 1) {
            const timespec now{};
            sigtimedwait(&pipe_, nullptr, &now);
        }
        pthread_sigmask(SIG_SETMASK, &old_, nullptr);
    }

private:
    sigset_t pipe_{};
    sigset_t old_{};
    bool was_pending_ = false;
};

}  // namespace

void write_in_place(const std::filesystem::path& path, const void* data, std::size_t size) {
    struct stat st {};
    const bool fifo = ::stat(path.c_str(), &st) == 0 && S_ISFIFO(st.st_mode);
    // A FIFO's open blocks until a reader comes, which may be never: O_NONBLOCK makes that ENXIO instead.
    Descriptor out(::open(path.c_str(), O_WRONLY | O_CLOEXEC | (fifo ? O_NONBLOCK : 0)));
    if (out.fd < 0) {
        if (fifo && errno == ENXIO) fail(ErrorCode::io, path, "is a FIFO with no reader");
        fail(ErrorCode::io, path, "cannot open for writing: " + errno_text(errno));
    }
    // With a reader, the writes may wait for it like any pipe's: blocking again, so that they never fail EAGAIN.
    if (fifo) {
        const int flags = ::fcntl(out.fd, F_GETFL);
        if (flags < 0 || ::fcntl(out.fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
            fail(ErrorCode::io, path, "cannot write: " + errno_text(errno));
        }
    }
    const SigpipeBlocked sigpipe_blocked;
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t done = 0; done < size;) {
        const ssize_t n = ::write(out.fd, bytes + done, size - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) fail(ErrorCode::io, path, "write error: " + errno_text(n < 0 ? errno : EIO));
        done += static_cast<std::size_t>(n);
    }
    const int fd = out.fd;
    out.fd = -1;
    if (::close(fd) != 0) fail(ErrorCode::io, path, "write error: " + errno_text(errno));
}

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& temporary)>& write_to) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (std::filesystem::is_directory(status)) fail(ErrorCode::io, path, "cannot open for writing: is a directory");
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
        // Not the target itself: a writer opening a FIFO would block, and one that seeks (TIFF) would fail.
        std::filesystem::path folder = std::filesystem::temp_directory_path(ec);
        if (ec) folder = "/tmp";
        const std::filesystem::path temporary = temporary_name(folder, path);
        const RegisteredTemporary registered(temporary);
        try {
            write_to(temporary);
        } catch (...) {
            std::filesystem::remove(temporary, ec);
            throw;
        }
        const std::vector<unsigned char> bytes = take_temporary(temporary, path);
        write_in_place(path, bytes.data(), bytes.size());
        return;
    }
    // Through a symbolic link the file it names is replaced, not the link.
    std::filesystem::path target = path;
    if (std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) {
        const std::filesystem::path resolved = std::filesystem::weakly_canonical(path, ec);
        if (!ec) target = resolved;
    }
    // Beside the target, so that the rename stays within one file system.
    const std::filesystem::path parent = target.parent_path().empty() ? "." : target.parent_path();
    if (!std::filesystem::is_directory(parent, ec)) {
        fail(ErrorCode::io, path,
             std::filesystem::exists(parent, ec) ? parent.string() + " is not a folder"
                                                 : "the folder " + parent.string() + " does not exist");
    }
    const std::filesystem::path temporary = temporary_name(parent, target);
    const RegisteredTemporary registered(temporary);
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
