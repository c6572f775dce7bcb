#pragma once
// Whole-file reads and writes with pyrseg::Error messages that name the file, shared by the format readers.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "pyrseg/error.hpp"

namespace pyrseg::io::detail {

// "<path>: <what>", the shape every io message takes.
[[noreturn]] void fail(ErrorCode code, const std::filesystem::path& path, std::string_view what);

// The whole content of a regular file (directories, FIFOs and devices are refused: they would fail or never end).
std::vector<unsigned char> read_file(const std::filesystem::path& path);

void write_file(const std::filesystem::path& path, const void* data, std::size_t size);

}  // namespace pyrseg::io::detail
