#include "render.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>

#include "rng.hpp"
#include "sensor.hpp"

namespace pyrseg::synthetic::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kNanF = std::numeric_limits<float>::quiet_NaN();
constexpr double kPi = 3.141592653589793;

constexpr double kProjectorBaseline = 150.0;  // projector to camera, along camera x (mm)
// Below this cosine between surface normal and camera or projector ray, the pattern is too faint to decode.
constexpr double kMinDecodableCos = 0.1;
constexpr int kTileWidth = 64;
constexpr int kBandHeight = 16;
constexpr std::size_t kShadowGrid = 64;  // cells per side of the projector-space grid of occluders

// A camera-space solid with the conservative bounds that let most rays skip it.
struct Bounded {
    double zmin = 0;                                      // no point of the solid is nearer (camera depth)
    double u0 = -kInf, u1 = kInf, v0 = -kInf, v1 = kInf;  // pixel rectangle holding its image
    double a0 = -kInf, a1 = kInf, b0 = -kInf, b1 = kInf;  // the same for the projector, in normalized coordinates
};

Bounded bounds_of(const Solid& s, double f, double cx, double cy, double baseline) {
    Bounded b;
    if (s.shape == Shape::plane) return b;
    Vec3 corners[8];
    bounding_corners(s, corners);
    b.zmin = kInf;
    double u0 = kInf, u1 = -kInf, v0 = kInf, v1 = -kInf, a0 = kInf, a1 = -kInf;
    for (const Vec3& c : corners) {
        b.zmin = std::min(b.zmin, c.z);
        if (c.z <= 1.0) continue;
        u0 = std::min(u0, c.x / c.z), u1 = std::max(u1, c.x / c.z);
        v0 = std::min(v0, c.y / c.z), v1 = std::max(v1, c.y / c.z);
        const double a = (c.x - baseline) / c.z;
        a0 = std::min(a0, a), a1 = std::max(a1, a);
    }
    if (b.zmin <= 1.0) {  // reaches behind the image plane: no useful rectangle
        b.zmin = std::min(b.zmin, 0.0);
        return b;
    }
    b.u0 = u0 * f + cx - 1, b.u1 = u1 * f + cx + 1, b.v0 = v0 * f + cy - 1, b.v1 = v1 * f + cy + 1;
    const double pad = 1e-9;
    b.a0 = a0 - pad, b.a1 = a1 + pad, b.b0 = v0 - pad, b.b1 = v1 + pad;
    return b;
}

// Occluder candidates binned by where they appear to the projector.
class ShadowGrid {
public:
    ShadowGrid(const std::vector<Solid>& solids, const std::vector<Bounded>& bounds) {
        a0_ = b0_ = kInf;
        double a1 = -kInf, b1 = -kInf;
        for (std::size_t i = 0; i < solids.size(); ++i) {
            if (solids[i].shape == Shape::plane) continue;
            a0_ = std::min(a0_, bounds[i].a0), a1 = std::max(a1, bounds[i].a1);
            b0_ = std::min(b0_, bounds[i].b0), b1 = std::max(b1, bounds[i].b1);
        }
        // Rays beyond twice the field of view never reach a pixel, so an unbounded occluder is clipped there.
        a0_ = std::max(a0_, -2.0), b0_ = std::max(b0_, -2.0), a1 = std::min(a1, 2.0), b1 = std::min(b1, 2.0);
        if (!(a0_ < a1) || !(b0_ < b1)) return;
        sa_ = static_cast<double>(kShadowGrid) / (a1 - a0_), sb_ = static_cast<double>(kShadowGrid) / (b1 - b0_);
        cells_.resize(kShadowGrid * kShadowGrid);
        for (std::size_t i = 0; i < solids.size(); ++i) {
            if (solids[i].shape == Shape::plane) continue;
            const std::size_t i0 = cell(bounds[i].a0, a0_, sa_), i1 = cell(bounds[i].a1, a0_, sa_);
            const std::size_t j0 = cell(bounds[i].b0, b0_, sb_), j1 = cell(bounds[i].b1, b0_, sb_);
            for (std::size_t j = j0; j <= j1; ++j) {
                for (std::size_t k = i0; k <= i1; ++k) cells_[j * kShadowGrid + k].push_back(i);
            }
        }
    }

