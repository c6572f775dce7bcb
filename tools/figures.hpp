#pragma once
// Pictures for people: coloured labels, the fillable mask, plain connected components for comparison, and
// captioned side-by-side figures (like the paper's Figure 3).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pyrseg/result.hpp"

namespace pyrseg::cli {

struct RgbImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb;  // 3 bytes per pixel
};

[[nodiscard]] RgbImage colorize(const std::vector<std::uint32_t>& labels, int width, int height);
// What a result's segments are coloured by: their track ids when it has them (Outputs::track_ids, pyrseg segment
// --track), so that a segment keeps its colour from frame to frame and a video of the pictures does not flicker as
// the labels 1..K are renumbered; else their labels.
[[nodiscard]] const std::vector<std::uint32_t>& colour_keys(const Result& result);
[[nodiscard]] RgbImage colorize_segments(const Result& result);  // colorize(colour_keys(result), ...)
[[nodiscard]] RgbImage mask_picture(const std::vector<std::uint8_t>& fillable, int width, int height);

struct Panel {
    std::string caption;
    RgbImage image;
};
// Panels side by side (all the same size), each under its caption, on a dark background.
[[nodiscard]] RgbImage side_by_side(const std::vector<Panel>& panels);

// The paper's Figure 3 for one result (needs Outputs::fillable_mask): mask | plain connected components | pyramid.
[[nodiscard]] RgbImage comparison_figure(const Result& result);
[[nodiscard]] std::vector<Panel> comparison_panels(const Result& result);  // its panels, to add to

void write_png(const std::string& path, const RgbImage& image);

// A line of the given thickness from (x0, y0) to (x1, y1) (a square brush moved along a Bresenham line), clipped to
// the image.
void draw_line(RgbImage& image, int x0, int y0, int x1, int y1, int thickness, std::array<std::uint8_t, 3> color);

}  // namespace pyrseg::cli
