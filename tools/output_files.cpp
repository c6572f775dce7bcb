#include "tools/output_files.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "pyrseg/error.hpp"

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;

struct FileCloser {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
    throw Error(ErrorCode::io, path.string() + ": " + what);
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

std::optional<std::uint64_t> ply_type_size(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return std::nullopt;
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
    if (fs::is_directory(status)) fail(target, "cannot open for writing: is a directory");
    Staged s;
    s.in_place = fs::exists(status) && !fs::is_regular_file(status);
    // Through a symbolic link the file it names is replaced, not the link (as io::write_* do).
    s.target = target;
    if (!s.in_place && fs::is_symlink(fs::symlink_status(target, ec))) {
        const fs::path resolved = fs::weakly_canonical(target, ec);
        if (!ec) s.target = resolved;
    }
    const fs::path folder = s.in_place ? fs::temp_directory_path() : s.target.parent_path();
    s.temporary = temporary_name(folder.empty() ? fs::path(".") : folder, s.target);
    staged_.push_back(s);  // before writing: a failed write's leftovers are removed with the rest
    try {
        write(s.temporary);
    } catch (const Error& e) {
        // Named by the target: the temporary file is an implementation detail.
        std::string message = e.what();
        constexpr std::string_view kPrefix = "pyrseg: ";  // Error's constructor adds it again
        if (message.starts_with(kPrefix)) message.erase(0, kPrefix.size());
        const std::string temporary = s.temporary.string();
        for (std::size_t at = message.find(temporary); at != std::string::npos; at = message.find(temporary, at)) {
            message.replace(at, temporary.size(), target.string());
            at += target.string().size();
        }
        throw Error(e.code(), message);
    }
    if (!fs::is_regular_file(s.temporary, ec)) fail(target, "the writer left no file");
}

void OutputFiles::commit() {
    std::vector<fs::path> replaced;
    try {
        for (const Staged& s : staged_) {
            if (!s.in_place) continue;
            const std::vector<char> bytes = read_all(s.temporary, s.target);
            write_checked(s.target, bytes.data(), bytes.size(), s.target);
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

void check_ply_complete(const fs::path& written, const fs::path& named) {
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(written, ec);
    if (ec) fail(named, "cannot check the written file: " + ec.message());
    std::vector<char> head(std::min<std::uintmax_t>(size, 1 << 16));
    {
        File file(std::fopen(written.c_str(), "rb"));
        if (!file || std::fread(head.data(), 1, head.size(), file.get()) != head.size()) {
            fail(named, "cannot check the written file");
        }
    }
    const std::string text(head.begin(), head.end());
    const std::size_t end = text.find("end_header\n");
    if (end == std::string::npos) fail(named, "write error: the PLY file was cut short (in its header)");
    // Elements of fixed-size properties, and PCL's range_grid: one count (0 or 1) per pixel, one index per vertex.
    std::uint64_t expected = end + 11;
    std::uint64_t vertices = 0;
    std::istringstream lines(text.substr(0, end));
    std::string line;
    std::string element;
    std::uint64_t count = 0;
    std::uint64_t stride = 0;
    const auto close_element = [&] { expected += count * stride; };
    while (std::getline(lines, line)) {
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (keyword == "format" && line.find("binary_little_endian") == std::string::npos) return;  // ascii: no size
        if (keyword == "element") {
            close_element();
            words >> element >> count;
            stride = 0;
            if (element == "vertex") vertices = count;
        } else if (keyword == "property") {
            std::string type;
            words >> type;
            if (type == "list") {
                std::string count_type;
                std::string index_type;
                words >> count_type >> index_type;
                const auto c = ply_type_size(count_type);
                const auto i = ply_type_size(index_type);
                if (element != "range_grid" || !c || !i) return;  // a layout this check does not know
                expected += count * *c + vertices * *i;
            } else if (const auto s = ply_type_size(type)) {
                stride += *s;
            } else {
                return;
            }
        }
    }
    close_element();
    if (size != expected) {
        fail(named, "write error: the PLY file has " + std::to_string(size) + " bytes, its header says " +
                        std::to_string(expected) + " (a full disk?)");
    }
}

}  // namespace pyrseg::cli
