#include "layout.hpp"

#include <algorithm>
#include <cmath>

#include "gjk.hpp"
#include "rng.hpp"

namespace pyrseg::synthetic::detail {
namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kDeg = kPi / 180.0;

// Roughly a PhoXi M over a small-load-carrier bin: the camera 1.2 m from the floor point it looks at.
constexpr double kCameraDistance = 1200.0;
constexpr double kBinHalfX = 365.0;  // inner half sizes
constexpr double kBinHalfY = 265.0;
constexpr double kWallThickness = 15.0;
constexpr double kBinHeight = 220.0;  // floor to rim
constexpr double kBottomThickness = 15.0;

// Objects rest this far above what carries them and stop this close to what they slide against: far below the
// noise, yet wide enough for the overlap test to settle quickly.
constexpr double kClearance = 0.01;
// Sliding probes in steps shorter than the thinnest wall and object, so that nothing is skipped over.
constexpr double kProbeStep = 4.0;
constexpr double kSeparation = 15.0;             // gap kept between objects (and walls) when they must not touch
constexpr double kWallRise = 1000.0;             // see Packer::add_wall
constexpr double kMaxPileTop = kBinHeight + 60;  // how high above the floor a pile may reach

const Vec3 kWorldUp{0, 0, 1};

enum class Kind { upright_box, leaning_box, standing_cylinder, lying_cylinder, sphere };

Kind random_kind(Rng& rng) {
    const double r = rng.uniform();
    if (r < 0.32) return Kind::upright_box;
    if (r < 0.47) return Kind::leaning_box;
    if (r < 0.64) return Kind::standing_cylinder;
    if (r < 0.84) return Kind::lying_cylinder;
    return Kind::sphere;
}

Vec3 horizontal(double angle) {
    return {std::cos(angle), std::sin(angle), 0};
}

// An object of the given kind at the origin; lean is the horizontal direction a leaning box tips towards.
Solid make_object(Kind kind, Rng& rng, Vec3 lean, bool steep) {
    Solid s;
    const double yaw = rng.uniform(0, 2 * kPi);
    switch (kind) {
        case Kind::upright_box:
        case Kind::leaning_box: {
            s.shape = Shape::box;
            const double a = rng.uniform(50, 170), b = rng.uniform(40, std::min(a, 130.0));
            s.half = {a / 2, b / 2, rng.uniform(30, 110) / 2};
            if (kind == Kind::upright_box) {
                s.frame = frame_from_z(kWorldUp, horizontal(yaw));
                break;
            }
            // Tipped about a bottom edge towards lean, as a box leaning on a wall or on a neighbour rests.
            if (rng.chance(0.5)) std::swap(s.half.x, s.half.y);
            const Vec3 axis = cross(kWorldUp, lean);
            const double tilt = (steep ? rng.uniform(15, 40) : rng.uniform(8, 20)) * kDeg;
            s.frame.axis[0] = rotated(lean, axis, tilt);
            s.frame.axis[1] = axis;
            s.frame.axis[2] = rotated(kWorldUp, axis, tilt);
            break;
        }
        case Kind::standing_cylinder:
            s.shape = Shape::cylinder;
            s.half.x = s.half.y = rng.uniform(20, 50);
            s.half.z = rng.uniform(30, 90);
            s.frame = frame_from_z(kWorldUp, horizontal(yaw));
            break;
        case Kind::lying_cylinder:
            s.shape = Shape::cylinder;
            s.half.x = s.half.y = rng.uniform(18, 45);
            s.half.z = rng.uniform(40, 100);
            s.frame = frame_from_z(horizontal(yaw), kWorldUp);
            break;
        case Kind::sphere:
            s.shape = Shape::sphere;
            s.half.x = s.half.y = s.half.z = rng.uniform(25, 60);
            break;
    }
    return s;
}

class Packer {
public:
    Packer(const SceneOptions& options, Rng& rng, Vec3 region_center, Frame region_frame, double base_z)
        : options_(options), rng_(rng), center_(region_center), frame_(region_frame), base_z_(base_z) {}

    // Walls block as if they rose far above the rim, so that nothing dropped from above comes to rest balanced on
    // a rim or hanging out of the bin.
    void add_wall(const Solid& wall) {
        Solid tall = wall;
        tall.half.z += kWallRise / 2;
        tall.center = tall.center + kWorldUp * (kWallRise / 2);
        blockers_.push_back(tall);
        ++walls_;
    }

    // Places one object; false when it does not fit.
    bool place(std::vector<Solid>& objects) {
        const bool ok = options_.touching ? place_touching(objects) : place_apart();
        if (ok) objects.push_back(blockers_.back());
        return ok;
    }

private:
    [[nodiscard]] Vec3 random_point(double inset) {
        const double hx = std::max(kBinHalfX - inset, 0.0), hy = std::max(kBinHalfY - inset, 0.0);
        return center_ + frame_.to_parent({rng_.uniform(-hx, hx), rng_.uniform(-hy, hy), 0});
    }

