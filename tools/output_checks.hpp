#pragma once
// The checks every output name passes before any input is read (issue 32): a mistake in them costs a message, not
// a frame's work or a file.
#include <filesystem>
#include <string>
#include <vector>

namespace pyrseg::cli {

// The key two names of one file share: its device and inode when it exists (symbolic links, hard links and ./..
// spellings all meet), else its absolute path with the symbolic links of its existing part resolved.
[[nodiscard]] std::string same_file_key(const std::filesystem::path& path);

struct NamedOutput {
    std::string option;  // "--labels", or what a batch calls the file
    std::filesystem::path path;
};

// Two outputs naming one file (one of them would be lost) are a UsageError naming both; a character device such as
// /dev/null may take several, since what is written there is meant to be lost. An output that is a folder, or whose
// folder does not exist, is a pyrseg::Error(io) saying so.
void check_outputs(const std::vector<NamedOutput>& outputs);

// The folder a batch writes into, created when missing: an empty name is a UsageError; a file of that name, or a
// folder that cannot be created, a pyrseg::Error(io) saying which.
void make_output_folder(const std::string& folder);

}  // namespace pyrseg::cli
