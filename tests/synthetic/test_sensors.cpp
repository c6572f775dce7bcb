// Tests of the synthetic generator's sensor models: the structured-light default untouched, determinism, the
// camera distance, and the measured noise, quantization, spatial correlation and missing data of each consumer
// model against its documented parameters (docs/sensors.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pyrseg/synthetic.hpp"

namespace {

namespace syn = pyrseg::synthetic;
using syn::generate;
using syn::Scene;
using syn::SceneOptions;
using syn::Sensor;

const Sensor kConsumers[] = {Sensor::kinect_v1, Sensor::realsense_d435, Sensor::azure_kinect};
const Sensor kAll[] = {Sensor::structured_light, Sensor::kinect_v1, Sensor::realsense_d435, Sensor::azure_kinect};

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_scene(const Scene& a, const Scene& b) {
    return a.width == b.width && a.height == b.height && same_bytes(a.points, b.points) &&
           same_bytes(a.normals, b.normals) && same_bytes(a.object_id, b.object_id) && a.primitives == b.primitives;
}

std::size_t index(const Scene& s, int u, int v) {
    return static_cast<std::size_t>(v) * static_cast<std::size_t>(s.width) + static_cast<std::size_t>(u);
}

bool valid(const Scene& s, std::size_t i) {
    return s.object_id[i] != syn::kNoDataId;
}

// Depth (mm) of the floor plane along pixel (u, v)'s nominal ray.
double floor_depth(const Scene& s, double u, double v) {
    const syn::Primitive& floor = s.primitives.front();
    const auto& n = floor.axes[2];
    const double d[3] = {(u - s.cx) / s.fx, (v - s.cy) / s.fy, 1.0};
    const double nc = n[0] * floor.center[0] + n[1] * floor.center[1] + n[2] * floor.center[2];
    return nc / (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]);
}

// A plain floor: no objects, no bin; complete (no missing data) unless holes are asked for.
SceneOptions plain_floor(Sensor sensor, double distance, int width = 320, int height = 240) {
    SceneOptions o;
    o.sensor = sensor;
    o.camera_distance_mm = distance;
    o.width = width;
    o.height = height;
    o.object_count = 0;
    o.bin = false;
    o.hole_fraction = 0;
    o.seed = 3;
    return o;
}

// Sigma (mm) of the model's random depth error before quantization at depth z, as the header documents it.
double law_sigma(const syn::SensorModel& m, double z, double f) {
    const double q = z - m.axial.quadratic_origin_mm;
    const double poly = m.axial.constant_mm + m.axial.linear * z + m.axial.quadratic_per_mm * q * q;
    const double disparity = m.baseline_mm > 0 ? z * z / (f * m.baseline_mm) * m.axial.disparity_sigma_px : 0.0;
    return std::hypot(poly, disparity);
}

// Depth step (mm) that the disparity quantization makes at depth z; 0 without one.
double disparity_step_mm(const syn::SensorModel& m, double z, double f) {
    return m.baseline_mm > 0 && m.disparity_step_px > 0 ? z * z / (f * m.baseline_mm) * m.disparity_step_px : 0.0;
}

TEST(Sensors, StructuredLightIsTheDefault) {
    SceneOptions o;
    o.width = 160;
    o.height = 120;
    const Scene plain = generate(o);
    o.sensor = Sensor::structured_light;
    o.camera_distance_mm = 1200;
    EXPECT_TRUE(same_scene(plain, generate(o)));
    o.sensor = Sensor::kinect_v1;
    EXPECT_FALSE(same_bytes(plain.points, generate(o).points));
}

TEST(Sensors, ThreadCountDoesNotChangeOutput) {
    for (const Sensor sensor : kAll) {
        SCOPED_TRACE(syn::sensor_name(sensor));
        SceneOptions o;
        o.sensor = sensor;
        o.width = 331;  // ragged tiles and bands
        o.height = 203;
        o.threads = 1;
        const Scene one = generate(o);
        o.threads = 4;
        const Scene four = generate(o);
        EXPECT_TRUE(same_scene(one, four));
        // The per-pixel invariants of every scene: NaN exactly where there is no data, unit normals facing the
        // camera, and the point on the pixel's nominal ray.
        std::size_t bad = 0;
        for (int v = 0; v < one.height; ++v) {
            for (int u = 0; u < one.width; ++u) {
                const std::size_t i = index(one, u, v);
                const float* p = &one.points[3 * i];
                const float* n = &one.normals[3 * i];
                if (!valid(one, i)) {
                    bad += !(std::isnan(p[0]) && std::isnan(p[2]) && std::isnan(n[0]) && std::isnan(n[2]));
                    continue;
                }
                bad += std::abs(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) - 1) > 1e-6;
                bad += !(n[0] * p[0] + n[1] * p[1] + n[2] * p[2] < 0) || !(p[2] > 0);
                bad += std::abs(p[0] - (u - one.cx) * p[2] / one.fx) > 1e-3 * p[2] / one.fx;
            }
        }
        EXPECT_EQ(bad, 0u);
    }
}

