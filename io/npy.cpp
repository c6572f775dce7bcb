// NumPy .npy files (https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html): a magic string, a
// version, a little-endian header length, a Python dict literal padded with spaces and '\n' so the data starts on a
// 64-byte boundary, then the raw array.
#include <bit>
#include <cctype>
#include <charconv>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <string_view>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {

namespace {

using detail::fail;

static_assert(std::endian::native == std::endian::little, "npy '<' dtypes are written straight from memory");

constexpr char kMagic[] = "\x93NUMPY";
constexpr std::size_t kMagicLen = 6;
constexpr std::size_t kAlign = 64;
constexpr std::uint64_t kMaxHeader = std::uint64_t{1} << 20;

std::string shape_repr(const std::vector<std::size_t>& shape) {
    std::string s = "(";
    for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
    return s + (shape.size() == 1 ? ",)" : ")");
}

void write_array(const std::filesystem::path& path, const char* descr, const std::vector<std::size_t>& shape,
                 const void* data, std::size_t bytes) {
    // The same dict numpy writes (keys sorted), padded the way numpy's _wrap_header pads it.
    std::string dict =
        std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': " + shape_repr(shape) + ", }";
    const std::size_t used = kMagicLen + 2 + 2 + dict.size() + 1;
    dict.append(kAlign - used % kAlign, ' ');
    dict += '\n';
    const auto header_len = static_cast<std::uint16_t>(dict.size());
    std::string out(kMagic, kMagicLen);
    out += '\x01';
    out += '\x00';
    out.append(reinterpret_cast<const char*>(&header_len), 2);
    out += dict;
    out.append(static_cast<const char*>(data), bytes);
    detail::write_file(path, out.data(), out.size());
}

void check_dims(const std::filesystem::path& path, const void* data, long long height, long long width,
                long long channels) {
    if (data == nullptr) fail(ErrorCode::invalid_argument, path, "null data pointer");
    if (height <= 0 || width <= 0 || channels <= 0) {
        fail(ErrorCode::invalid_argument, path,
             "bad array size " + std::to_string(height) + " x " + std::to_string(width) + " x " +
                 std::to_string(channels));
    }
}

// A tokenizer and parser for the only Python literal numpy writes here: {'key': value, ...} with strings, True,
// False and tuples of integers as values.
class HeaderParser {
public:
    HeaderParser(std::string_view text, const std::filesystem::path& path) : text_(text), path_(path) {}

    NpyArray parse() {
        NpyArray a;
        bool has_descr = false, has_order = false, has_shape = false;
        expect('{');
        while (!peek('}')) {
            const std::string key = string_value();
            expect(':');
            if (key == "descr" && !has_descr) {
                if (peek('[')) fail("structured dtypes (a list as 'descr') are not supported");
                a.dtype = string_value();
                has_descr = true;
            } else if (key == "fortran_order" && !has_order) {
                if (word() != "False") fail("only C order arrays are supported ('fortran_order': False)");
                has_order = true;
            } else if (key == "shape" && !has_shape) {
                a.shape = tuple();
                has_shape = true;
            } else {
                fail("unexpected or repeated key '" + key + "' in the header");
            }
            if (!peek('}')) expect(',');
        }
        expect('}');
        skip_space();
        if (pos_ != text_.size()) fail("unexpected text after the header dict");
        if (!has_descr || !has_order || !has_shape) {
            fail("the header needs the keys 'descr', 'fortran_order' and 'shape'");
        }
        return a;
    }

private:
    [[noreturn]] void fail(const std::string& what) const { detail::fail(ErrorCode::format, path_, what); }

    void skip_space() {
        while (pos_ < text_.size() &&
               (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\n' || text_[pos_] == '\r')) {
            ++pos_;
        }
    }
    bool peek(char c) {
        skip_space();
        return pos_ < text_.size() && text_[pos_] == c;
    }
    void expect(char c) {
        if (!peek(c)) fail(std::string("malformed header dict: expected '") + c + "' at byte " + std::to_string(pos_));
        ++pos_;
    }
    std::string string_value() {
        skip_space();
        if (pos_ >= text_.size() || (text_[pos_] != '\'' && text_[pos_] != '"')) {
            fail("malformed header dict: expected a string at byte " + std::to_string(pos_));
        }
        const char quote = text_[pos_++];
        const std::size_t end = text_.find(quote, pos_);
        if (end == std::string_view::npos) fail("malformed header dict: unterminated string");
        std::string s(text_.substr(pos_, end - pos_));
        pos_ = end + 1;
        return s;
    }
    std::string_view word() {
        skip_space();
        const std::size_t start = pos_;
        while (pos_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[pos_]))) ++pos_;
        return text_.substr(start, pos_ - start);
    }
    std::vector<std::size_t> tuple() {
        std::vector<std::size_t> dims;
        expect('(');
        while (!peek(')')) {
            std::uint64_t v = 0;
            const auto [end, ec] = std::from_chars(text_.data() + pos_, text_.data() + text_.size(), v);
            if (ec != std::errc())
                fail("malformed 'shape': expected a non-negative integer at byte " + std::to_string(pos_));
            pos_ = static_cast<std::size_t>(end - text_.data());
            if (pos_ < text_.size() && text_[pos_] == 'L') ++pos_;  // Python 2 longs
            dims.push_back(static_cast<std::size_t>(v));
            if (!peek(')')) expect(',');
        }
        expect(')');
        return dims;
    }

    std::string_view text_;
    const std::filesystem::path& path_;
    std::size_t pos_ = 0;
};

