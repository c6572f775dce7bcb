// PNG through libpng. libpng reports errors by longjmp to a setjmp point; that is only well-defined in C++ when the
// jump skips no frame with non-trivial destructors, so each setjmp lives in a small function (encode, read_header,
// read_rows) whose locals are all trivial, and everything owning memory lives in the callers.
#include <png.h>

#include <bit>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {

namespace {

using detail::fail;

struct ErrorSlot {
    char message[256] = "unknown libpng error";
};

void on_error(png_structp png, png_const_charp message) {
    auto* slot = static_cast<ErrorSlot*>(png_get_error_ptr(png));
    std::snprintf(slot->message, sizeof slot->message, "%s", message);
    png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // benign (e.g. unknown chunks); errors still fail the call

// ---- writing

void write_to_vector(png_structp png, png_bytep data, std::size_t size) {
    auto* out = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(png));
    bool ok = true;
    try {
        out->insert(out->end(), data, data + size);
    } catch (...) {
        ok = false;
    }
    // png_error leaves by longjmp, which must not happen inside a catch handler.
    if (!ok) png_error(png, "out of memory");
}

void flush_nothing(png_structp) {}

struct Spec {
    png_uint_32 width, height;
    int bit_depth, color_type;
};

bool encode(png_structp png, png_infop info, const Spec& spec, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, spec.width, spec.height, spec.bit_depth, spec.color_type, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    // PNG stores 16-bit samples big-endian.
    if (spec.bit_depth == 16 && std::endian::native == std::endian::little) png_set_swap(png);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    return true;
}

void write_png(const std::filesystem::path& path, const void* pixels, int width, int height, int channels,
               int bit_depth) {
    if (pixels == nullptr) fail(ErrorCode::invalid_argument, path, "null pixel pointer");
    if (width <= 0 || height <= 0) {
        fail(ErrorCode::invalid_argument, path,
             "cannot write a " + std::to_string(width) + " x " + std::to_string(height) + " image");
    }
    const int color_type = channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY;
    const std::size_t row_bytes =
        static_cast<std::size_t>(width) * static_cast<std::size_t>(channels) * static_cast<std::size_t>(bit_depth / 8);
    // libpng only reads the rows (transforms such as the byte swap work on its own copy), hence the const_cast.
    std::vector<png_bytep> rows(static_cast<std::size_t>(height));
    auto* base = const_cast<png_bytep>(static_cast<const png_byte*>(pixels));
    for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = base + y * row_bytes;

    ErrorSlot slot;
    std::vector<unsigned char> out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &slot, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (info == nullptr) {
        png_destroy_write_struct(&png, nullptr);
        fail(ErrorCode::internal, path, "cannot create a libpng writer");
    }
    png_set_write_fn(png, &out, write_to_vector, flush_nothing);
    const Spec spec{static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), bit_depth, color_type};
    const bool ok = encode(png, info, spec, rows.data());
    png_destroy_write_struct(&png, &info);
    if (!ok) fail(ErrorCode::io, path, std::string("PNG encoding failed: ") + slot.message);
    detail::write_file(path, out.data(), out.size());
}

// ---- reading

// libpng reads the file as it decodes (never more than a chunk header or a zlib buffer at a time), so the file is
// not read whole first.
void read_from_file(png_structp png, png_bytep out, std::size_t size) {
    auto* file = static_cast<detail::InputFile*>(png_get_io_ptr(png));
    if (file->read_some_nothrow(out, size) != size) {
        png_error(png,
                  std::ferror(file->get()) ? "read error" : "file ends in the middle of a chunk (truncated file?)");
    }
}

// What libpng may allocate for one chunk (text, ICC profile, unknown chunk; also their decompressed size). libpng
// allocates a chunk's claimed length before reading it, so without a limit a 52-byte file can ask for 2 GiB. Image
// data (IDAT) is streamed through a fixed buffer and is not bound by it.
constexpr png_alloc_size_t kMaxChunkBytes = png_alloc_size_t{8} << 20;
// Ancillary chunks (tEXt, sPLT, unknown) libpng keeps: each costs memory and a file can hold millions.
constexpr png_uint_32 kMaxCachedChunks = 256;

void limit_chunks(png_structp png) {
    // Width and height keep libpng's limits (png_set_user_limits, 1000000 each): the pixel data is bounded more
    // tightly by the file's size in read_png_file, with a message that says so.
    png_set_chunk_malloc_max(png, kMaxChunkBytes);
    png_set_chunk_cache_max(png, kMaxCachedChunks);
    // Metadata pyrseg never uses is skipped unread (libpng then neither allocates it nor inflates it).
    static constexpr png_byte kIgnored[] = "tEXt\0zTXt\0iTXt\0iCCP\0sPLT\0eXIf\0";
    png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, kIgnored, static_cast<int>(sizeof kIgnored / 5));
    png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, nullptr, 0);
}

