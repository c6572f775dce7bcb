#include "lzf_block.hpp"

#include <lzf.h>

#include <limits>

namespace pyrseg::io::detail {

std::vector<unsigned char> lzf_pack(const void* data, std::size_t size) {
    // Headroom so incompressible data still fits: LZF grows such data by about one byte in 32.
    const std::size_t capacity = size + size / 16 + 64;
    if (size == 0 || capacity > std::numeric_limits<unsigned>::max()) return {};
    std::vector<unsigned char> out(capacity);
    const unsigned n = lzf_compress(data, static_cast<unsigned>(size), out.data(), static_cast<unsigned>(out.size()));
    out.resize(n);
    return out;
}

}  // namespace pyrseg::io::detail
