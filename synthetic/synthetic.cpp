#include "pyrseg/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include "layout.hpp"
#include "render.hpp"
#include "rng.hpp"

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

constexpr double kPi = 3.141592653589793;

bool finite(const std::array<double, 3>& v) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// The pose's rotation as the moved camera's axes in the default camera's frame (its columns).
detail::Frame frame_of(const Pose& pose) {
    detail::Frame f;
    for (std::size_t c = 0; c < 3; ++c) f.axis[c] = {pose.rotation[0][c], pose.rotation[1][c], pose.rotation[2][c]};
    return f;
}

bool is_rotation(const Pose& pose) {
    for (const auto& row : pose.rotation) {
        if (!finite(row)) return false;
    }
    const detail::Frame f = frame_of(pose);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            if (std::abs(detail::dot(f.axis[i], f.axis[j]) - (i == j ? 1.0 : 0.0)) > 1e-6) return false;
        }
    }
    return detail::dot(detail::cross(f.axis[0], f.axis[1]), f.axis[2]) > 0;
}

void check_frame_options(const SceneOptions& options) {
    check(is_rotation(options.camera_pose), "camera_pose.rotation must be a rotation (orthonormal, determinant 1)");
    check(finite(options.camera_pose.translation), "camera_pose.translation must be finite");
    std::set<std::uint32_t> ids;
    for (const ObjectChange& c : options.object_changes) {
        check(c.id >= kFirstObjectId, "object_changes: id " + std::to_string(c.id) + " is not an object's");
        check(ids.insert(c.id).second, "object_changes: id " + std::to_string(c.id) + " is changed twice");
        check(finite(c.offset), "object_changes: offsets must be finite");
    }
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
    check_frame_options(options);

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
    // A still frame (the default pose, no object changes) is transformed exactly as it always was.
    const bool moved = !(options.camera_pose == Pose{});
    const detail::Frame camera = frame_of(options.camera_pose);
    const detail::Vec3 camera_shift{options.camera_pose.translation[0], options.camera_pose.translation[1],
                                    options.camera_pose.translation[2]};
    std::vector<detail::Solid> solids;
    solids.reserve(layout.solids.size());
    for (detail::Solid s : layout.solids) {
        s.center = layout.camera.to_local(s.center - camera_position);
        for (detail::Vec3& axis : s.frame.axis) axis = layout.camera.to_local(axis);
        const auto change = std::find_if(options.object_changes.begin(), options.object_changes.end(),
                                         [&](const ObjectChange& c) { return c.id == s.id; });
        if (change != options.object_changes.end()) {
            if (change->hidden) continue;
            s.center = s.center + detail::Vec3{change->offset[0], change->offset[1], change->offset[2]};
        }
        if (moved) {
            s.center = camera.to_local(s.center - camera_shift);
            for (detail::Vec3& axis : s.frame.axis) axis = camera.to_local(axis);
        }
        solids.push_back(s);
        scene.primitives.push_back(primitive_of(s));
    }
    detail::render(solids, options, scene);
    return scene;
}

