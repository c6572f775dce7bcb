#pragma once
// The seed generator's parts: each writes valid files of its kind into ROOT/<harness>/.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace pyrseg::fuzz {

void write_seed(const std::filesystem::path& dir, const std::string& name, const void* data, std::size_t size);
inline void write_seed(const std::filesystem::path& dir, const std::string& name, std::string_view text) {
    write_seed(dir, name, text.data(), text.size());
}

void write_text_seeds(const std::filesystem::path& root);  // calib, intrinsics, args, py_arrays
void write_tiff_seeds(const std::filesystem::path& root);  // tiff and depth: the sample layouts pyrseg cannot write

}  // namespace pyrseg::fuzz
