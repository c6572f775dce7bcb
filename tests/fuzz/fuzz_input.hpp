#pragma once
// What every harness shares: the input as a file for the readers that take a path, and the rule that a
// pyrseg::Error is a reader's normal answer to a bad file while anything else escaping it is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include "pyrseg/error.hpp"

namespace pyrseg::fuzz {

// One folder per process (libFuzzer's -jobs/-workers run several at once), in /dev/shm so that writing the input
// every run costs a memory copy, not disk I/O.
class ScratchFolder {
public:
    ScratchFolder() {
        std::error_code ec;
        std::filesystem::path base = "/dev/shm";
        if (!std::filesystem::is_directory(base, ec)) base = std::filesystem::temp_directory_path();
        path_ = base / ("pyrseg-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(path_);
    }
    ~ScratchFolder() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    ScratchFolder(const ScratchFolder&) = delete;
    ScratchFolder& operator=(const ScratchFolder&) = delete;
    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

// The extension matters: the depth reader and OpenCV's FileStorage choose the format by it.
inline std::filesystem::path write_input(const std::uint8_t* data, std::size_t size, const std::string& extension) {
    static const ScratchFolder folder;
    std::filesystem::path path = folder.path() / ("input" + extension);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    // A harness that cannot write its input would report every run as clean: stop instead.
    if (f == nullptr) std::abort();
    const bool written = size == 0 || std::fwrite(data, 1, size, f) == size;
    if (std::fclose(f) != 0 || !written) std::abort();
    return path;
}

// A reader's result that breaks the header's promises is a bug even when nothing crashed.
inline void expect(bool condition) {
    if (!condition) __builtin_trap();
}

template <class Read>
void tolerate_format_errors(Read&& read) {
    try {
        read();
    } catch (const pyrseg::Error&) {
        // The documented way to refuse a file: not a finding.
    }
}

}  // namespace pyrseg::fuzz