std::vector<SceneOptions> sequence(const SequenceOptions& options) {
    const auto fail = [](bool ok, const std::string& what) {
        if (!ok) throw std::invalid_argument("pyrseg::synthetic::sequence: " + what);
    };
    fail(options.frames >= 1 && options.frames <= 100000, "frames must be within 1..100000");
    fail(std::isfinite(options.max_step_mm) && options.max_step_mm >= 0 && options.max_step_mm <= 200,
         "max_step_mm must be within 0..200");
    fail(std::isfinite(options.max_turn_deg) && options.max_turn_deg >= 0 && options.max_turn_deg <= 30,
         "max_turn_deg must be within 0..30");
    const SceneOptions& scene = options.scene;
    // The scene's own checks, on its still frame (a 1 x 1 image: the layout alone).
    SceneOptions still = scene;
    still.width = still.height = 1;
    still.camera_pose = {};
    still.object_changes.clear();
    still.noise_seed = 0;
    (void)generate(still);

    const auto frames = static_cast<std::size_t>(options.frames);
    const std::size_t steps = frames - 1;

    // The walk: per frame a velocity and a turn (a rotation vector in the camera's own frame), each axis a sum of
    // three cosines, then scaled so that the largest step and turn are the maxima asked.
    detail::Rng walk(scene.seed, detail::Stream::camera_walk);
    std::vector<detail::Vec3> velocity(steps), turn(steps);
    for (int channel = 0; channel < 6; ++channel) {
        // Along the optical axis the camera moves half as much as across it.
        const double weight = channel == 2 ? 0.5 : 1.0;
        double amplitude[3], omega[3], phase[3];
        for (int k = 0; k < 3; ++k) {
            amplitude[k] = weight * walk.uniform(0.5, 1.0);
            omega[k] = 2 * kPi / walk.uniform(20, 60);
            phase[k] = walk.uniform(0, 2 * kPi);
        }
        for (std::size_t i = 0; i < steps; ++i) {
            double v = 0;
            for (int k = 0; k < 3; ++k) v += amplitude[k] * std::cos(omega[k] * static_cast<double>(i) + phase[k]);
            detail::Vec3& out = channel < 3 ? velocity[i] : turn[i];
            (channel % 3 == 0 ? out.x : channel % 3 == 1 ? out.y : out.z) = v;
        }
    }
    const auto scale_to = [](std::vector<detail::Vec3>& values, double maximum) {
        double largest = 0;
        for (const detail::Vec3& v : values) largest = std::max(largest, detail::norm(v));
        const double scale = largest > 0 ? maximum / largest : 0.0;
        for (detail::Vec3& v : values) v = v * scale;
    };
    scale_to(velocity, options.max_step_mm);
    scale_to(turn, options.max_turn_deg * kPi / 180);

    std::vector<SceneOptions> out(frames, scene);
    detail::Vec3 position;
    detail::Frame axes;  // the camera's axes in the default camera's frame
    detail::Rng noise(scene.seed, detail::Stream::frame_noise);
    for (std::size_t i = 0; i < frames; ++i) {
        SceneOptions& frame = out[i];
        frame.object_changes.clear();
        frame.camera_pose = {};
        frame.noise_seed = 0;
        if (i == 0) continue;
        position = position + velocity[i - 1];
        // A turn w about the camera's own axes is the turn R w about the default camera's.
        const detail::Vec3 w = axes.to_parent(turn[i - 1]);
        const double angle = detail::norm(w);
        if (angle > 0) {
            for (detail::Vec3& a : axes.axis) a = detail::rotated(a, w * (1 / angle), angle);
            // Re-orthonormalized, so that rounding does not build up over long sequences.
            axes.axis[0] = detail::normalized(axes.axis[0]);
            axes.axis[1] = detail::normalized(axes.axis[1] - axes.axis[0] * detail::dot(axes.axis[0], axes.axis[1]));
            axes.axis[2] = detail::cross(axes.axis[0], axes.axis[1]);
        }
        for (std::size_t r = 0; r < 3; ++r) {
            for (std::size_t c = 0; c < 3; ++c) {
                const detail::Vec3& a = axes.axis[c];
                frame.camera_pose.rotation[r][c] = r == 0 ? a.x : r == 1 ? a.y : a.z;
            }
        }
        frame.camera_pose.translation = {position.x, position.y, position.z};
        frame.noise_seed = noise.next() | 1;  // never 0, which would mean the scene's seed
    }
    if (!options.object_motion) return out;

    // The objects' plans, one object after another in id order, each drawing the same numbers whatever it does.
    const detail::Layout layout = detail::make_layout(scene);
    detail::Rng rng(scene.seed, detail::Stream::object_motion);
    const int n = options.frames;
    for (const detail::Solid& s : layout.solids) {
        if (s.id < kFirstObjectId) continue;
        const double slide = rng.uniform(), heading = rng.uniform(0, 2 * kPi), reach = rng.uniform(15, 40);
        const double period = rng.uniform(60, 150);
        const double occlude = rng.uniform(), occlusion_length = rng.uniform(2, 9), occlusion_start = rng.uniform();
        const double fate = rng.uniform(), fate_at = rng.uniform();
        // Along the floor: a horizontal direction of the world, in the default camera's frame.
        const detail::Vec3 direction =
            layout.camera.to_local({std::cos(heading), std::sin(heading), 0}) * (slide < 0.4 ? reach : 0.0);
        const int hidden_for = static_cast<int>(occlusion_length);  // 2..8
        const int hidden_from = occlude < 0.5 ? 1 + static_cast<int>(occlusion_start * std::max(1, n - 1)) : n;
        int leaves = n, appears = 0;
        const int third = n / 3, two_thirds = 2 * n / 3;
        if (fate < 0.1) {
            leaves = third + static_cast<int>(fate_at * static_cast<double>(n - third));
        } else if (fate < 0.2) {
            appears = 1 + static_cast<int>(fate_at * static_cast<double>(std::max(1, two_thirds - 1)));
        }
        for (int i = 0; i < n; ++i) {
            ObjectChange change;
            change.id = s.id;
            change.hidden = (i >= hidden_from && i < hidden_from + hidden_for) || i >= leaves || i < appears;
            const double along = std::sin(2 * kPi * i / period);  // from where it lay, to and fro
            change.offset = {direction.x * along, direction.y * along, direction.z * along};
            if (change.hidden || change.offset != std::array<double, 3>{}) {
                out[static_cast<std::size_t>(i)].object_changes.push_back(change);
            }
        }
    }
    return out;
}

}  // namespace pyrseg::synthetic
