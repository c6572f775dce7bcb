#pragma once
// Seeded synthetic bin-picking scenes as a structured-light camera (PhoXi-like, about 1.2 m above the floor,
// looking down) sees them, with exact surface normals and per-pixel ground truth, for tests, benchmarks and the demo.
//
// The scene lives in millimetres and the field of view is fixed, so every resolution shows the same scene; the
// layout depends only on the seed and on object_count, touching and bin, never on the size, noise or holes.
// Output is deterministic for a given seed on a given platform, whatever the thread count.
#include <array>
#include <cstdint>
#include <vector>

namespace pyrseg::synthetic {

// Values of Scene::object_id.
inline constexpr std::uint32_t kNoDataId = 0;
inline constexpr std::uint32_t kFloorId = 1;
inline constexpr std::uint32_t kBinBottomId = 2;
inline constexpr std::uint32_t kFirstWallId = 3;  // the four walls are 3, 4, 5, 6
inline constexpr std::uint32_t kFirstObjectId = 7;

inline constexpr int kMaxImageSide = 16384;
inline constexpr int kMaxObjectCount = 1000;

struct SceneOptions {
    int width = 640;
    int height = 480;
    std::uint64_t seed = 1;
    int object_count = 12;        // boxes, cylinders and spheres in the bin, 0..max_object_count
    double noise_mm = 0.1;        // sigma of gaussian depth noise along the viewing ray (0: none)
    double hole_fraction = 0.01;  // approximate fraction of pixels in missing-data blobs, 0..1 (0: no missing data)
    bool touching = true;         // pack objects so that several touch each other and the bin walls
    bool bin = true;              // a bin (bottom + walls) on the floor; false: objects on a plain floor
    // Structured-light dropouts on top of the blobs: where the projector (150 mm beside the camera) cannot light
    // the surface, and surfaces seen or lit at grazing angles. Only when hole_fraction > 0, so that
    // hole_fraction = 0 always gives a complete frame.
    bool shadows = true;
    int threads = 0;  // 0: one per hardware thread; the output does not depend on it
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
// 0..max_object_count, noise_mm negative or not finite, hole_fraction outside 0..1, or threads negative.
Scene generate(const SceneOptions& options);

// Fillable masks whose one region winds across the whole frame, the worst cases of fills that carry labels a step
// at a time: corridors 8 pixels wide between 8-pixel walls (so that they survive to level N - 2), 1 = fillable.
struct FillMask {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> fillable;  // W*H, row-major
};
// A square spiral from the border inwards; each lap turns four times.
FillMask spiral_mask(int width, int height);
// A perfect maze (depth-first from the top-left cell, seeded) on a grid of 16-pixel cells.
FillMask maze_mask(int width, int height, std::uint32_t seed = 12345);

}  // namespace pyrseg::synthetic