// Bytes per element of a little-endian (or byte-order-free) numeric dtype; 0 when unsupported.
std::size_t item_size(std::string_view dtype) {
    if (dtype.size() < 3) return 0;
    const char order = dtype[0], kind = dtype[1];
    std::size_t size = 0;
    const auto [end, ec] = std::from_chars(dtype.data() + 2, dtype.data() + dtype.size(), size);
    if (ec != std::errc() || end != dtype.data() + dtype.size()) return 0;
    const bool ok =
        (kind == 'b' && size == 1) || ((kind == 'i' || kind == 'u') && std::has_single_bit(size) && size <= 8) ||
        (kind == 'f' && (size == 2 || size == 4 || size == 8)) || (kind == 'c' && (size == 8 || size == 16));
    if (!ok) return 0;
    if (order == '<' || order == '=' || (order == '|' && size == 1)) return size;
    return 0;
}

}  // namespace

void write_npy(const std::filesystem::path& path, const std::uint32_t* data, int height, int width) {
    check_dims(path, data, height, width, 1);
    const std::size_t n = static_cast<std::size_t>(height) * static_cast<std::size_t>(width);
    write_array(path, "<u4", {static_cast<std::size_t>(height), static_cast<std::size_t>(width)}, data,
                n * sizeof(std::uint32_t));
}

void write_npy(const std::filesystem::path& path, const std::uint8_t* data, int height, int width) {
    check_dims(path, data, height, width, 1);
    const std::size_t n = static_cast<std::size_t>(height) * static_cast<std::size_t>(width);
    write_array(path, "|u1", {static_cast<std::size_t>(height), static_cast<std::size_t>(width)}, data, n);
}

void write_npy(const std::filesystem::path& path, const float* data, int height, int width, int channels) {
    check_dims(path, data, height, width, channels);
    std::vector<std::size_t> shape = {static_cast<std::size_t>(height), static_cast<std::size_t>(width)};
    if (channels > 1) shape.push_back(static_cast<std::size_t>(channels));
    const std::size_t n = shape[0] * shape[1] * static_cast<std::size_t>(channels);
    write_array(path, "<f4", shape, data, n * sizeof(float));
}

NpyArray read_npy(const std::filesystem::path& path) {
    return detail::read_npy(path, [](const NpyArray&) {});
}

namespace detail {

NpyArray read_npy(const std::filesystem::path& path, const std::function<void(const NpyArray& header)>& check) {
    return guard_reader(path, [&] {
        InputFile file(path);
        // The magic, version and header length first: a file that is not .npy costs 12 bytes of reading.
        const std::vector<unsigned char> start = read_head(file, 12);
        if (start.size() < kMagicLen + 4 || std::memcmp(start.data(), kMagic, kMagicLen) != 0) {
            fail(ErrorCode::format, path, "not a .npy file (no \\x93NUMPY magic)");
        }
        const unsigned major = start[6], minor = start[7];
        if ((major != 1 && major != 2 && major != 3) || minor != 0) {
            fail(ErrorCode::format, path,
                 "npy format version " + std::to_string(major) + "." + std::to_string(minor) + " is not supported");
        }
        std::size_t prefix = 10;
        std::uint64_t header_len = static_cast<std::uint64_t>(start[8]) | static_cast<std::uint64_t>(start[9]) << 8;
        if (major >= 2) {
            if (start.size() < 12) fail(ErrorCode::format, path, "truncated npy header");
            header_len |= static_cast<std::uint64_t>(start[10]) << 16 | static_cast<std::uint64_t>(start[11]) << 24;
            prefix = 12;
        }
        if (header_len > file.size() - prefix) {
            fail(ErrorCode::format, path,
                 "header length " + std::to_string(header_len) + " exceeds the " +
                     std::to_string(file.size() - prefix) + " bytes left in the file (truncated file?)");
        }
        // numpy itself refuses headers over 10000 bytes unless told otherwise; a dict of a dtype and a shape
        // never needs more.
        if (header_len > kMaxHeader) {
            fail(ErrorCode::format, path,
                 "header length " + std::to_string(header_len) + " is more than the " + std::to_string(kMaxHeader) +
                     " bytes a .npy header may have here");
        }
        std::string header(static_cast<std::size_t>(header_len), '\0');
        file.seek(prefix);
        file.read_exact(header.data(), header.size(), "the end of the header");
        NpyArray a = HeaderParser(header, path).parse();

        const std::size_t item = item_size(a.dtype);
        if (item == 0) {
            fail(ErrorCode::format, path,
                 "dtype '" + a.dtype + "' is not supported (little-endian bool, int, uint, float or complex only)");
        }
        std::uint64_t total = item;
        for (const std::size_t d : a.shape) {
            if (d != 0 && total > std::numeric_limits<std::uint64_t>::max() / d) {
                fail(ErrorCode::format, path, "shape " + shape_repr(a.shape) + " overflows");
            }
            total *= d;
        }
        const std::uint64_t left = file.size() - prefix - header_len;
        if (total != left) {
            fail(ErrorCode::format, path,
                 "shape " + shape_repr(a.shape) + " of '" + a.dtype + "' needs " + std::to_string(total) +
                     " bytes of data, the file has " + std::to_string(left) +
                     (total > left ? " (truncated file?)" : ""));
        }
        check(a);
        a.bytes.resize(static_cast<std::size_t>(total));
        file.read_exact(a.bytes.data(), a.bytes.size(), "the end of the array data");
        return a;
    });
}

}  // namespace detail

}  // namespace pyrseg::io
