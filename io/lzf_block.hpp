#pragma once
// LZF compression of a whole block, as PCD's DATA binary_compressed stores it (also used by tests to build files).
#include <cstddef>
#include <vector>

namespace pyrseg::io::detail {

// The compressed bytes; empty when size is 0 or does not fit LZF's 32-bit lengths.
std::vector<unsigned char> lzf_pack(const void* data, std::size_t size);

}  // namespace pyrseg::io::detail
