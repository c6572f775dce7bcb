#include "tools/output_files.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "io/file_util.hpp"
#include "pyrseg/error.hpp"
#include "tools/printable.hpp"

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;

struct FileCloser {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
    throw Error(ErrorCode::io, printable(path) + ": " + what);
}

std::string errno_text(int err) {
    return std::error_code(err, std::generic_category()).message();
}

// A hidden name in `folder` that keeps the target's extension (the io writers choose a format by it); the pid and
// a counter keep concurrent runs and several outputs apart.
fs::path temporary_name(const fs::path& folder, const fs::path& target) {
    static std::atomic<unsigned> counter{0};
    std::string name = ".";
    name += target.stem().string();
    name += ".pyrseg-out-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
    name += target.extension().string();
    return folder / name;
}

// `size` bytes into `path` (opened for writing, not replaced), every step checked: buffered bytes reach the file
// only at fflush/fclose, which is where a full disk shows.
void write_checked(const fs::path& path, const void* data, std::size_t size, const fs::path& named) {
    errno = 0;
    File file(std::fopen(path.c_str(), "wb"));
    if (!file) fail(named, "cannot open for writing: " + errno_text(errno));
    if (size > 0 && std::fwrite(data, 1, size, file.get()) != size) fail(named, "write error: " + errno_text(errno));
    if (std::fflush(file.get()) != 0) fail(named, "write error: " + errno_text(errno));
    if (std::fclose(file.release()) != 0) fail(named, "write error: " + errno_text(errno));
}

std::vector<char> read_all(const fs::path& path, const fs::path& named) {
    File file(std::fopen(path.c_str(), "rb"));
    if (!file) fail(named, "cannot read back the temporary file: " + errno_text(errno));
    std::vector<char> bytes;
    char chunk[1 << 16];
    std::size_t n = 0;
    while ((n = std::fread(chunk, 1, sizeof chunk, file.get())) > 0) bytes.insert(bytes.end(), chunk, chunk + n);
    if (std::ferror(file.get())) fail(named, "cannot read back the temporary file: " + errno_text(errno));
    return bytes;
}

}  // namespace

OutputFiles::~OutputFiles() {
    for (const Staged& s : staged_) {
        std::error_code ec;
        fs::remove(s.temporary, ec);
    }
}

void OutputFiles::stage(const fs::path& target, const std::function<void(const fs::path&)>& write) {
    std::error_code ec;
    const fs::file_status status = fs::status(target, ec);
    if (fs::is_directory(status)) fail(target, "is a folder, not a file");
    Staged s;
    s.in_place = fs::exists(status) && !fs::is_regular_file(status);
    // Through a symbolic link the file it names is replaced, not the link (as io::write_* do).
    s.target = target;
    if (!s.in_place && fs::is_symlink(fs::symlink_status(target, ec))) {
        const fs::path resolved = fs::weakly_canonical(target, ec);
        if (!ec) s.target = resolved;
    }
    const fs::path folder = s.in_place ? fs::temp_directory_path() : s.target.parent_path();
    if (!s.in_place && !folder.empty() && !fs::is_directory(folder, ec)) {
        fail(target, fs::exists(folder, ec) ? printable(folder) + " is a file, not a folder"
                                            : "the folder " + printable(folder) + " does not exist");
    }
    s.temporary = temporary_name(folder.empty() ? fs::path(".") : folder, s.target);
    s.registered = io::detail::RegisteredTemporary(s.temporary);
    staged_.push_back(std::move(s));  // before writing: a failed write's leftovers are removed with the rest
    const Staged& staged = staged_.back();
    try {
        write(staged.temporary);
    } catch (const Error& e) {
        // Named by the target: the temporary file is an implementation detail.
        std::string message = e.what();
        constexpr std::string_view kPrefix = "pyrseg: ";  // Error's constructor adds it again
        if (message.starts_with(kPrefix)) message.erase(0, kPrefix.size());
        const std::string named = printable(target);
        for (const std::string& temporary : {staged.temporary.string(), printable(staged.temporary)}) {
            for (std::size_t at = message.find(temporary); at != std::string::npos; at = message.find(temporary, at)) {
                message.replace(at, temporary.size(), named);
                at += named.size();
            }
        }
        throw Error(e.code(), message);
    }
    if (!fs::is_regular_file(staged.temporary, ec)) fail(target, "the writer left no file");
}

void OutputFiles::commit() {
    std::vector<fs::path> replaced;
    try {
        for (const Staged& s : staged_) {
            if (!s.in_place) continue;
            const std::vector<char> bytes = read_all(s.temporary, s.target);
            // Gone before the write, which may wait for a FIFO's reader: a run killed meanwhile leaves nothing.
            std::error_code ec;
            fs::remove(s.temporary, ec);
            io::detail::write_in_place(s.target, bytes.data(), bytes.size());
        }
        for (const Staged& s : staged_) {
            if (s.in_place) continue;
            std::error_code ec;
            fs::rename(s.temporary, s.target, ec);
            if (ec) fail(s.target, "cannot replace the file: " + ec.message());
            replaced.push_back(s.target);
        }
    } catch (...) {
        for (const fs::path& p : replaced) {
            std::error_code ec;
            fs::remove(p, ec);
        }
        throw;
    }
}

void write_text_file(const fs::path& path, std::string_view text) {
    OutputFiles files;
    files.stage(path, [&](const fs::path& temporary) { write_checked(temporary, text.data(), text.size(), path); });
    files.commit();
}

}  // namespace pyrseg::cli
