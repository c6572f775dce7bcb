#include "tools/figures.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "pyrseg/io.hpp"
#include "tools/eval/bridges.hpp"
#include "tools/font5x7.hpp"

namespace pyrseg::cli {
namespace {

constexpr std::uint8_t kBackground = 24;
constexpr int kGap = 8;

const Glyph* find_glyph(char c) {
    const char upper = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    for (const Glyph& g : kFont) {
        if (g.c == upper) return &g;
    }
    return nullptr;  // blank (space and anything the font lacks)
}

void draw_text(RgbImage& img, int x0, int y0, int scale, const std::string& text) {
    int x = x0;
    for (char c : text) {
        if (const Glyph* g = find_glyph(c)) {
            for (int row = 0; row < 7; ++row) {
                for (int col = 0; col < 5; ++col) {
                    if ((g->rows[std::size_t(row)] & (0x10 >> col)) == 0) continue;
                    for (int dy = 0; dy < scale; ++dy) {
                        for (int dx = 0; dx < scale; ++dx) {
                            const int px = x + col * scale + dx;
                            const int py = y0 + row * scale + dy;
                            if (px < 0 || py < 0 || px >= img.width || py >= img.height) continue;
                            std::fill_n(img.rgb.begin() + 3 * (std::ptrdiff_t(py) * img.width + px), 3, 235);
                        }
                    }
                }
            }
        }
        x += 6 * scale;
    }
}

}  // namespace

RgbImage colorize(const std::vector<std::uint32_t>& labels, int width, int height) {
    return RgbImage{width, height, io::colorize_labels(labels.data(), width, height)};
}

const std::vector<std::uint32_t>& colour_keys(const Result& result) {
    return result.track_ids.size() == result.labels.size() && !result.track_ids.empty() ? result.track_ids
                                                                                        : result.labels;
}

RgbImage colorize_segments(const Result& result) {
    return colorize(colour_keys(result), result.width, result.height);
}

RgbImage mask_picture(const std::vector<std::uint8_t>& fillable, int width, int height) {
    RgbImage img{width, height, std::vector<std::uint8_t>(std::size_t(width) * std::size_t(height) * 3)};
    for (std::size_t i = 0; i < fillable.size(); ++i)
        std::fill_n(img.rgb.begin() + std::ptrdiff_t(3 * i), 3, fillable[i] ? 255 : 0);
    return img;
}

RgbImage side_by_side(const std::vector<Panel>& panels) {
    if (panels.empty()) return {};
    const int pw = panels.front().image.width;
    const int ph = panels.front().image.height;
    const int scale = std::max(1, pw / 320);
    const int caption_h = 7 * scale + 2 * kGap;
    RgbImage out;
    out.width = int(panels.size()) * pw + (int(panels.size()) + 1) * kGap;
    out.height = ph + caption_h + kGap;
    out.rgb.assign(std::size_t(out.width) * std::size_t(out.height) * 3, kBackground);
    for (std::size_t p = 0; p < panels.size(); ++p) {
        const int x0 = kGap + int(p) * (pw + kGap);
        draw_text(out, x0, kGap, scale, panels[p].caption);
        const RgbImage& img = panels[p].image;
        for (int y = 0; y < std::min(ph, img.height); ++y) {
            const auto src = img.rgb.begin() + 3 * std::ptrdiff_t(y) * img.width;
            std::copy(src, src + std::ptrdiff_t{3} * std::min(pw, img.width),
                      out.rgb.begin() + 3 * (std::ptrdiff_t(y + caption_h) * out.width + x0));
        }
    }
    return out;
}

std::vector<Panel> comparison_panels(const Result& r) {
    std::uint32_t ccl_count = 0;
    const auto ccl = eval::connected_components(r.fillable_mask, r.width, r.height, &ccl_count);
    return {{"fillable mask", mask_picture(r.fillable_mask, r.width, r.height)},
            {"connected components: " + std::to_string(ccl_count), colorize(ccl, r.width, r.height)},
            {"pyramid: " + std::to_string(r.segment_count) + (&colour_keys(r) == &r.track_ids ? ", by track" : ""),
             colorize_segments(r)}};
}

RgbImage comparison_figure(const Result& r) {
    return side_by_side(comparison_panels(r));
}

void write_png(const std::string& path, const RgbImage& image) {
    io::write_png_rgb(path, image.rgb.data(), image.width, image.height);
}

void draw_line(RgbImage& image, int x0, int y0, int x1, int y1, int thickness, std::array<std::uint8_t, 3> color) {
    const int dx = std::abs(x1 - x0);
    const int dy = -std::abs(y1 - y0);
    const int sx = x0 < x1 ? 1 : -1;
    const int sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    const int lo = -(thickness - 1) / 2;
    const int hi = thickness / 2;
    for (;;) {
        for (int y = y0 + lo; y <= y0 + hi; ++y) {
            for (int x = x0 + lo; x <= x0 + hi; ++x) {
                if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
                std::copy(color.begin(), color.end(), image.rgb.begin() + 3 * (std::ptrdiff_t(y) * image.width + x));
            }
        }
        if (x0 == x1 && y0 == y1) break;
        const int e2 = 2 * err;
        if (e2 >= dy) {
            err += dy;
            x0 += sx;
        }
        if (e2 <= dx) {
            err += dx;
            y0 += sy;
        }
    }
}

}  // namespace pyrseg::cli