TEST(Sensors, NamesRoundTrip) {
    for (const Sensor sensor : kAll) {
        ASSERT_NE(syn::sensor_name(sensor), nullptr);
        EXPECT_EQ(syn::sensor_from_name(syn::sensor_name(sensor)), sensor);
        EXPECT_EQ(syn::sensor_model(sensor).sensor, sensor);
    }
    EXPECT_STREQ(syn::sensor_name(Sensor::kinect_v1), "kinect-v1");
    EXPECT_STREQ(syn::sensor_name(Sensor::realsense_d435), "realsense-d435");
    EXPECT_STREQ(syn::sensor_name(Sensor::azure_kinect), "azure-kinect");
    EXPECT_STREQ(syn::sensor_name(Sensor::structured_light), "structured-light");
    EXPECT_FALSE(syn::sensor_from_name("kinect").has_value());
    EXPECT_FALSE(syn::sensor_from_name("").has_value());
    EXPECT_FALSE(syn::sensor_from_name("Kinect-V1").has_value());
    EXPECT_EQ(syn::sensor_name(static_cast<Sensor>(17)), nullptr);
}

TEST(Sensors, RejectsInvalidCameraDistanceAndSensor) {
    for (const double distance : {299.0, 6001.0, -1200.0, std::nan(""), HUGE_VAL}) {
        SceneOptions o;
        o.width = o.height = 8;
        o.camera_distance_mm = distance;
        EXPECT_THROW(generate(o), std::invalid_argument) << distance;
    }
    SceneOptions o;
    o.width = o.height = 8;
    o.sensor = static_cast<Sensor>(17);
    EXPECT_THROW(generate(o), std::invalid_argument);
    for (const double distance : {300.0, 6000.0}) {
        o.sensor = Sensor::kinect_v1;
        o.camera_distance_mm = distance;
        EXPECT_NO_THROW(generate(o)) << distance;
    }
}

TEST(Sensors, CameraDistanceMovesOnlyTheCamera) {
    SceneOptions o;
    o.width = o.height = 8;
    const Scene near = generate(o);
    o.camera_distance_mm = 2500;
    const Scene far = generate(o);
    ASSERT_EQ(near.primitives.size(), far.primitives.size());
    EXPECT_EQ(near.objects_placed, far.objects_placed);
    for (std::size_t i = 0; i < near.primitives.size(); ++i) {
        const syn::Primitive &a = near.primitives[i], &b = far.primitives[i];
        EXPECT_EQ(a.axes, b.axes);
        EXPECT_EQ(a.half_size, b.half_size);
        EXPECT_NEAR(b.center[0], a.center[0], 1e-9);
        EXPECT_NEAR(b.center[1], a.center[1], 1e-9);
        EXPECT_NEAR(b.center[2] - a.center[2], 1300, 1e-9);
    }
}

// Distinct depths of a plain floor differ by the disparity quantization step at that depth, in whole millimetres.
TEST(Sensors, DepthIsQuantizedLikeTheSensor) {
    for (const Sensor sensor : kConsumers) {
        for (const double distance : {1200.0, 2400.0}) {
            SCOPED_TRACE(std::string(syn::sensor_name(sensor)) + " at " + std::to_string(distance));
            const Scene s = generate(plain_floor(sensor, distance));
            const syn::SensorModel m = syn::sensor_model(sensor);
            std::vector<float> z;
            for (std::size_t i = 0; i < s.object_id.size(); ++i) z.push_back(s.points[3 * i + 2]);
            std::sort(z.begin(), z.end());
            const double median_z = z[z.size() / 2];
            z.erase(std::unique(z.begin(), z.end()), z.end());
            std::vector<double> gaps;
            for (std::size_t i = 1; i < z.size(); ++i) {
                EXPECT_EQ(z[i], std::round(z[i])) << "whole millimetres";
                gaps.push_back(z[i] - z[i - 1]);
            }
            ASSERT_GE(gaps.size(), 3u);
            // Near the median depth only: the step grows with z^2 across the frame.
            std::vector<double> local;
            for (std::size_t i = 1; i < z.size(); ++i) {
                if (std::abs(z[i] - median_z) < 0.04 * median_z) local.push_back(z[i] - z[i - 1]);
            }
            ASSERT_FALSE(local.empty());
            std::nth_element(local.begin(), local.begin() + static_cast<std::ptrdiff_t>(local.size() / 2), local.end());
            const double gap = local[local.size() / 2];
            const double expected = std::max(disparity_step_mm(m, median_z, s.fx), m.depth_step_mm);
            std::printf("  %-15s z %6.0f mm: median gap %6.2f mm, model step %6.2f mm\n", syn::sensor_name(sensor),
                        median_z, gap, expected);
            EXPECT_LE(std::abs(gap - expected), std::max(1.0, 0.12 * expected));
        }
    }
}

