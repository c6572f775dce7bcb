#pragma once
// Progress of a batch: a bar redrawn in place on a terminal (frames, fps, ETA), or one plain line per frame when
// the output is a file or a pipe.
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace pyrseg::cli {

class Progress {
public:
    enum class Style { bar, lines, none };
    // auto: a bar when `out` is a terminal, else lines.
    [[nodiscard]] static Style style_for(const std::string& option, std::FILE* out);

    Progress(std::size_t total, Style style, std::FILE* out);
    // After each frame; `line` describes it (used by Style::lines, and printed above the bar for failures).
    void frame_done(const std::string& line, bool failed);
    void finish();  // ends the bar's line
    [[nodiscard]] double elapsed_seconds() const;

private:
    void draw_bar();
    std::size_t total_;
    std::size_t done_ = 0;
    Style style_;
    std::FILE* out_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace pyrseg::cli
