#pragma once
// A self-contained generator (xoshiro256** seeded by splitmix64, Box-Muller normals), so that scenes do not depend
// on how a standard library implements its distributions.
#include <cmath>
#include <cstdint>

namespace pyrseg::synthetic::detail {

inline std::uint64_t splitmix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// Independent streams of one seed (layout, holes, the noise of each row; a sequence's camera walk, object motion
// and per-frame noise seeds), so that changing one part of the options or the image size leaves the others as they
// were. Sensor models draw row j of their field k from sensor_rows + (k << 16) + j, clear of noise_rows + v for
// every v below the largest image side.
enum class Stream : std::uint64_t {
    layout = 1,
    holes = 2,
    camera_walk = 3,
    object_motion = 4,
    frame_noise = 5,
    noise_rows = 0x100,
    sensor_rows = 0x100000
};

class Rng {
public:
    Rng(std::uint64_t seed, std::uint64_t stream) {
        std::uint64_t state = seed;
        const std::uint64_t mixed = splitmix64(state) ^ (stream * 0xd1b54a32d192ed03ULL);
        state = mixed;
        for (auto& word : s_) word = splitmix64(state);
    }
    Rng(std::uint64_t seed, Stream stream) : Rng(seed, static_cast<std::uint64_t>(stream)) {}

    std::uint64_t next() {
        const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
        const std::uint64_t t = s_[1] << 17;
        s_[2] ^= s_[0];
        s_[3] ^= s_[1];
        s_[1] ^= s_[2];
        s_[0] ^= s_[3];
        s_[2] ^= t;
        s_[3] = rotl(s_[3], 45);
        return result;
    }

    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    int below(int n) { return static_cast<int>(uniform() * n); }  // 0..n-1
    bool chance(double p) { return uniform() < p; }

    double normal() {
        if (has_spare_) {
            has_spare_ = false;
            return spare_;
        }
        const double u1 = 1.0 - uniform();  // (0, 1]: log stays finite
        const double u2 = uniform();
        const double r = std::sqrt(-2.0 * std::log(u1));
        const double angle = 6.283185307179586 * u2;
        spare_ = r * std::sin(angle);
        has_spare_ = true;
        return r * std::cos(angle);
    }

private:
    static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

    std::uint64_t s_[4] = {};
    double spare_ = 0;
    bool has_spare_ = false;
};

}  // namespace pyrseg::synthetic::detail