struct NoiseStats {
    double law_mm = 0;       // rms of the model's sigma over the pixels
    double measured_mm = 0;  // measured, with the known quantization variance taken out
    double lag1 = 0;         // residual autocorrelation one pixel apart along rows
};

// Residuals of a plain floor against its exact depth along each pixel's nominal ray.
NoiseStats floor_noise(Sensor sensor, double distance, int width, int height) {
    const Scene s = generate(plain_floor(sensor, distance, width, height));
    const syn::SensorModel m = syn::sensor_model(sensor);
    std::vector<double> r(s.object_id.size());
    double sum_r2 = 0, sum_law2 = 0, sum_quant = 0, sum_r = 0;
    for (int v = 0; v < s.height; ++v) {
        for (int u = 0; u < s.width; ++u) {
            const std::size_t i = index(s, u, v);
            EXPECT_TRUE(valid(s, i));
            const double z = floor_depth(s, u, v);
            r[i] = s.points[3 * i + 2] - z;
            sum_r += r[i];
            sum_r2 += r[i] * r[i];
            sum_law2 += std::pow(law_sigma(m, z, s.fx), 2);
            // Quantization (disparity, then output rounding) and the lateral jitter across the sloping floor add
            // variance the law does not include.
            const double q = disparity_step_mm(m, z, s.fx);
            const double slope = std::hypot(floor_depth(s, u + 1, v) - z, floor_depth(s, u, v + 1) - z);
            sum_quant += q * q / 12 + m.depth_step_mm * m.depth_step_mm / 12 +
                         slope * slope * m.lateral_sigma_px * m.lateral_sigma_px;
        }
    }
    const auto n = static_cast<double>(r.size());
    const double mean = sum_r / n;
    double c0 = 0, c1 = 0;
    for (int v = 0; v < s.height; ++v) {
        for (int u = 0; u + 1 < s.width; ++u) {
            const double a = r[index(s, u, v)] - mean, b = r[index(s, u + 1, v)] - mean;
            c0 += a * a;
            c1 += a * b;
        }
    }
    NoiseStats stats;
    stats.law_mm = std::sqrt(sum_law2 / n);
    stats.measured_mm = std::sqrt(std::max(0.0, sum_r2 / n - mean * mean - sum_quant / n));
    stats.lag1 = c1 / c0;
    return stats;
}

// The axial noise follows each model's law at two distances: z^2 growth for the triangulating sensors, z for ToF.
TEST(Sensors, AxialNoiseFollowsTheModelLaw) {
    for (const Sensor sensor : kConsumers) {
        SCOPED_TRACE(syn::sensor_name(sensor));
        const NoiseStats near = floor_noise(sensor, 1200, 640, 480);
        const NoiseStats far = floor_noise(sensor, 2400, 640, 480);
        std::printf("  %-15s sigma at 1.2 m %.2f mm (law %.2f), at 2.4 m %.2f mm (law %.2f), ratio %.2f\n",
                    syn::sensor_name(sensor), near.measured_mm, near.law_mm, far.measured_mm, far.law_mm,
                    far.measured_mm / near.measured_mm);
        EXPECT_NEAR(near.measured_mm, near.law_mm, 0.1 * near.law_mm);
        EXPECT_NEAR(far.measured_mm, far.law_mm, 0.1 * far.law_mm);
        const double growth = far.measured_mm / near.measured_mm;  // doubling the distance
        if (syn::sensor_model(sensor).time_of_flight) {
            EXPECT_NEAR(growth, 2.0, 0.3) << "proportional to z";
        } else {
            EXPECT_GT(growth, 3.2) << "about z^2";
            EXPECT_LT(growth, 4.6);
        }
    }
}

// Block matching shares its error over the correlation window; the structured-light default's noise is white.
TEST(Sensors, NoiseIsSpatiallyCorrelated) {
    for (const Sensor sensor : kAll) {
        const NoiseStats s = floor_noise(sensor, 1200, 320, 240);
        std::printf("  %-16s lag-1 autocorrelation %.3f\n", syn::sensor_name(sensor), s.lag1);
        if (sensor == Sensor::structured_light) {
            EXPECT_LT(std::abs(s.lag1), 0.05);
        } else {
            EXPECT_GT(s.lag1, 0.4) << syn::sensor_name(sensor);
        }
    }
}

