#include "tools/plot.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <utility>

#include "tools/figures.hpp"
#include "tools/font5x7.hpp"

namespace pyrseg::cli {
namespace {

using Rgb = std::array<std::uint8_t, 3>;

constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kInk{30, 30, 30};
constexpr Rgb kGrid{225, 225, 225};
constexpr int kScale = 2;          // font scale: glyphs 10 x 14 pixels
constexpr int kChar = 6 * kScale;  // advance per character
constexpr int kLine = 7 * kScale;  // glyph height
constexpr int kPlotW = 300;        // plot area of one panel
constexpr int kPlotH = 220;
constexpr int kLeft = 6 * kChar;  // room for y tick labels ("100%")
constexpr int kPanelGap = 24;
constexpr int kMargin = 16;

class Canvas {
public:
    Canvas(int width, int height) : img_{width, height, {}} {
        img_.rgb.assign(std::size_t(width) * std::size_t(height) * 3, 255);
    }

    void dot(int x, int y, Rgb c) {
        if (x < 0 || y < 0 || x >= img_.width || y >= img_.height) return;
        std::copy(c.begin(), c.end(), img_.rgb.begin() + 3 * (std::ptrdiff_t(y) * img_.width + x));
    }

    void rect(int x0, int y0, int x1, int y1, Rgb c) {  // filled, inclusive
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) dot(x, y, c);
        }
    }

    void line(int x0, int y0, int x1, int y1, int thickness, Rgb c) { draw_line(img_, x0, y0, x1, y1, thickness, c); }

    void text(int x, int y, const std::string& s, Rgb c) {
        for (const char ch : s) {
            const char upper = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
            for (const Glyph& g : kFont) {
                if (g.c != upper) continue;
                for (int row = 0; row < 7; ++row) {
                    for (int col = 0; col < 5; ++col) {
                        if ((g.rows[std::size_t(row)] & (0x10 >> col)) == 0) continue;
                        rect(x + col * kScale, y + row * kScale, x + col * kScale + kScale - 1,
                             y + row * kScale + kScale - 1, c);
                    }
                }
            }
            x += kChar;
        }
    }

    RgbImage take() { return std::move(img_); }

private:
    RgbImage img_;
};

int text_width(const std::string& s) {
    return s.empty() ? 0 : int(s.size()) * kChar - kScale;
}

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

}  // namespace