struct Layout {
    png_uint_32 width = 0, height = 0;
    int channels = 0, bit_depth = 0;
    std::uint64_t stored_bits = 0;  // bits per pixel in the file, before expansion
    std::size_t row_bytes = 0;      // after expansion
};

bool read_header(png_structp png, png_infop info, Layout* out) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_info(png, info);
    const int color_type = png_get_color_type(png, info);
    const int depth = png_get_bit_depth(png, info);
    out->stored_bits = static_cast<std::uint64_t>(png_get_channels(png, info)) * static_cast<unsigned>(depth);
    // Samples stay as stored except where a caller could not use them as they are: palette indices and packed
    // sub-byte gray.
    if (color_type == PNG_COLOR_TYPE_PALETTE) {
        png_set_palette_to_rgb(png);
        if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    }
    if (color_type == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (depth == 16 && std::endian::native == std::endian::little) png_set_swap(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    out->width = png_get_image_width(png, info);
    out->height = png_get_image_height(png, info);
    out->channels = png_get_channels(png, info);
    out->bit_depth = png_get_bit_depth(png, info);
    out->row_bytes = png_get_rowbytes(png, info);
    return true;
}

bool read_rows(png_structp png, png_infop info, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_image(png, rows);
    png_read_end(png, info);
    return true;
}

struct ReadGuard {
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~ReadGuard() { png_destroy_read_struct(&png, &info, nullptr); }
};

Image read_png_file(const std::filesystem::path& path) {
    detail::InputFile file(path);
    png_byte signature[8] = {};
    if (file.read_some(signature, sizeof signature) != sizeof signature || png_sig_cmp(signature, 0, 8) != 0) {
        fail(ErrorCode::format, path, "not a PNG file (no PNG signature)");
    }
    ErrorSlot slot;
    ReadGuard g;
    g.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &slot, on_error, on_warning);
    if (g.png != nullptr) g.info = png_create_info_struct(g.png);
    if (g.info == nullptr) fail(ErrorCode::internal, path, "cannot create a libpng reader");
    limit_chunks(g.png);
    png_set_read_fn(g.png, &file, read_from_file);
    png_set_sig_bytes(g.png, 8);

    Layout layout;
    if (!read_header(g.png, g.info, &layout)) {
        fail(ErrorCode::format, path, std::string("corrupt PNG: ") + slot.message);
    }
    detail::check_image_size(path, "PNG", layout.width, layout.height);
    // Deflate expands at most 1032-fold, so an image claiming more pixel data than that is lying: refuse it before
    // allocating rather than let a tiny file request gigabytes.
    const std::uint64_t stored = (layout.width * layout.stored_bits + 7) / 8 * layout.height;
    const std::uint64_t limit = 1040 * static_cast<std::uint64_t>(file.size()) + 4096;
    if (stored > limit || static_cast<std::uint64_t>(layout.row_bytes) * layout.height > (std::uint64_t{1} << 34)) {
        fail(ErrorCode::format, path,
             "a " + std::to_string(layout.width) + " x " + std::to_string(layout.height) +
                 " image cannot be stored in a file of " + std::to_string(file.size()) + " bytes");
    }
    Image image;
    image.width = static_cast<int>(layout.width);
    image.height = static_cast<int>(layout.height);
    image.channels = layout.channels;
    image.bit_depth = layout.bit_depth;
    image.data.resize(layout.row_bytes * layout.height);
    std::vector<png_bytep> rows(layout.height);
    for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = image.data.data() + y * layout.row_bytes;
    if (!read_rows(g.png, g.info, rows.data())) {
        fail(ErrorCode::format, path, std::string("corrupt PNG: ") + slot.message);
    }
    return image;
}

}  // namespace

void write_png_rgb(const std::filesystem::path& path, const std::uint8_t* rgb, int width, int height) {
    write_png(path, rgb, width, height, 3, 8);
}

void write_png_gray16(const std::filesystem::path& path, const std::uint16_t* gray, int width, int height) {
    write_png(path, gray, width, height, 1, 16);
}

void write_png_gray8(const std::filesystem::path& path, const std::uint8_t* gray, int width, int height) {
    write_png(path, gray, width, height, 1, 8);
}

Image read_png(const std::filesystem::path& path) {
    return detail::guard_reader(path, [&] { return read_png_file(path); });
}

}  // namespace pyrseg::io
