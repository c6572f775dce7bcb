#include "tools/scene_picture.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "pyrseg/io.hpp"

namespace pyrseg::cli {
namespace {

using Vec3 = std::array<double, 3>;

std::optional<std::array<int, 2>> project(const Vec3& p, const PinholeCamera& k) {
    constexpr double kFar = 1e6;  // pixels: far enough off the picture, small enough for int
    if (!(p[2] > 0)) return std::nullopt;
    const double u = std::clamp(k.fx * p[0] / p[2] + k.cx, -kFar, kFar);
    const double v = std::clamp(k.fy * p[1] / p[2] + k.cy, -kFar, kFar);
    if (!std::isfinite(u) || !std::isfinite(v)) return std::nullopt;
    return std::array<int, 2>{int(std::lround(u)), int(std::lround(v))};
}

void edge(RgbImage& image, const Vec3& a, const Vec3& b, const PinholeCamera& k, std::array<std::uint8_t, 3> color) {
    const auto pa = project(a, k);
    const auto pb = project(b, k);
    if (!pa || !pb) return;
    draw_line(image, (*pa)[0], (*pa)[1], (*pb)[0], (*pb)[1], 2, color);
}

}  // namespace

RgbImage scene_picture(const RgbImage& base, const Scene& scene, const PinholeCamera& camera) {
    RgbImage image = base;
    constexpr std::array<std::uint8_t, 3> kWhite{255, 255, 255};
    for (const SceneSupport& s : scene.supports) {
        const Vec3 flat = {s.extents[0], s.extents[1], 0.0};
        const int ring[4] = {0, 1, 3, 2};
        for (int i = 0; i < 4; ++i) {
            edge(image, box_corner(s.centroid, s.axes, flat, ring[i]),
                 box_corner(s.centroid, s.axes, flat, ring[(i + 1) % 4]), camera, kWhite);
        }
    }
    for (const SceneObject& o : scene.objects) {
        if (o.support < 0) continue;  // over no support: walls, background
        const std::array<std::uint8_t, 3> color = io::label_color(o.label);
        for (int bits = 0; bits < 8; ++bits) {
            for (int a = 0; a < 3; ++a) {
                const int other = bits | (1 << a);
                if (other != bits) {
                    edge(image, box_corner(o.box_centre, o.axes, o.extents, bits),
                         box_corner(o.box_centre, o.axes, o.extents, other), camera, color);
                }
            }
        }
    }
    return image;
}

}  // namespace pyrseg::cli