// Pixels within reach of a depth discontinuity of the exact (noise-free structured-light) frame, or of a surface
// it sees at a grazing angle (cosine below 0.2).
std::vector<char> near_edges(const Scene& exact, int reach) {
    const int w = exact.width, h = exact.height;
    std::vector<char> edge(exact.object_id.size(), 0), near(edge.size(), 0);
    for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
            const std::size_t i = index(exact, u, v);
            const float* p = &exact.points[3 * i];
            const float* n = &exact.normals[3 * i];
            const double cosine = -(n[0] * p[0] + n[1] * p[1] + n[2] * p[2]) / std::hypot(p[0], p[1], p[2]);
            if (cosine < 0.2) edge[i] = 1;
            const double z = p[2];
            for (const auto& [nu, nv] : {std::pair{u + 1, v}, std::pair{u, v + 1}}) {
                if (nu >= w || nv >= h) continue;
                const double zn = exact.points[3 * index(exact, nu, nv) + 2];
                if (std::abs(zn - z) > 12 * std::min(z, zn) / exact.fx) edge[index(exact, u, v)] = 1;
            }
        }
    }
    for (int v = 0; v < h; ++v) {
        for (int u = 0; u < w; ++u) {
            if (!edge[index(exact, u, v)]) continue;
            for (int y = std::max(0, v - reach); y <= std::min(h - 1, v + reach); ++y) {
                for (int x = std::max(0, u - reach); x <= std::min(w - 1, u + reach); ++x) near[index(exact, x, y)] = 1;
            }
        }
    }
    return near;
}

// The sensor's own dropouts (shadows, depth edges, grazing angles, the stereo band) concentrate at depth
// discontinuities and grazing surfaces, and ToF flying pixels occur only at discontinuities.
TEST(Sensors, MissingDataConcentratesAtDiscontinuities) {
    SceneOptions base;
    base.width = 320;
    base.height = 240;
    base.seed = 4;
    SceneOptions clean = base;
    clean.noise_mm = 0;
    clean.hole_fraction = 0;
    const Scene exact = generate(clean);
    const std::vector<char> near = near_edges(exact, 6);
    for (const Sensor sensor : kConsumers) {
        SCOPED_TRACE(syn::sensor_name(sensor));
        const syn::SensorModel m = syn::sensor_model(sensor);
        SceneOptions o = base;
        o.sensor = sensor;
        const Scene s = generate(o);
        o.shadows = false;  // the same hole blobs without the sensor's dropouts
        const Scene blobs = generate(o);
        // The D435's left band is as wide as the disparity of the nearest floor.
        const int band = m.stereo_band ? static_cast<int>(std::ceil(s.fx * m.baseline_mm / 1150)) + 2 : 0;
        std::size_t in_zone = 0, zone = 0, dropped = 0, dropped_in_zone = 0, flying = 0, flying_near = 0;
        for (int v = 0; v < s.height; ++v) {
            for (int u = 0; u < s.width; ++u) {
                const std::size_t i = index(s, u, v);
                const bool expected_zone = near[i] || u < band;
                zone += expected_zone;
                if (!valid(blobs, i)) continue;  // a hole blob, not the sensor
                if (!valid(s, i)) {
                    ++dropped;
                    dropped_in_zone += expected_zone;
                    continue;
                }
                in_zone += expected_zone;
                // Far off its own surface: a mixed (flying) pixel; Azure Kinect casts no jittered rays, so the
                // exact frame holds its surface depth.
                const double sigma = law_sigma(m, exact.points[3 * i + 2], s.fx);
                if (m.lateral_sigma_px == 0 &&
                    std::abs(s.points[3 * i + 2] - exact.points[3 * i + 2]) > 8 * sigma + 3) {
                    ++flying;
                    flying_near += near[i];
                }
            }
        }
        const auto pixels = static_cast<double>(s.object_id.size());
        const double share = static_cast<double>(dropped_in_zone) / static_cast<double>(dropped);
        std::printf(
            "  %-15s sensor dropouts %.2f%% of the frame, %.1f%% of them in the %.1f%% near edges%s;"
            " flying pixels %zu (%zu near edges)\n",
            syn::sensor_name(sensor), 100 * static_cast<double>(dropped) / pixels, 100 * share,
            100 * static_cast<double>(zone) / pixels, m.stereo_band ? " or the band" : "", flying, flying_near);
        EXPECT_GT(static_cast<double>(dropped), 0.01 * pixels);
        EXPECT_GT(share, 0.95);
        EXPECT_LT(static_cast<double>(zone), 0.35 * pixels);
        if (m.time_of_flight) {
            EXPECT_GT(flying, 20u);
            EXPECT_GE(static_cast<double>(flying_near), 0.95 * static_cast<double>(flying));
        } else if (m.lateral_sigma_px == 0) {
            EXPECT_EQ(flying, 0u);
        }
    }
}

}  // namespace