    // Candidates for the projector ray of normalized direction (a, b); null when there are none.
    [[nodiscard]] const std::vector<std::size_t>* at(double a, double b) const {
        if (cells_.empty()) return nullptr;
        const double fa = (a - a0_) * sa_, fb = (b - b0_) * sb_;
        const auto cells = static_cast<double>(kShadowGrid);
        if (!(fa >= 0 && fa < cells && fb >= 0 && fb < cells)) return nullptr;
        return &cells_[static_cast<std::size_t>(fb) * kShadowGrid + static_cast<std::size_t>(fa)];
    }

private:
    static std::size_t cell(double x, double origin, double scale) {
        return static_cast<std::size_t>(std::clamp((x - origin) * scale, 0.0, static_cast<double>(kShadowGrid - 1)));
    }

    double a0_, b0_, sa_ = 0, sb_ = 0;
    std::vector<std::vector<std::size_t>> cells_;
};

// A missing-data blob: a wobbly ellipse in normalized image coordinates ((u - cx) / f, (v - cy) / f).
struct Blob {
    double x, y, ax, ay, cos_r, sin_r, w1, p1, w2, p2;

    [[nodiscard]] double reach() const { return std::max(ax, ay) * (1 + w1 + w2); }
    [[nodiscard]] bool contains(double s, double t) const {
        const double dx = s - x, dy = t - y;
        const double lx = (dx * cos_r + dy * sin_r) / ax, ly = (dy * cos_r - dx * sin_r) / ay;
        const double angle = std::atan2(ly, lx);
        const double limit = 1 + w1 * std::sin(3 * angle + p1) + w2 * std::sin(5 * angle + p2);
        return lx * lx + ly * ly < limit * limit;
    }
};

std::vector<Blob> make_blobs(const SceneOptions& options, double half_w, double half_h) {
    std::vector<Blob> blobs;
    if (options.hole_fraction <= 0) return blobs;
    Rng rng(options.seed, Stream::holes);
    // Blobs fall independently and overlap; this total area covers about hole_fraction of the image.
    const double covered = std::min(options.hole_fraction, 0.999);
    double remaining = -std::log(1 - covered) * (4 * half_w * half_h);
    while (remaining > 0 && blobs.size() < 20000) {
        Blob b{};
        const double r = std::exp(rng.uniform(std::log(0.006), std::log(0.045)));
        const double stretch = std::exp(rng.uniform(-0.45, 0.45));
        const double rotation = rng.uniform(0, kPi);
        b.x = rng.uniform(-half_w, half_w), b.y = rng.uniform(-half_h, half_h);
        b.ax = r * stretch, b.ay = r / stretch;
        b.cos_r = std::cos(rotation), b.sin_r = std::sin(rotation);
        b.w1 = rng.uniform(0, 0.25), b.p1 = rng.uniform(0, 2 * kPi);
        b.w2 = rng.uniform(0, 0.12), b.p2 = rng.uniform(0, 2 * kPi);
        double area = kPi * b.ax * b.ay * (1 + 0.5 * (b.w1 * b.w1 + b.w2 * b.w2));
        if (area > remaining) {  // the last blob shrinks to hit the target
            const double shrink = std::sqrt(remaining / area);
            b.ax *= shrink, b.ay *= shrink;
            area = remaining;
        }
        remaining -= area;
        blobs.push_back(b);
    }
    return blobs;
}

struct Entry {
    double zmin;
    std::size_t index;
};

