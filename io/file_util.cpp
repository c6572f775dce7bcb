#include "file_util.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
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

std::vector<unsigned char> read_file(const std::filesystem::path& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        fail(ErrorCode::io, path, "cannot open: " + (ec ? ec.message() : errno_text(ENOENT)));
    }
    if (std::filesystem::is_directory(status)) fail(ErrorCode::io, path, "cannot read: is a directory");
    if (!std::filesystem::is_regular_file(status)) fail(ErrorCode::io, path, "cannot read: not a regular file");

    errno = 0;
    File file(std::fopen(path.c_str(), "rb"));
    if (!file) fail(ErrorCode::io, path, "cannot open: " + errno_text(errno));

    std::vector<unsigned char> bytes;
    // The size is only a hint: the file may change under us, so read to the end rather than trusting it.
    const auto hint = std::filesystem::file_size(path, ec);
    if (!ec && hint < (std::size_t{1} << 40)) bytes.reserve(static_cast<std::size_t>(hint));
    unsigned char chunk[1 << 16];
    for (;;) {
        const std::size_t n = std::fread(chunk, 1, sizeof chunk, file.get());
        bytes.insert(bytes.end(), chunk, chunk + n);
        if (n < sizeof chunk) break;
    }
    if (std::ferror(file.get())) fail(ErrorCode::io, path, "read error: " + errno_text(errno));
    return bytes;
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
