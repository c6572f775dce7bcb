#pragma once
// How the CLI prints text that may carry a file name: control characters (a newline, a carriage return, an
// escape sequence) escaped, so that a line stays one line and a name cannot redraw the terminal.
#include <filesystem>
#include <string>
#include <string_view>

namespace pyrseg::cli {

// `text` with each control character (and DEL) written as \n, \r, \t or \xHH; everything else as it is.
[[nodiscard]] std::string printable(std::string_view text);
[[nodiscard]] inline std::string printable(const std::string& text) {
    return printable(std::string_view(text));
}
[[nodiscard]] inline std::string printable(const char* text) {
    return printable(std::string_view(text));
}
// A path as the CLI prints it.
[[nodiscard]] inline std::string printable(const std::filesystem::path& path) {
    return printable(std::string_view(path.native()));
}

}  // namespace pyrseg::cli