class Renderer {
public:
    // fields is null for the structured-light default, whose path stays as it always was.
    Renderer(const std::vector<Solid>& solids, const SceneOptions& options, Scene& scene, const SensorModel& model,
             const SensorFields* fields)
        : solids_(solids),
          options_(options),
          scene_(scene),
          f_(scene.fx),
          dropouts_(options.shadows && options.hole_fraction > 0),
          model_(model),
          fields_(fields),
          baseline_(fields != nullptr ? model.baseline_mm : kProjectorBaseline),
          min_cos_(fields != nullptr ? model.min_cos : kMinDecodableCos),
          pad_(fields != nullptr ? fields->max_jitter : 0.0) {
        bounds_.reserve(solids.size());
        for (const Solid& s : solids) bounds_.push_back(bounds_of(s, f_, scene.cx, scene.cy, baseline_));
        if (dropouts_ && baseline_ > 0) shadows_.emplace(solids, bounds_);
    }

    void band(int v_begin, std::vector<std::vector<Entry>>& tiles) const {
        const int w = scene_.width;
        const int v_end = std::min(v_begin + kBandHeight, scene_.height);
        const int tile_count = (w + kTileWidth - 1) / kTileWidth;
        tiles.resize(static_cast<std::size_t>(tile_count));
        for (int t = 0; t < tile_count; ++t) {
            list_tile(t * kTileWidth, std::min(w, (t + 1) * kTileWidth), v_begin, v_end,
                      tiles[static_cast<std::size_t>(t)]);
        }
        for (int v = v_begin; v < v_end; ++v) {
            Rng rng(noise_seed_of(options_),
                    static_cast<std::uint64_t>(Stream::noise_rows) + static_cast<std::uint64_t>(v));
            for (int u = 0; u < w; ++u) {
                const std::vector<Entry>& list = tiles[static_cast<std::size_t>(u / kTileWidth)];
                if (fields_ != nullptr) {
                    sensor_pixel(u, v, list);
                } else {
                    pixel(u, v, list, rng);
                }
            }
        }
    }

private:
    [[nodiscard]] Vec3 ray(double u, double v) const { return {(u - scene_.cx) / f_, (v - scene_.cy) / f_, 1.0}; }

    // The solids that may be seen in the tile, nearest first, from rays jittered up to pad_ pixels.
    void list_tile(int u0, int u1, int v0, int v1, std::vector<Entry>& list) const {
        list.clear();
        for (std::size_t i = 0; i < solids_.size(); ++i) {
            const Solid& s = solids_[i];
            const Bounded& b = bounds_[i];
            if (s.shape == Shape::plane) {
                // Depth along a plane is monotonic across the tile, so its corners bound it.
                double zmin = kInf;
                const Vec3 n = s.frame.axis[2];
                for (int c = 0; c < 4; ++c) {
                    const Vec3 d = ray((c & 1) ? u1 - 1 + pad_ : u0 - pad_, (c & 2) ? v1 - 1 + pad_ : v0 - pad_);
                    const double nd = dot(n, d);
                    zmin = nd < 0 ? std::min(zmin, dot(n, s.center) / nd) : 0.0;
                    if (nd >= 0) break;
                }
                list.push_back({zmin * (1 - 1e-9) - 1e-9, i});
                continue;
            }
            if (b.u1 < u0 - pad_ || b.u0 > u1 - 1 + pad_ || b.v1 < v0 - pad_ || b.v0 > v1 - 1 + pad_) continue;
            list.push_back({b.zmin, i});
        }
        std::sort(list.begin(), list.end(), [](const Entry& a, const Entry& b) {
            return a.zmin < b.zmin || (a.zmin == b.zmin && a.index < b.index);
        });
    }

    // Whether the projector cannot light p (normal n) on solid k, or lights it too obliquely.
    [[nodiscard]] bool unlit(Vec3 p, Vec3 n, std::size_t k) const {
        const Vec3 projector{baseline_, 0, 0};
        const Vec3 q = p - projector;
        if (dot(n, q) > -min_cos_ * norm(q)) return true;
        const std::vector<std::size_t>* candidates = shadows_->at(q.x / q.z, q.y / q.z);
        if (candidates == nullptr) return false;
        Hit hit;
        for (const std::size_t i : *candidates) {
            if (i == k || bounds_[i].zmin >= p.z) continue;
            if (ray_entry(solids_[i], projector, q, 1 - 1e-9, hit)) return true;
        }
        return false;
    }

