#include "pyrseg/synthetic.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "layout.hpp"
#include "render.hpp"

namespace pyrseg::synthetic {
namespace {

constexpr double kMinCameraDistance = 300;   // above the highest pile (rim + 60 mm) with room for a near range
constexpr double kMaxCameraDistance = 6000;  // beyond every modelled sensor's range

void check(bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("pyrseg::synthetic::generate: " + what);
}

std::array<double, 3> array_of(detail::Vec3 v) {
    return {v.x, v.y, v.z};
}

Primitive primitive_of(const detail::Solid& s) {
    Primitive p;
    p.id = s.id;
    p.shape = s.shape;
    p.center = array_of(s.center);
    for (int i = 0; i < 3; ++i) p.axes[static_cast<std::size_t>(i)] = array_of(s.frame.axis[i]);
    p.half_size = array_of(s.half);
    return p;
}

}  // namespace

Scene generate(const SceneOptions& options) {
    check(options.width >= 1 && options.width <= kMaxImageSide,
          "width " + std::to_string(options.width) + " is outside 1.." + std::to_string(kMaxImageSide));
    check(options.height >= 1 && options.height <= kMaxImageSide,
          "height " + std::to_string(options.height) + " is outside 1.." + std::to_string(kMaxImageSide));
    check(options.object_count >= 0 && options.object_count <= kMaxObjectCount,
          "object_count " + std::to_string(options.object_count) + " is outside 0.." + std::to_string(kMaxObjectCount));
    check(std::isfinite(options.noise_mm) && options.noise_mm >= 0, "noise_mm must be finite and >= 0");
    check(options.hole_fraction >= 0 && options.hole_fraction <= 1, "hole_fraction must be within 0..1");
    check(std::isfinite(options.camera_distance_mm) && options.camera_distance_mm >= kMinCameraDistance &&
              options.camera_distance_mm <= kMaxCameraDistance,
          "camera_distance_mm must be within 300..6000");
    check(sensor_name(options.sensor) != nullptr, "unknown sensor");
    check(options.threads >= 0, "threads must be >= 0");

    const detail::Layout layout = detail::make_layout(options);

    Scene scene;
    scene.width = options.width;
    scene.height = options.height;
    scene.fx = scene.fy = detail::focal_length(options.width, options.height);
    scene.cx = (options.width - 1) / 2.0;
    scene.cy = (options.height - 1) / 2.0;
    scene.objects_placed = layout.objects_placed;

    // The camera slides along its own axis to the asked distance from the floor point it looks at, so that the
    // layout stays as it is (the default, 1200 mm, is where the layout put it, to the bit).
    const detail::Vec3 camera_position = layout.camera.axis[2] * -options.camera_distance_mm;
    std::vector<detail::Solid> solids = layout.solids;
    for (detail::Solid& s : solids) {
        s.center = layout.camera.to_local(s.center - camera_position);
        for (detail::Vec3& axis : s.frame.axis) axis = layout.camera.to_local(axis);
        scene.primitives.push_back(primitive_of(s));
    }
    detail::render(solids, options, scene);
    return scene;
}

}  // namespace pyrseg::synthetic
