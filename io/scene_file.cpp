// The scene summary (pyrseg/scene.hpp) as JSON (nlohmann/json), or its boxes and support outlines as a PLY mesh.
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {
namespace {

using Vec3 = std::array<double, 3>;

nlohmann::json number(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json vector3(const Vec3& v) {
    return {number(v[0]), number(v[1]), number(v[2])};
}

nlohmann::json axes3(const std::array<Vec3, 3>& axes) {
    return {vector3(axes[0]), vector3(axes[1]), vector3(axes[2])};
}

std::string to_json(const Scene& scene, const SegmentTable& frame) {
    nlohmann::json doc;
    doc["source"] = frame.source;
    doc["width"] = frame.width;
    doc["height"] = frame.height;
    doc["unit_mm"] = frame.unit_mm;
    nlohmann::json supports = nlohmann::json::array();
    for (const SceneSupport& s : scene.supports) {
        supports.push_back(
            {{"label", s.label},
             {"pixel_count", s.pixel_count},
             {"plane", {{"normal", vector3(s.normal)}, {"offset", number(s.offset)}}},
             {"rms", number(s.rms)},
             {"level", s.level},
             {"centroid", vector3(s.centroid)},
             {"box", {{"centre", vector3(s.centroid)}, {"axes", axes3(s.axes)}, {"extents", vector3(s.extents)}}}});
    }
    nlohmann::json objects = nlohmann::json::array();
    for (const SceneObject& o : scene.objects) {
        objects.push_back(
            {{"label", o.label},
             {"pixel_count", o.pixel_count},
             {"support", o.support},
             {"touches", o.touches},
             {"support_label",
              o.support >= 0 ? nlohmann::json(scene.supports[std::size_t(o.support)].label) : nlohmann::json(nullptr)},
             {"height", number(o.height)},
             {"centroid", vector3(o.centroid)},
             {"box", {{"centre", vector3(o.box_centre)}, {"axes", axes3(o.axes)}, {"extents", vector3(o.extents)}}}});
    }
    doc["supports"] = std::move(supports);
    doc["objects"] = std::move(objects);
    return doc.dump(1) + "\n";
}

// ASCII PLY: each object's box as 8 vertices and 12 triangles in its segment's colour; each support's outline (its
// box's rectangle in its plane) as 4 vertices and 2 triangles, in its colour.
std::string to_ply(const Scene& scene) {
    std::string vertices;
    std::string faces;
    std::size_t vertex_count = 0;
    std::size_t face_count = 0;
    auto add_vertex = [&](const Vec3& p, std::uint32_t label) {
        const std::array<std::uint8_t, 3> rgb = label_color(label);
        char line[160];
        std::snprintf(line, sizeof line, "%.9g %.9g %.9g %u %u %u\n", p[0], p[1], p[2], unsigned(rgb[0]),
                      unsigned(rgb[1]), unsigned(rgb[2]));
        vertices += line;
        ++vertex_count;
    };
    auto add_triangle = [&](std::size_t a, std::size_t b, std::size_t c) {
        faces += "3 " + std::to_string(a) + ' ' + std::to_string(b) + ' ' + std::to_string(c) + '\n';
        ++face_count;
    };
    auto add_quad = [&](std::size_t first, int a, int b, int c, int d) {
        add_triangle(first + std::size_t(a), first + std::size_t(b), first + std::size_t(c));
        add_triangle(first + std::size_t(a), first + std::size_t(c), first + std::size_t(d));
    };
    for (const SceneSupport& s : scene.supports) {
        const std::size_t first = vertex_count;
        const Vec3 flat = {s.extents[0], s.extents[1], 0.0};
        for (const int bits : {0, 1, 3, 2}) add_vertex(box_corner(s.centroid, s.axes, flat, bits), s.label);
        add_quad(first, 0, 1, 2, 3);
    }
    for (const SceneObject& o : scene.objects) {
        if (!std::isfinite(o.extents[0]) || !std::isfinite(o.extents[1]) || !std::isfinite(o.extents[2])) continue;
        const std::size_t first = vertex_count;
        // Vertex i is box_corner i (bit a set: the positive side of axis a).
        for (int i = 0; i < 8; ++i) add_vertex(box_corner(o.box_centre, o.axes, o.extents, i), o.label);
        add_quad(first, 0, 2, 3, 1);  // z-
        add_quad(first, 4, 5, 7, 6);  // z+
        add_quad(first, 0, 1, 5, 4);  // y-
        add_quad(first, 2, 6, 7, 3);  // y+
        add_quad(first, 0, 4, 6, 2);  // x-
        add_quad(first, 1, 3, 7, 5);  // x+
    }
    return "ply\nformat ascii 1.0\ncomment pyrseg scene: object boxes and support outlines\nelement vertex " +
           std::to_string(vertex_count) +
           "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
           "property uchar blue\nelement face " +
           std::to_string(face_count) + "\nproperty list uchar int vertex_indices\nend_header\n" + vertices + faces;
}

}  // namespace

void write_scene(const std::filesystem::path& path, const Scene& scene, const SegmentTable& frame) {
    const std::string text = detail::lower_extension(path) == ".ply" ? to_ply(scene) : to_json(scene, frame);
    detail::write_file(path, text.data(), text.size());
}

}  // namespace pyrseg::io
