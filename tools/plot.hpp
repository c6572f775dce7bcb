#pragma once
// Small line charts for reports (`pyrseg eval`): a row of panels sharing a title, a legend and a y range, drawn
// with the 5x7 caption font, written as PNG through tools/figures.hpp.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "tools/figures.hpp"

namespace pyrseg::cli {

struct LineSeries {
    std::string name;
    std::array<std::uint8_t, 3> color{};
    bool hollow = false;    // hollow square markers instead of filled ones (tells overlapping lines apart)
    std::vector<double> y;  // one value per x of the panel; NaN: no point
};

struct LinePanel {
    std::string title;
    std::vector<double> x;              // ascending; every x gets a tick
    std::vector<std::string> x_labels;  // the ticks' labels, one per x; empty: the x values themselves
    std::vector<LineSeries> series;
};

struct LineChart {
    std::string title;    // above everything
    std::string x_label;  // under every panel
    double y_min = 0, y_max = 1;
    std::vector<double> y_ticks;
    bool percent = false;  // tick labels as y * 100 with a % sign
    std::vector<LinePanel> panels;
};

[[nodiscard]] RgbImage render_line_chart(const LineChart& chart);

}  // namespace pyrseg::cli