    void pixel(int u, int v, const std::vector<Entry>& list, Rng& rng) const {
        const Vec3 d = ray(u, v);
        std::size_t k = 0;
        Hit nearest;
        const double best = cast(d, list, nearest, k);
        const std::size_t at =
            static_cast<std::size_t>(v) * static_cast<std::size_t>(scene_.width) + static_cast<std::size_t>(u);
        float* point = scene_.points.data() + 3 * at;
        float* normal = scene_.normals.data() + 3 * at;
        bool valid = best < kInf;
        const double length = norm(d);
        if (valid && dropouts_) {
            valid = dot(nearest.normal, d) <= -kMinDecodableCos * length && !unlit(d * best, nearest.normal, k);
        }
        if (!valid) {
            point[0] = point[1] = point[2] = kNanF;
            normal[0] = normal[1] = normal[2] = kNanF;
            scene_.object_id[at] = kNoDataId;
            return;
        }
        const double t = options_.noise_mm > 0 ? best + options_.noise_mm * rng.normal() / length : best;
        const Vec3 p = d * t;
        point[0] = static_cast<float>(p.x), point[1] = static_cast<float>(p.y), point[2] = static_cast<float>(p.z);
        normal[0] = static_cast<float>(nearest.normal.x), normal[1] = static_cast<float>(nearest.normal.y);
        normal[2] = static_cast<float>(nearest.normal.z);
        scene_.object_id[at] = solids_[k].id;
    }

    // The nearest entry of the ray d (kInf when it hits nothing).
    double cast(Vec3 d, const std::vector<Entry>& list, Hit& nearest, std::size_t& k) const {
        double best = kInf;
        Hit hit;
        for (const Entry& e : list) {
            if (e.zmin >= best) break;
            if (ray_entry(solids_[e.index], {0, 0, 0}, d, best, hit)) {
                best = hit.t;
                nearest = hit;
                k = e.index;
            }
        }
        return best;
    }

    // A consumer sensor's pixel: the exact hit of its jittered ray, or NaN where the sensor's geometry gives no
    // data; apply_sensor() turns it into a measurement afterwards.
    void sensor_pixel(int u, int v, const std::vector<Entry>& list) const {
        const std::size_t at =
            static_cast<std::size_t>(v) * static_cast<std::size_t>(scene_.width) + static_cast<std::size_t>(u);
        const Vec3 nominal = ray(u, v);
        Vec3 d = nominal;
        if (!fields_->jitter_u.empty()) d = ray(u + fields_->jitter_u[at], v + fields_->jitter_v[at]);
        Hit nearest;
        std::size_t k = 0;
        double best = cast(d, list, nearest, k);
        // The point is reported on the nominal ray, so its surface must face that ray too: where the jittered ray
        // slipped past a silhouette onto a side the nominal ray sees edge-on, the nominal ray decides.
        if (!(best < kInf && dot(nearest.normal, nominal) < -1e-3 * norm(nominal)) && pad_ > 0) {
            d = nominal;
            best = cast(d, list, nearest, k);
        }
        float* point = scene_.points.data() + 3 * at;
        float* normal = scene_.normals.data() + 3 * at;
        bool valid = best < kInf;
        const Vec3 p = d * best;
        if (valid && dropouts_) {
            valid = dot(nearest.normal, d) <= -min_cos_ * norm(d) && (baseline_ <= 0 || !unlit(p, nearest.normal, k));
            if (valid && model_.stereo_band) {
                // The second imager, baseline_ along x with the same intrinsics, must see the point to match it.
                const double u2 = f_ * (p.x - baseline_) / p.z + scene_.cx;
                valid = u2 >= -0.5 && u2 <= scene_.width - 0.5;
            }
        }
        if (!valid) {
            point[0] = point[1] = point[2] = kNanF;
            normal[0] = normal[1] = normal[2] = kNanF;
            scene_.object_id[at] = kNoDataId;
            return;
        }
        point[0] = static_cast<float>(p.x), point[1] = static_cast<float>(p.y), point[2] = static_cast<float>(p.z);
        normal[0] = static_cast<float>(nearest.normal.x), normal[1] = static_cast<float>(nearest.normal.y);
        normal[2] = static_cast<float>(nearest.normal.z);
        scene_.object_id[at] = solids_[k].id;
    }

