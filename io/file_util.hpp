#pragma once
// Whole-file reads and writes with pyrseg::Error messages that name the file, shared by the format readers.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io::detail {

// "<path>: <what>", the shape every io message takes.
[[noreturn]] void fail(ErrorCode code, const std::filesystem::path& path, std::string_view what);

// The whole content of a regular file (directories, FIFOs and devices are refused: they would fail or never end).
std::vector<unsigned char> read_file(const std::filesystem::path& path);

// Writes into a temporary file beside `path` and renames it over `path` once complete, so that a failure (a full
// disk, an exception, a crash) leaves either the old file or none, never a partial one.
void write_file(const std::filesystem::path& path, const void* data, std::size_t size);

// The same for writers that open the file themselves (PCL's): `write_to` writes the temporary file it is given and
// throws on failure; the temporary file is removed then, and renamed over `path` otherwise. Existing targets that
// are not regular files (/dev/null, a FIFO) are written in place: they cannot be replaced.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& temporary)>& write_to);

// What a cloud writer needs of its cloud: a positive size that fits int, 3 point values per pixel, and 0 or 3
// normal values per pixel. ErrorCode::invalid_argument naming the file otherwise.
void check_cloud_to_write(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace pyrseg::io::detail
