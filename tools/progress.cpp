#include "tools/progress.hpp"

#include <unistd.h>

#include <algorithm>

#include "tools/args.hpp"
#include "tools/printable.hpp"

namespace pyrseg::cli {

Progress::Style Progress::style_for(const std::string& option, std::FILE* out) {
    if (option == "bar") return Style::bar;
    if (option == "lines") return Style::lines;
    if (option == "none") return Style::none;
    if (option != "auto") throw UsageError{"--progress expects auto, bar, lines or none, got '" + option + "'"};
    return isatty(fileno(out)) != 0 ? Style::bar : Style::lines;
}

Progress::Progress(std::size_t total, Style style, std::FILE* out) : total_(total), style_(style), out_(out) {
    if (style_ == Style::bar) draw_bar();
}

double Progress::elapsed_seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::frame_done(const std::string& line, bool failed) {
    ++done_;
    const std::string shown = printable(line);
    if (style_ == Style::lines) {
        std::fprintf(out_, "[%zu/%zu] %s\n", done_, total_, shown.c_str());
    } else if (style_ == Style::bar) {
        if (failed) std::fprintf(out_, "\r\033[K%s\n", shown.c_str());  // failures stay visible above the bar
        draw_bar();
    }
    std::fflush(out_);
}

void Progress::draw_bar() {
    constexpr int kWidth = 30;
    const double seconds = elapsed_seconds();
    const double fps = seconds > 0 ? double(done_) / seconds : 0.0;
    const int filled = total_ == 0 ? kWidth : int(double(kWidth) * double(done_) / double(total_));
    std::string bar(std::size_t(filled), '=');
    if (filled < kWidth) bar += '>';
    bar.resize(kWidth, ' ');
    const double eta = fps > 0 ? double(total_ - done_) / fps : 0.0;
    std::fprintf(out_, "\r\033[K[%s] %zu/%zu frames  %.1f fps  ETA %.0f s", bar.c_str(), done_, total_, fps,
                 std::max(0.0, eta));
}

void Progress::finish() {
    if (style_ == Style::bar) std::fprintf(out_, "\n");
    std::fflush(out_);
}

}  // namespace pyrseg::cli
