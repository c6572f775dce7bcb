#pragma once
// Consumer depth-camera models (docs/sensors.md): correlated noise fields drawn before ray casting, and the depth
// pipeline applied to the exact hits after it. The structured-light default never comes here.
#include <vector>

#include "pyrseg/synthetic.hpp"

namespace pyrseg::synthetic::detail {

// Spatially correlated gaussian fields of one frame (W*H, row-major), drawn from the seed alone.
struct SensorFields {
    std::vector<float> depth;     // unit sigma: scales the axial noise of each pixel
    std::vector<float> jitter_u;  // pixels: where each pixel's ray really passes; empty without lateral noise
    std::vector<float> jitter_v;
    double max_jitter = 0;  // no |jitter| exceeds this, so that tiles padded by it hold every solid a ray can hit
};

// The seed of a frame's depth noise and sensor fields: noise_seed, or seed when it is 0.
inline std::uint64_t noise_seed_of(const SceneOptions& options) {
    return options.noise_seed != 0 ? options.noise_seed : options.seed;
}

// The thread count for options.threads (0: one per hardware thread).
int thread_count(const SceneOptions& options);

SensorFields make_sensor_fields(const SensorModel& model, const SceneOptions& options, int width, int height);

// Turns the exact hits that render() left in scene (points on the jittered rays; NaN where the geometry gives no
// data) into what the sensor reports: edge dropouts, range limits, flying pixels, axial noise, disparity and
// output quantization, each point on its pixel's nominal ray.
void apply_sensor(const SensorModel& model, const SensorFields& fields, const SceneOptions& options, Scene& scene);

}  // namespace pyrseg::synthetic::detail
