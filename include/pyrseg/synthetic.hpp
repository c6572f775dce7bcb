#pragma once
// Seeded synthetic bin-picking scenes as a depth camera (by default a PhoXi-like structured-light scanner, about
// 1.2 m above the floor, looking down) sees them, with exact surface normals and per-pixel ground truth, for tests,
// benchmarks and the demo. Consumer depth cameras (Kinect v1, RealSense D435, Azure Kinect) are modelled too; see
// docs/sensors.md.
//
// The scene lives in millimetres and the field of view is fixed, so every resolution shows the same scene; the
// layout depends only on the seed and on object_count, touching and bin, never on the size, noise, holes, sensor or
// camera distance.
// Output is deterministic for a given seed on a given platform, whatever the thread count.
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "pyrseg/synthetic_export.hpp"

namespace pyrseg::synthetic {

// Values of Scene::object_id.
inline constexpr std::uint32_t kNoDataId = 0;
inline constexpr std::uint32_t kFloorId = 1;
inline constexpr std::uint32_t kBinBottomId = 2;
inline constexpr std::uint32_t kFirstWallId = 3;  // the four walls are 3, 4, 5, 6
inline constexpr std::uint32_t kFirstObjectId = 7;

inline constexpr int kMaxImageSide = 16384;
inline constexpr int kMaxObjectCount = 1000;

// The depth camera whose noise and missing data the frame shows.
enum class Sensor : std::uint8_t { structured_light, kinect_v1, realsense_d435, azure_kinect };

// Where the camera is, relative to where generate() puts it by default, in the default camera's frame (x right, y
// down, z forward, mm): the moved camera's axes are the columns of rotation (row-major, orthonormal, right-handed)
// and its centre is translation. A point at p in the default camera's frame is at rotation^T (p - translation) in
// the moved camera's. The projector (or second imager) moves with the camera.
struct Pose {
    std::array<std::array<double, 3>, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    std::array<double, 3> translation{};
    friend bool operator==(const Pose&, const Pose&) = default;
};

// One object of the layout moved or left out of a frame (the objects of a sequence that move, leave and appear).
struct ObjectChange {
    std::uint32_t id = 0;            // an object's id (kFirstObjectId and up); ids the layout did not place are ignored
    std::array<double, 3> offset{};  // mm, in the default camera's frame (before camera_pose)
    bool hidden = false;             // left out of the frame: what it hid shows
    friend bool operator==(const ObjectChange&, const ObjectChange&) = default;
};

struct SceneOptions {
    int width = 640;
    int height = 480;
    std::uint64_t seed = 1;
    int object_count = 12;        // boxes, cylinders and spheres in the bin, 0..max_object_count
    double noise_mm = 0.1;        // sigma of gaussian depth noise along the viewing ray (0: none); structured_light
                                  // only: the other sensors follow their own noise model (SensorModel)
    double hole_fraction = 0.01;  // approximate fraction of pixels in missing-data blobs, 0..1 (0: no missing data)
    bool touching = true;         // pack objects so that several touch each other and the bin walls
    bool bin = true;              // a bin (bottom + walls) on the floor; false: objects on a plain floor
    // The depth camera whose noise and missing data the frame shows (docs/sensors.md).
    Sensor sensor = Sensor::structured_light;
    // From the camera to the floor point it looks at, 300..6000 mm. Only the camera moves (along its axis); the
    // layout stays as it is.
    double camera_distance_mm = 1200;
    // Structured-light dropouts on top of the blobs: where the projector (150 mm beside the camera) cannot light
    // the surface, and surfaces seen or lit at grazing angles; for the other sensors all their missing data
    // (shadows, grazing angles, depth edges, out of range, the stereo band). Only when hole_fraction > 0, so that
    // hole_fraction = 0 always gives a complete frame.
    bool shadows = true;
    int threads = 0;  // 0: one per hardware thread; the output does not depend on it
    // The frame of a sequence (sequence() sets these; the defaults give the still scene): the camera's pose relative
    // to where camera_distance_mm puts it; objects moved or left out (at most one change per id); and the seed of
    // the depth noise and of the sensor models' random fields (0: seed), so that frames of one scene differ in
    // their noise as a real camera's do. The layout and the missing-data blobs follow seed alone.
    Pose camera_pose;
    std::vector<ObjectChange> object_changes;
    std::uint64_t noise_seed = 0;
};

enum class Shape : std::uint8_t { plane, box, cylinder, sphere };

// One analytic solid of the scene in camera space (mm). Every valid pixel with object_id k lies, noise aside, on
// the surface of the primitive with id k.
struct Primitive {
    std::uint32_t id = 0;
    Shape shape = Shape::plane;
    std::array<double, 3> center{};               // plane: a point on it
    std::array<std::array<double, 3>, 3> axes{};  // orthonormal local x, y, z; plane: z is the normal, toward the
                                                  // camera; cylinder: z is the axis
    std::array<double, 3> half_size{};            // box: half edges; cylinder: radius, radius, half length;
                                                  // sphere: the radius three times; plane: zeros
    friend bool operator==(const Primitive&, const Primitive&) = default;
};

struct Scene {
    int width = 0, height = 0;
    double fx = 0, fy = 0, cx = 0, cy = 0;  // pinhole intrinsics used (pixels); pixel (u, v) sees the ray
                                            // ((u - cx) / fx, (v - cy) / fy, 1)
    std::vector<float> points;              // 3*W*H xyz, mm, camera space (z forward, y down); NaN where no data
    std::vector<float> normals;             // 3*W*H exact unit normals toward the camera; NaN where no data
    std::vector<std::uint32_t> object_id;   // W*H ground truth: 0 no data, 1 floor, 2 bin bottom, 3..6 bin walls,
                                            // 7.. objects
    int objects_placed = 0;                 // objects that fit; fewer than object_count when the bin is full
    std::vector<Primitive> primitives;      // floor, bin parts (when bin), then the objects, ids 7, 8, ...
};

// Throws std::invalid_argument for width or height outside 1..max_image_side, object_count outside
// 0..max_object_count, noise_mm negative or not finite, hole_fraction outside 0..1, camera_distance_mm outside
// 300..6000, an unknown sensor, threads negative, a camera_pose whose rotation is not a rotation (within 1e-6) or
// whose numbers are not finite, or an object change with an id below kFirstObjectId, an id changed twice or an
// offset not finite. The camera must stay outside every solid (the floor's side of it).
PYRSEG_SYNTHETIC_EXPORT Scene generate(const SceneOptions& options);

// A sequence of frames of one scene for tracking (`pyrseg eval --tracks`): the camera on a smooth random walk that
// starts at its default pose, and, with object_motion, objects that slide, vanish for a few frames (occluded) and
// come back, leave for good, or appear later. The walk's velocity and turn rate are sums of three cosines per axis
// (periods 20..60 frames, seeded), scaled so that the largest step between two frames is max_step_mm and the
// largest turn max_turn_deg (a typical step is half the largest). Sums of cosines keep the camera near its start:
// with the defaults, seeds 1..6 stay within 161 mm and 25 degrees of it over 300 frames.
struct SequenceOptions {
    SceneOptions scene;       // the scene and the sensor; its camera_pose, object_changes and noise_seed are replaced
    int frames = 300;         // 1..100000
    double max_step_mm = 20;  // the camera moves at most this far from one frame to the next, 0..200
    double max_turn_deg = 2;  // and turns at most this much, 0..30
    bool object_motion = false;
    // With object_motion, for each object in turn (seeded): with probability 0.4 it slides along the floor to and
    // fro (15..40 mm from where it lay, one period in 60..150 frames, so at most 4.2 mm a frame); with
    // probability 0.5 it is hidden for 2..8 frames once, anywhere after frame 0; with probability 0.1 it leaves for
    // good after the first third, else with probability 0.1 it appears (is hidden until a frame in the first two
    // thirds).
};

// Each frame's options for generate(): the scene's, with the frame's camera_pose, object_changes and noise_seed
// (frame 0: the default pose and the scene's own noise). Throws std::invalid_argument for options out of range, as
// generate() does for the scene.
PYRSEG_SYNTHETIC_EXPORT std::vector<SceneOptions> sequence(const SequenceOptions& options);

// Pairs of objects (ids a < b, sorted) that no depth data can tell apart: two upright boxes whose top faces lie in
// one plane (within 0.05 mm) and touch along a side (within 0.05 mm), as identical parts packed side by side in a
// bin. Their visible surfaces meet with no depth step and no crease, so any segmentation from depth alone sees one
// surface there; `pyrseg eval` reports its merge rates with and without these pairs (docs/quality.md).
PYRSEG_SYNTHETIC_EXPORT std::vector<std::array<std::uint32_t, 2>> flush_pairs(const Scene& scene);

// "structured-light", "kinect-v1", "realsense-d435", "azure-kinect"; nullptr for a value outside the enum.
PYRSEG_SYNTHETIC_EXPORT const char* sensor_name(Sensor sensor);
// The sensor of that name (as sensor_name writes it); nullopt for any other string.
PYRSEG_SYNTHETIC_EXPORT std::optional<Sensor> sensor_from_name(std::string_view name);

// The random depth error (sigma, mm) before quantization at depth z (mm) is
//   sqrt(polynomial(z)^2 + (z^2 / (f b) * disparity_sigma_px)^2),
//   polynomial(z) = constant_mm + linear * z + quadratic_per_mm * (z - quadratic_origin_mm)^2,
// with f the frame's focal length (pixels) and b the baseline. Pixel quantities are pixels of the generated frame,
// as if the sensor had that resolution with the generator's fixed field of view. See docs/sensors.md for sources.
struct AxialNoise {
    double constant_mm = 0;
    double linear = 0;            // mm per mm of depth
    double quadratic_per_mm = 0;  // mm per mm^2
    double quadratic_origin_mm = 0;
    double disparity_sigma_px = 0;  // matching noise in disparity; needs baseline_mm > 0
};

struct SensorModel {
    Sensor sensor = Sensor::structured_light;
    // Projector or second imager along the camera's +x (mm); points it cannot see have no data. Triangulating
    // sensors measure disparity d = f b / z. 0: the illuminator sits at the camera (time of flight).
    double baseline_mm = 0;
    bool time_of_flight = false;       // measures depth directly: no disparity, flying pixels at edges
    double disparity_step_px = 0;      // disparity quantization (subpixel step); 0: none
    AxialNoise axial;                  // random depth error
    double correlation_radius_px = 0;  // noise and jitter are box-filtered over (2r + 1)^2 pixels; 0: white
    double lateral_sigma_px = 0;       // jitter of the ray each pixel samples (pixels)
    double depth_step_mm = 0;          // output rounding (1: whole millimetres as uint16 sensors); 0: none
    double min_depth_mm = 0;           // no data nearer ...
    double max_depth_mm = 0;           // ... or farther than this (0: no limit)
    double min_cos = 0;                // no data where the camera (or projector) sees the surface at a cosine
                                       // below this (grazing angles)
    double edge_dropout = 0;           // probability that a pixel at a depth discontinuity has no data
    double flying_pixel = 0;           // probability that a kept pixel at a discontinuity mixes both depths
    bool stereo_band = false;          // no data where the second imager (same field of view) does not see
};

// The parameters of a sensor. structured_light describes the PhoXi-like default (its noise is noise_mm).
PYRSEG_SYNTHETIC_EXPORT SensorModel sensor_model(Sensor sensor);

// Fillable masks whose one region winds across the whole frame, the worst cases of fills that carry labels a step
// at a time: corridors 8 pixels wide between 8-pixel walls (so that they survive to level N - 2), 1 = fillable.
struct FillMask {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> fillable;  // W*H, row-major
};
// A square spiral from the border inwards; each lap turns four times.
PYRSEG_SYNTHETIC_EXPORT FillMask spiral_mask(int width, int height);
// A perfect maze (depth-first from the top-left cell, seeded) on a grid of 16-pixel cells.
PYRSEG_SYNTHETIC_EXPORT FillMask maze_mask(int width, int height, std::uint32_t seed = 12345);

}  // namespace pyrseg::synthetic