    const std::vector<Solid>& solids_;
    const SceneOptions& options_;
    Scene& scene_;
    double f_;
    bool dropouts_;
    const SensorModel& model_;
    const SensorFields* fields_;
    double baseline_;  // projector or second imager along x (mm); 0: none
    double min_cos_;   // grazing-angle limit for the camera and the projector
    double pad_;       // how far (pixels) a jittered ray may stray from its pixel
    std::vector<Bounded> bounds_;
    std::optional<ShadowGrid> shadows_;
};

void punch_blobs(const std::vector<Blob>& blobs, Scene& scene) {
    const double f = scene.fx;
    for (const Blob& b : blobs) {
        const double reach = b.reach();
        const int u0 = static_cast<int>(std::max(0.0, std::floor((b.x - reach) * f + scene.cx)));
        const int u1 = static_cast<int>(std::min(scene.width - 1.0, std::ceil((b.x + reach) * f + scene.cx)));
        const int v0 = static_cast<int>(std::max(0.0, std::floor((b.y - reach) * f + scene.cy)));
        const int v1 = static_cast<int>(std::min(scene.height - 1.0, std::ceil((b.y + reach) * f + scene.cy)));
        for (int v = v0; v <= v1; ++v) {
            for (int u = u0; u <= u1; ++u) {
                if (!b.contains((u - scene.cx) / f, (v - scene.cy) / f)) continue;
                const std::size_t at =
                    static_cast<std::size_t>(v) * static_cast<std::size_t>(scene.width) + static_cast<std::size_t>(u);
                std::fill_n(scene.points.begin() + static_cast<std::ptrdiff_t>(3 * at), 3, kNanF);
                std::fill_n(scene.normals.begin() + static_cast<std::ptrdiff_t>(3 * at), 3, kNanF);
                scene.object_id[at] = kNoDataId;
            }
        }
    }
}

}  // namespace

double focal_length(int width, int height) {
    const double tan_half = std::tan(30.0 * kPi / 180.0);
    return std::max(static_cast<double>(width), height * 4.0 / 3.0) / (2.0 * tan_half);
}

void render(const std::vector<Solid>& solids, const SceneOptions& options, Scene& scene) {
    const std::size_t pixels = static_cast<std::size_t>(scene.width) * static_cast<std::size_t>(scene.height);
    scene.points.resize(3 * pixels);
    scene.normals.resize(3 * pixels);
    scene.object_id.resize(pixels);

    const SensorModel model = sensor_model(options.sensor);
    const bool consumer = options.sensor != Sensor::structured_light;
    const SensorFields fields =
        consumer ? make_sensor_fields(model, options, scene.width, scene.height) : SensorFields{};
    const Renderer renderer(solids, options, scene, model, consumer ? &fields : nullptr);
    const int bands = (scene.height + kBandHeight - 1) / kBandHeight;
    std::atomic<int> next{0};
    auto work = [&] {
        std::vector<std::vector<Entry>> tiles;
        for (int b = next++; b < bands; b = next++) renderer.band(b * kBandHeight, tiles);
    };
    int threads = options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
    threads = std::clamp(threads, 1, std::min(bands, 256));
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    if (consumer) apply_sensor(model, fields, options, scene);

    const double half_w = scene.width / (2 * scene.fx), half_h = scene.height / (2 * scene.fy);
    punch_blobs(make_blobs(options, half_w, half_h), scene);
}

}  // namespace pyrseg::synthetic::detail