    // Whether p lies over the floor of the bin (or of the region objects are put in when there is none).
    [[nodiscard]] bool inside(Vec3 p) const {
        const Vec3 l = frame_.to_local(p - center_);
        return std::abs(l.x) < kBinHalfX && std::abs(l.y) < kBinHalfY;
    }

    void rest(Solid& s) const { s.center.z += base_z_ + kClearance - support(s, -kWorldUp).z; }

    [[nodiscard]] bool free(const Solid& s, double margin = 0) const {
        return std::none_of(blockers_.begin(), blockers_.end(), [&](const Solid& b) { return overlaps(s, b, margin); });
    }

    // Moves s (free where it is) along the unit dir by up to distance, stopping at the first contact. Returns
    // whether it touched something.
    [[nodiscard]] bool slide(Solid& s, Vec3 dir, double distance) const {
        const Vec3 start = s.center;
        double lo = 0;
        for (double reach = kProbeStep;; reach += kProbeStep) {
            const double hi = std::min(reach, distance);
            if (!free(moved(s, dir * hi))) {
                double a = lo, b = hi;
                while (b - a > kClearance / 2) {
                    const double mid = 0.5 * (a + b);
                    (free(moved(s, dir * mid)) ? a : b) = mid;
                }
                s.center = start + dir * a;
                return true;
            }
            lo = hi;
            if (hi >= distance) break;
        }
        s.center = start + dir * distance;
        return false;
    }

    bool commit(const Solid& s) {
        blockers_.push_back(s);
        return true;
    }

    bool place_apart() {
        const Kind kind = random_kind(rng_);
        const Solid shape = make_object(kind, rng_, horizontal(rng_.uniform(0, 2 * kPi)), false);
        for (int attempt = 0; attempt < 60; ++attempt) {
            Solid s = moved(shape, random_point(40));
            rest(s);
            if (free(s, kSeparation)) return commit(s);
        }
        return false;
    }

    bool place_touching(const std::vector<Solid>& objects) {
        std::vector<std::size_t> twins;  // upright boxes and standing cylinders, whose copies pack flush
        for (std::size_t i = 0; i < objects.size(); ++i) {
            const Solid& o = objects[i];
            const bool upright = o.frame.axis[2].z > 0.999999 && o.shape != Shape::sphere;
            if (upright && support(o, -kWorldUp).z < base_z_ + 2 * kClearance) twins.push_back(i);
        }
        // The first chance is always taken, so that every touching scene has a flush pair: two faces meeting
        // without a depth step, the hardest case for depth-edge segmentation.
        if (!twins.empty() && (!twin_placed_ || rng_.chance(0.3))) {
            const std::size_t pick = twins[static_cast<std::size_t>(rng_.below(static_cast<int>(twins.size())))];
            if (place_twin(objects[pick])) return twin_placed_ = true;
        }
        if (objects.size() >= 4 && rng_.chance(0.12))
            return drop(make_object(random_kind(rng_), rng_, {1, 0, 0}, false));

        const Kind kind = random_kind(rng_);
        const bool to_wall = walls_ > 0 && (objects.empty() || rng_.chance(0.4));
        const std::size_t wall = static_cast<std::size_t>(rng_.below(std::max(walls_, 1)));
        // On a plain floor some objects stay where they fall, so that not everything ends up in one heap.
        const bool alone = objects.empty() || (walls_ == 0 && rng_.chance(0.3));
        const std::size_t target = alone ? 0 : static_cast<std::size_t>(rng_.below(static_cast<int>(objects.size())));
        for (int attempt = 0; attempt < 40; ++attempt) {
            const Vec3 start = random_point(30);
            Vec3 dir;
            double distance;
            if (to_wall) {
                // Walls are stored with their inward normal as local x.
                const Solid& w = blockers_[wall];
                dir = -w.frame.axis[0];
                distance = dot(w.center - start, dir) + 1.0;
            } else if (!alone) {
                Vec3 towards = objects[target].center - start;
                towards.z = 0;
                distance = norm(towards);
                if (distance < 1) continue;
                dir = towards * (1.0 / distance);
            } else {
                dir = horizontal(rng_.uniform(0, 2 * kPi));
                distance = 0;
            }
            Solid s = moved(make_object(kind, rng_, dir, true), start);
            rest(s);
            if (!free(s)) continue;
            if (distance > 0) (void)slide(s, dir, distance);
            return commit(s);
        }
        return drop(make_object(kind == Kind::leaning_box ? Kind::upright_box : kind, rng_, {1, 0, 0}, false));
    }

