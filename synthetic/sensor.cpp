#include "sensor.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

#include "rng.hpp"

namespace pyrseg::synthetic {

const char* sensor_name(Sensor sensor) {
    switch (sensor) {
        case Sensor::structured_light:
            return "structured-light";
        case Sensor::kinect_v1:
            return "kinect-v1";
        case Sensor::realsense_d435:
            return "realsense-d435";
        case Sensor::azure_kinect:
            return "azure-kinect";
    }
    return nullptr;
}

std::optional<Sensor> sensor_from_name(std::string_view name) {
    for (const Sensor s : {Sensor::structured_light, Sensor::kinect_v1, Sensor::realsense_d435, Sensor::azure_kinect}) {
        if (name == sensor_name(s)) return s;
    }
    return std::nullopt;
}

// Numbers marked "assumed" have no published value; they were chosen to look like the sensor's frames and are
// listed as such in docs/sensors.md.
SensorModel sensor_model(Sensor sensor) {
    SensorModel m;
    m.sensor = sensor;
    switch (sensor) {
        case Sensor::structured_light:
            // The generator's historical PhoXi-like scanner (render.cpp): noise is SceneOptions::noise_mm.
            m.baseline_mm = 150;  // projector beside the camera, as render.cpp's kProjectorBaseline
            m.min_cos = 0.1;      // render.cpp's kMinDecodableCos
            break;
        case Sensor::kinect_v1:
            // Khoshelham & Oude Elberink 2012, "Accuracy and Resolution of Kinect Depth Data for Indoor Mapping
            // Applications" (Sensors 12): IR projector 7.5 cm from the IR camera; disparity stored in 1/8 pixel.
            m.baseline_mm = 75;
            m.disparity_step_px = 1.0 / 8;
            // Nguyen, Izadi & Lovell 2012, "Modeling Kinect Sensor Noise for Improved 3D Reconstruction and
            // Tracking" (3DIMPVT): sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 m; 1.9 mm at 1 m, 41 mm at 5 m, as the
            // quadratic growth (about 1.5 mm at 1 m, 4 cm at 5 m) of Khoshelham & Oude Elberink 2012.
            m.axial.constant_mm = 1.2;
            m.axial.quadratic_per_mm = 0.0019e-3;
            m.axial.quadratic_origin_mm = 400;
            // Konolige & Mihelich 2011, "Technical description of Kinect calibration" (ROS wiki): the depth image
            // is offset by about half a 9-pixel correlation window, so errors are shared over 9 x 9 pixels.
            m.correlation_radius_px = 4;
            m.lateral_sigma_px = 0.8;  // Nguyen, Izadi & Lovell 2012: lateral sigma about 0.8 px below 60 degrees
            m.depth_step_mm = 1;       // OpenNI and the Kinect SDK report whole millimetres (uint16)
            m.min_depth_mm = 800;      // Kinect for Windows SDK 1.8, DepthRange.Default: 800..4000 mm
            m.max_depth_mm = 4000;
            m.min_cos = 0.17;       // assumed: no data beyond about 80 degrees (Nguyen 2012: noise soars past 70)
            m.edge_dropout = 0.35;  // assumed: ragged holes along depth edges
            break;
        case Sensor::realsense_d435:
            // Intel RealSense D400 Series Product Family Datasheet (rev. 2019+): D435 stereo baseline 50 mm,
            // Min-Z about 280 mm at 1280 x 720, range up to about 10 m, and the invalid band along the left edge
            // where the right imager does not see.
            m.baseline_mm = 50;
            m.min_depth_mm = 280;
            m.max_depth_mm = 10000;
            m.stereo_band = true;
            // Grunnet-Jepsen et al., "Subpixel Linearity Improvement for Intel RealSense Depth Camera D400 Series":
            // disparity resolved to 1/32 pixel.
            m.disparity_step_px = 1.0 / 32;
            // Grunnet-Jepsen, Sweetser & Woodfill, "Best-Known-Methods for Tuning Intel RealSense D400 Depth
            // Cameras for Best Performance": depth RMS error = z^2 subpixel / (f b), subpixel RMS about 0.08 px.
            m.axial.disparity_sigma_px = 0.08;
            m.correlation_radius_px = 3;  // assumed: a 7 x 7 matching window (Intel does not publish its size)
            m.lateral_sigma_px = 0.5;     // assumed: edges wander less than Kinect v1's 0.8 px
            m.depth_step_mm = 1;          // default depth unit 0.001 m (uint16), same white paper
            m.min_cos = 0.17;             // assumed: no match beyond about 80 degrees
            m.edge_dropout = 0.3;         // assumed
            break;
        case Sensor::azure_kinect:
            // Microsoft, "Azure Kinect DK depth camera" and "Azure Kinect DK hardware specifications": AMCW
            // time of flight, depth in whole millimetres, NFOV unbinned range 0.5..3.86 m; the illuminator sits
            // beside the lens, so there are no shadows to speak of.
            m.time_of_flight = true;
            m.depth_step_mm = 1;
            m.min_depth_mm = 500;
            m.max_depth_mm = 3860;
            // Tolgyessy, Dekan, Chovanec & Hubinsky 2021, "Evaluation of the Azure Kinect and Its Comparison to
            // Kinect V1 and Kinect V2" (Sensors 21): sigma grows about linearly with distance, 1-2 mm at 1 m.
            m.axial.linear = 0.0015;
            m.correlation_radius_px = 1;  // assumed: the depth engine's spatial filtering
            m.min_cos = 0.17;             // assumed: returns too weak beyond about 80 degrees
            // Azure Kinect DK depth camera page: pixels mixing foreground and background near edges are
            // invalidated, most but not all of them; the fractions are assumed.
            m.edge_dropout = 0.5;
            m.flying_pixel = 0.5;
            break;
    }
    return m;
}

namespace detail {
namespace {

// Neighbours whose depths differ by more than this many pixel footprints (z / f) lie across a depth
// discontinuity: steeper than about 85 degrees, which no surface the sensor keeps (min_cos) reaches.
constexpr double kJumpSlope = 12.0;
constexpr double kMaxJitterSigmas = 4.0;  // jitter is clipped here so that padded tiles bound every ray
constexpr float kNanF = std::numeric_limits<float>::quiet_NaN();

enum Field : std::uint64_t { depth_field = 0, jitter_u_field = 1, jitter_v_field = 2, decision_field = 3 };

Rng row_rng(std::uint64_t seed, Field field, int row) {
    return {seed, static_cast<std::uint64_t>(Stream::sensor_rows) + (static_cast<std::uint64_t>(field) << 16) +
                      static_cast<std::uint64_t>(row)};
}

// Runs f(row) for every row on the option's threads; rows write disjoint outputs, so the order does not matter.
template <typename F>
void for_rows(int rows, int threads, const F& f) {
    std::atomic<int> next{0};
    auto work = [&] {
        for (int r = next++; r < rows; r = next++) f(r);
    };
    threads = std::clamp(threads, 1, std::max(1, std::min(rows, 256)));
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
}

// White gaussian noise box-filtered over (2r + 1)^2 pixels and divided by 2r + 1, so that every pixel keeps unit
// sigma while neighbours share most of their noise, as block matching shares errors over its window. The white
// field has an r-pixel margin, so that the border pixels are filtered like the others.
std::vector<float> correlated_field(std::uint64_t seed, Field field, int width, int height, int r, int threads) {
    const int side = 2 * r + 1;
    const auto w = static_cast<std::size_t>(width);
    std::vector<float> rows(static_cast<std::size_t>(height + 2 * r) * w);
    for_rows(height + 2 * r, threads, [&](int j) {
        Rng rng = row_rng(seed, field, j);
        std::vector<double> white(static_cast<std::size_t>(width + 2 * r));
        for (double& x : white) x = rng.normal();
        float* out = rows.data() + static_cast<std::size_t>(j) * w;
        for (std::size_t u = 0; u < w; ++u) {
            double sum = 0;
            for (int k = 0; k < side; ++k) sum += white[u + static_cast<std::size_t>(k)];
            out[u] = static_cast<float>(sum);
        }
    });
    std::vector<float> result(static_cast<std::size_t>(height) * w);
    for_rows(height, threads, [&](int v) {
        float* out = result.data() + static_cast<std::size_t>(v) * w;
        for (std::size_t u = 0; u < w; ++u) {
            double sum = 0;
            for (int k = 0; k < side; ++k) sum += rows[static_cast<std::size_t>(v + k) * w + u];
            out[u] = static_cast<float>(sum / side);
        }
    });
    return result;
}

double polynomial_sigma(const AxialNoise& a, double z) {
    const double q = z - a.quadratic_origin_mm;
    return a.constant_mm + a.linear * z + a.quadratic_per_mm * q * q;
}

// The depth the sensor reports for exact depth z, given this pixel's unit noise n.
double measure(const SensorModel& m, double f, double z, double n) {
    const double sigma_z = polynomial_sigma(m.axial, z);
    if (m.baseline_mm <= 0) {
        z += sigma_z * n;  // time of flight: the error is in the measured depth itself
    } else {
        // Triangulation measures disparity: the noise and its quantization live there.
        const double fb = f * m.baseline_mm;
        const double sigma_d = std::hypot(m.axial.disparity_sigma_px, sigma_z * fb / (z * z));
        double d = fb / z + sigma_d * n;
        if (m.disparity_step_px > 0) d = std::round(d / m.disparity_step_px) * m.disparity_step_px;
        z = fb / std::max(d, m.disparity_step_px > 0 ? m.disparity_step_px : 1e-6);
    }
    if (m.depth_step_mm > 0) z = std::max(std::round(z / m.depth_step_mm), 1.0) * m.depth_step_mm;
    return std::max(z, 1e-3);
}

}  // namespace

int thread_count(const SceneOptions& options) {
    return options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
}

SensorFields make_sensor_fields(const SensorModel& model, const SceneOptions& options, int width, int height) {
    SensorFields fields;
    const int r = static_cast<int>(model.correlation_radius_px);
    const int threads = thread_count(options);
    fields.depth = correlated_field(noise_seed_of(options), depth_field, width, height, r, threads);
    if (model.lateral_sigma_px > 0) {
        const double sigma = model.lateral_sigma_px, limit = kMaxJitterSigmas;
        for (const Field field : {jitter_u_field, jitter_v_field}) {
            std::vector<float> jitter = correlated_field(noise_seed_of(options), field, width, height, r, threads);
            for (float& x : jitter) x = static_cast<float>(sigma * std::clamp(static_cast<double>(x), -limit, limit));
            (field == jitter_u_field ? fields.jitter_u : fields.jitter_v) = std::move(jitter);
        }
        fields.max_jitter = sigma * limit;
    }
    return fields;
}

void apply_sensor(const SensorModel& model, const SensorFields& fields, const SceneOptions& options, Scene& scene) {
    const int width = scene.width, height = scene.height;
    const auto w = static_cast<std::size_t>(width);
    const double f = scene.fx;
    // Neighbours are judged on the exact depths, before any pixel is overwritten.
    std::vector<float> exact(w * static_cast<std::size_t>(height));
    for (std::size_t i = 0; i < exact.size(); ++i) exact[i] = scene.points[3 * i + 2];
    const bool dropouts = options.shadows && options.hole_fraction > 0;

    for_rows(height, thread_count(options), [&](int v) {
        Rng rng = row_rng(noise_seed_of(options), decision_field, v);
        for (int u = 0; u < width; ++u) {
            // Every pixel draws the same numbers, so that one pixel's fate never shifts another's.
            const double drop = rng.uniform(), fly = rng.uniform(), mix = rng.uniform();
            const std::size_t at = static_cast<std::size_t>(v) * w + static_cast<std::size_t>(u);
            double z = exact[at];
            if (std::isnan(z)) continue;
            bool edge = false;
            double other = z, jump = 0;
            const int du[4] = {-1, 1, 0, 0}, dv[4] = {0, 0, -1, 1};
            for (int k = 0; k < 4; ++k) {
                const int nu = u + du[k], nv = v + dv[k];
                if (nu < 0 || nu >= width || nv < 0 || nv >= height) continue;
                const double zn = exact[static_cast<std::size_t>(nv) * w + static_cast<std::size_t>(nu)];
                if (std::isnan(zn)) {
                    edge = true;  // next to a shadow or another gap of the geometry
                    continue;
                }
                const double step = std::abs(zn - z);
                if (step > kJumpSlope * std::min(z, zn) / f) {
                    edge = true;
                    if (step > jump) jump = step, other = zn;
                }
            }
            const bool out_of_range = z < model.min_depth_mm || (model.max_depth_mm > 0 && z > model.max_depth_mm);
            float* point = scene.points.data() + 3 * at;
            if (dropouts && (out_of_range || (edge && drop < model.edge_dropout))) {
                point[0] = point[1] = point[2] = kNanF;
                std::fill_n(scene.normals.data() + 3 * at, 3, kNanF);
                scene.object_id[at] = kNoDataId;
                continue;
            }
            // A time-of-flight pixel that sees both sides of an edge mixes their returns into a depth between.
            if (model.time_of_flight && jump > 0 && fly < model.flying_pixel) z += mix * (other - z);
            z = measure(model, f, z, fields.depth[at]);
            // Depth cameras report each depth on the pixel's own ray, wherever the matched pattern came from.
            point[0] = static_cast<float>((u - scene.cx) * z / scene.fx);
            point[1] = static_cast<float>((v - scene.cy) * z / scene.fy);
            point[2] = static_cast<float>(z);
        }
    });
}

}  // namespace detail
}  // namespace pyrseg::synthetic
