// Label colours: a low-discrepancy sequence over (hue, shade), so consecutive labels land far apart and the first
// few hundred labels never collide, yet every colour is a pure function of the label.
#include <cstddef>
#include <limits>
#include <string>

#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {

namespace {

// 2^32 / g^2 and 2^32 / g for the plastic number g: the R2 sequence, the 2-D analogue of golden-ratio hashing.
constexpr std::uint32_t kHueStep = 0x91E10DA5u;
constexpr std::uint32_t kShadeStep = 0xC13FA9A9u;
constexpr unsigned kMinLevel = 130;  // lowest saturation or value, out of 255: keeps every colour vivid

// Around the hue circle in six sectors, each channel is full, off, rising or falling.
enum Ramp { full, off, rise, fall };
constexpr Ramp kRamps[6][3] = {{full, rise, off}, {fall, full, off}, {off, full, rise},
                               {off, fall, full}, {rise, off, full}, {full, off, fall}};

unsigned ramp_level(Ramp r, unsigned up) {
    switch (r) {
        case full:
            return 255;
        case off:
            return 0;
        case rise:
            return up;
        case fall:
            return 255 - up;
    }
    return 0;
}

}  // namespace

std::array<std::uint8_t, 3> label_color(std::uint32_t label) {
    if (label == 0) return {0, 0, 0};
    // Integer arithmetic only, so the same label is the same colour on every machine.
    const std::uint32_t hue =
        static_cast<std::uint32_t>((std::uint64_t{static_cast<std::uint32_t>(label * kHueStep)} * 1536) >> 32);
    const unsigned t = (label * kShadeStep) >> 24;
    const unsigned up = hue & 255;
    const unsigned sector = hue >> 8;
    // Half the shades darken the pure hue, half pale it, so colours with nearby hues still differ.
    const unsigned value = t < 128 ? 255 - (127 - t) * (255 - kMinLevel) / 127 : 255;
    const unsigned saturation = t < 128 ? 255 : 255 - (t - 128) * (255 - kMinLevel) / 127;
    std::array<std::uint8_t, 3> out{};
    for (int c = 0; c < 3; ++c) {
        unsigned v = 255 - (saturation * (255 - ramp_level(kRamps[sector][c], up)) + 127) / 255;
        v = (v * value + 127) / 255;
        out[static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(v);
    }
    return out;
}

std::vector<std::uint8_t> colorize_labels(const std::uint32_t* labels, int width, int height) {
    if (width <= 0 || height <= 0 ||
        static_cast<long long>(width) * height > std::numeric_limits<std::ptrdiff_t>::max() / 3) {
        throw Error(ErrorCode::invalid_argument,
                    "colorize_labels: bad image size " + std::to_string(width) + " x " + std::to_string(height));
    }
    if (labels == nullptr) throw Error(ErrorCode::invalid_argument, "colorize_labels: null labels pointer");
    const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<std::uint8_t> rgb(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
        const auto c = label_color(labels[i]);
        rgb[3 * i] = c[0];
        rgb[3 * i + 1] = c[1];
        rgb[3 * i + 2] = c[2];
    }
    return rgb;
}

}  // namespace pyrseg::io
