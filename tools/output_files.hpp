#pragma once
// The files one frame writes, all or none (issue 18): each is written under a temporary name and checked, and only
// when every one of them succeeded are they moved to their names. A full disk, a file-size limit or /dev/full then
// costs the frame an error and leaves none of its outputs, never some of them or a truncated one.
#include <filesystem>
#include <functional>
#include <string_view>
#include <vector>

#include "io/temporary_files.hpp"

namespace pyrseg::cli {

class OutputFiles {
public:
    OutputFiles() = default;
    ~OutputFiles();  // removes whatever was staged and not committed
    OutputFiles(const OutputFiles&) = delete;
    OutputFiles& operator=(const OutputFiles&) = delete;

    // Runs `write` on a temporary file for `target` (beside it, with the same extension; in the temporary folder
    // for a target that is a device or a FIFO, which cannot be replaced). `write` throws pyrseg::Error on failure.
    void stage(const std::filesystem::path& target, const std::function<void(const std::filesystem::path&)>& write);

    // Moves every staged file to its target (devices and FIFOs are written first: they cannot be taken back; a FIFO
    // with no reader is an error at once, io::detail::write_in_place). On failure, pyrseg::Error, and the targets
    // this frame had already replaced are removed.
    void commit();

private:
    struct Staged {
        std::filesystem::path target;     // where the file goes (a symbolic link's own target)
        std::filesystem::path temporary;  // where it is written first
        bool in_place = false;            // a device or FIFO: its bytes are copied into it
        // For a termination signal's handler to remove (tools/main.cpp): Ctrl-C mid-frame leaves no temporary.
        io::detail::RegisteredTemporary registered;
    };
    std::vector<Staged> staged_;
};

// A text file (a report), whole or not at all.
void write_text_file(const std::filesystem::path& path, std::string_view text);

}  // namespace pyrseg::cli