    // A copy of an upright object pushed against one of its sides, as identical parts pack in a bin.
    bool place_twin(const Solid& original) {
        for (int attempt = 0; attempt < 8; ++attempt) {
            Vec3 dir, offset;
            if (original.shape == Shape::box) {
                const int face = rng_.below(4);
                dir = original.frame.axis[face % 2] * (face < 2 ? 1.0 : -1.0);
                const Vec3 along = original.frame.axis[1 - face % 2];
                const double half_along = face % 2 == 0 ? original.half.y : original.half.x;
                offset = along * (rng_.uniform(-0.6, 0.6) * half_along);
            } else {
                dir = horizontal(rng_.uniform(0, 2 * kPi));
            }
            const double distance = 2 * bounding_radius(original) + 2 * kProbeStep;
            Solid s = moved(original, dir * distance + offset);
            if (!inside(s.center) || !free(s)) continue;
            if (!slide(s, -dir, distance)) continue;
            return commit(s);
        }
        return false;
    }

    // Dropped from above onto whatever is below, for a second layer; a full bin takes no more.
    bool drop(Solid shape) {
        for (int attempt = 0; attempt < 20; ++attempt) {
            Solid s = moved(shape, random_point(40));
            rest(s);
            const double rise = 600;
            Solid high = moved(s, kWorldUp * rise);
            if (!free(high)) continue;
            (void)slide(high, -kWorldUp, rise);
            if (support(high, kWorldUp).z > kMaxPileTop) continue;
            return commit(high);
        }
        return false;
    }

    const SceneOptions& options_;
    Rng& rng_;
    Vec3 center_;
    Frame frame_;
    double base_z_;
    std::vector<Solid> blockers_;  // walls first, then the objects
    int walls_ = 0;
    bool twin_placed_ = false;
};

}  // namespace

Layout make_layout(const SceneOptions& options) {
    Rng rng(options.seed, Stream::layout);
    Layout layout;

    const double tilt = rng.uniform(2, 6) * kDeg;
    const Vec3 forward = rotated(-kWorldUp, horizontal(rng.uniform(0, 2 * kPi)), tilt);
    layout.camera = frame_from_z(forward, {1, 0, 0});
    layout.camera_position = forward * -kCameraDistance;

    Solid floor;
    floor.shape = Shape::plane;
    floor.id = kFloorId;
    layout.solids.push_back(floor);

    const Vec3 bin_center{rng.uniform(-40, 40), rng.uniform(-30, 30), 0};
    const Frame bin_frame = frame_from_z(kWorldUp, horizontal(rng.uniform(-8, 8) * kDeg));
    const double base_z = options.bin ? kBottomThickness : 0.0;
    Packer packer(options, rng, bin_center, bin_frame, base_z);

    if (options.bin) {
        Solid bottom;
        bottom.shape = Shape::box;
        bottom.id = kBinBottomId;
        bottom.center = bin_center + kWorldUp * (kBottomThickness / 2);
        bottom.frame = bin_frame;
        bottom.half = {kBinHalfX, kBinHalfY, kBottomThickness / 2};
        layout.solids.push_back(bottom);
        // Local x of each wall is its inward normal; the x walls run past the corners to close them.
        const double along_x = kBinHalfX + kWallThickness / 2, along_y = kBinHalfY + kWallThickness / 2;
        const struct {
            Vec3 offset, inward;
            double length = 0;
        } walls[4] = {{{along_x, 0, 0}, {-1, 0, 0}, kBinHalfY + kWallThickness},
                      {{0, along_y, 0}, {0, -1, 0}, kBinHalfX},
                      {{-along_x, 0, 0}, {1, 0, 0}, kBinHalfY + kWallThickness},
                      {{0, -along_y, 0}, {0, 1, 0}, kBinHalfX}};
        for (int i = 0; i < 4; ++i) {
            Solid wall;
            wall.shape = Shape::box;
            wall.id = kFirstWallId + static_cast<std::uint32_t>(i);
            wall.center = bin_center + bin_frame.to_parent(walls[i].offset) + kWorldUp * (kBinHeight / 2);
            wall.frame.axis[0] = bin_frame.to_parent(walls[i].inward);
            wall.frame.axis[2] = kWorldUp;
            wall.frame.axis[1] = cross(kWorldUp, wall.frame.axis[0]);
            wall.half = {kWallThickness / 2, walls[i].length, kBinHeight / 2};
            layout.solids.push_back(wall);
            packer.add_wall(wall);
        }
    }

    std::vector<Solid> objects;
    int misses = 0;  // in a row: once this many objects in a row do not fit, the bin is full
    for (int i = 0; i < options.object_count && misses < 25; ++i) {
        if (!packer.place(objects)) {
            ++misses;
            continue;
        }
        misses = 0;
        objects.back().id = kFirstObjectId + static_cast<std::uint32_t>(objects.size() - 1);
    }
    layout.objects_placed = static_cast<int>(objects.size());
    layout.solids.insert(layout.solids.end(), objects.begin(), objects.end());
    return layout;
}

}  // namespace pyrseg::synthetic::detail
