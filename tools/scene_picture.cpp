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

RgbImage dimmed_gray(const RgbImage& image) {
    RgbImage out = image;
    for (std::size_t i = 0; i + 2 < out.rgb.size(); i += 3) {
        const int gray = (int(image.rgb[i]) + int(image.rgb[i + 1]) + int(image.rgb[i + 2])) / 3;
        const auto v = std::uint8_t(24 + gray / 2);
        out.rgb[i] = out.rgb[i + 1] = out.rgb[i + 2] = v;
    }
    return out;
}

namespace {

// Least squares of pixel = f * ratio + c over the sums of a line fit; the RMS miss in pixels.
struct LineFit {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    void add(double x, double y) {
        n += 1;
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
    }
    [[nodiscard]] bool solve(double& f, double& c, double& rms) const {
        const double det = n * sxx - sx * sx;
        if (!(det > 0)) return false;
        f = (n * sxy - sx * sy) / det;
        c = (sy - f * sx) / n;
        // sum (y - f x - c)^2, expanded
        const double sse = syy + f * f * sxx + n * c * c - 2 * f * sxy - 2 * c * sy + 2 * f * c * sx;
        rms = std::sqrt(std::max(0.0, sse) / n);
        return true;
    }
};

}  // namespace

std::optional<PinholeCamera> fit_pinhole(const io::PointCloud& cloud) {
    LineFit u, v;
    for (int y = 0; y < cloud.height; ++y) {
        for (int x = 0; x < cloud.width; ++x) {
            const float* p = cloud.points.data() + 3 * (std::size_t(y) * std::size_t(cloud.width) + std::size_t(x));
            if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !(p[2] > 0) || !std::isfinite(p[2])) continue;
            u.add(double(p[0]) / p[2], x);
            v.add(double(p[1]) / p[2], y);
        }
    }
    if (u.n < 100) return std::nullopt;
    PinholeCamera k;
    double u_rms = 0, v_rms = 0;
    if (!u.solve(k.fx, k.cx, u_rms) || !v.solve(k.fy, k.cy, v_rms)) return std::nullopt;
    if (!(u_rms <= 0.5 && v_rms <= 0.5) || !(k.fx > 0 && k.fy > 0)) return std::nullopt;
    return k;
}

}  // namespace pyrseg::cli