RgbImage render_line_chart(const LineChart& chart) {
    const int panels = std::max<int>(1, int(chart.panels.size()));
    const int panel_w = kLeft + kPlotW;
    const int width =
        std::max(2 * kMargin + panels * panel_w + (panels - 1) * kPanelGap, 2 * kMargin + text_width(chart.title));
    // The legend (the series of the first panel) wraps onto as many rows as the width needs.
    const std::vector<LineSeries> no_series;
    const std::vector<LineSeries>& legend = chart.panels.empty() ? no_series : chart.panels.front().series;
    const auto entry_width = [](const LineSeries& s) { return 46 + text_width(s.name) + 30; };
    int legend_rows = 1;
    for (int lx = kMargin; const LineSeries& s : legend) {
        if (lx > kMargin && lx + entry_width(s) > width - kMargin) {
            ++legend_rows;
            lx = kMargin;
        }
        lx += entry_width(s);
    }
    const int title_y = kMargin;
    const int legend_y = title_y + kLine + 10;
    const int panel_title_y = legend_y + legend_rows * (kLine + 8) + 10;
    const int plot_y = panel_title_y + kLine + 10;
    const int height = plot_y + kPlotH + 10 + kLine + 10 + kLine + kMargin;
    Canvas canvas(width, height);

    canvas.text(kMargin, title_y, chart.title, kInk);
    int lx = kMargin;
    int ly = legend_y;
    for (const LineSeries& s : legend) {
        if (lx > kMargin && lx + entry_width(s) > width - kMargin) {
            lx = kMargin;
            ly += kLine + 8;
        }
        const int my = ly + kLine / 2;
        canvas.line(lx, my, lx + 36, my, 3, s.color);
        canvas.rect(lx + 14, my - 4, lx + 22, my + 4, s.color);
        if (s.hollow) canvas.rect(lx + 16, my - 2, lx + 20, my + 2, kWhite);
        canvas.text(lx + 46, ly, s.name, kInk);
        lx += entry_width(s);
    }

    const double y_span = chart.y_max > chart.y_min ? chart.y_max - chart.y_min : 1.0;
    for (int p = 0; p < int(chart.panels.size()); ++p) {
        const LinePanel& panel = chart.panels[std::size_t(p)];
        const int x0 = kMargin + p * (panel_w + kPanelGap) + kLeft;  // plot area left
        const int x1 = x0 + kPlotW - 1;
        const int y0 = plot_y;  // plot area top
        const int y1 = y0 + kPlotH - 1;
        canvas.text(x0 + (kPlotW - text_width(panel.title)) / 2, panel_title_y, panel.title, kInk);
        const double x_lo = panel.x.empty() ? 0.0 : panel.x.front();
        const double x_hi = panel.x.empty() ? 1.0 : panel.x.back();
        const double x_span = x_hi > x_lo ? x_hi - x_lo : 1.0;
        const int inset = 14;  // keeps the first and last points off the axes
        const auto px = [&](double v) {
            return x0 + inset + int(std::lround((v - x_lo) / x_span * double(kPlotW - 1 - 2 * inset)));
        };
        const auto py = [&](double v) {
            const double t = std::clamp((v - chart.y_min) / y_span, 0.0, 1.0);
            return y1 - int(std::lround(t * double(kPlotH - 1)));
        };
        // Grid and y ticks.
        for (const double t : chart.y_ticks) {
            const int y = py(t);
            canvas.line(x0, y, x1, y, 1, kGrid);
            canvas.line(x0 - 6, y, x0, y, 1, kInk);
            const std::string label = chart.percent ? number(std::round(t * 100.0)) + "%" : number(t);
            canvas.text(x0 - 10 - text_width(label), y - kLine / 2, label, kInk);
        }
        // x ticks.
        for (std::size_t t = 0; t < panel.x.size(); ++t) {
            const int x = px(panel.x[t]);
            canvas.line(x, y1, x, y1 + 6, 1, kInk);
            const std::string label = t < panel.x_labels.size() ? panel.x_labels[t] : number(panel.x[t]);
            canvas.text(x - text_width(label) / 2, y1 + 10, label, kInk);
        }
        canvas.text(x0 + (kPlotW - text_width(chart.x_label)) / 2, y1 + 10 + kLine + 10, chart.x_label, kInk);
        // Axes.
        canvas.line(x0, y0, x0, y1, 2, kInk);
        canvas.line(x0, y1, x1, y1, 2, kInk);
        // Series: lines, then markers on top.
        for (const LineSeries& s : panel.series) {
            for (std::size_t i = 1; i < std::min(s.y.size(), panel.x.size()); ++i) {
                if (std::isnan(s.y[i - 1]) || std::isnan(s.y[i])) continue;
                canvas.line(px(panel.x[i - 1]), py(s.y[i - 1]), px(panel.x[i]), py(s.y[i]), 3, s.color);
            }
        }
        for (const LineSeries& s : panel.series) {
            for (std::size_t i = 0; i < std::min(s.y.size(), panel.x.size()); ++i) {
                if (std::isnan(s.y[i])) continue;
                const int x = px(panel.x[i]);
                const int y = py(s.y[i]);
                canvas.rect(x - 5, y - 5, x + 5, y + 5, s.color);
                if (s.hollow) canvas.rect(x - 2, y - 2, x + 2, y + 2, kWhite);
            }
        }
    }
    return canvas.take();
}

}  // namespace pyrseg::cli
