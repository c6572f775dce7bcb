// Soak: one Segmenter per backend over many frames whose content changes (scenes, holes, noise), the process's
// resident memory checked flat once warm. PYRSEG_SOAK_FRAMES sets the number of frames: the suite's short run
// (default 120) catches a leak per frame of a few tens of kilobytes; ctest's `soak_long` (label `long`, not in the
// default run: `ctest --preset release -L long`) runs 5000.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::test {
namespace {

// Resident set size in bytes (/proc/self/statm: pages).
std::size_t resident_bytes() {
    std::ifstream statm("/proc/self/statm");
    std::size_t total = 0;
    std::size_t resident = 0;
    statm >> total >> resident;
    return resident * std::size_t(::sysconf(_SC_PAGESIZE));
}

int soak_frames() {
    const char* v = std::getenv("PYRSEG_SOAK_FRAMES");
    return v != nullptr && std::atoi(v) > 0 ? std::atoi(v) : 120;
}

std::vector<std::string> available() {
    std::vector<std::string> names;
    for (const BackendInfo& b : list_backends()) {
        if (b.available) names.push_back(b.name);
    }
    return names;
}

class Soak : public ::testing::TestWithParam<std::string> {};

TEST_P(Soak, ResidentMemoryStaysFlatOverChangingFrames) {
    constexpr int kWidth = 160;
    constexpr int kHeight = 120;
    // A small pool of different frames, generated once: what changes from frame to frame is the content the passes
    // see (segments, holes, fragmented masks), not the allocations of making them.
    std::vector<synthetic::Scene> scenes;
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
        synthetic::SceneOptions o;
        o.width = kWidth;
        o.height = kHeight;
        o.seed = seed;
        o.threads = 1;
        o.noise_mm = seed % 2 == 0 ? 1.5 : 0.1;
        o.hole_fraction = seed % 3 == 0 ? 0.1 : 0.01;
        scenes.push_back(synthetic::generate(o));
    }
    Segmenter segmenter(kWidth, kHeight, {}, GetParam());
    Result result;
    const auto frame = [&](int i) {
        const synthetic::Scene& s = scenes[std::size_t(i) % scenes.size()];
        const bool given = (i / int(scenes.size())) % 2 == 1;
        segmenter.segment(CloudView{s.points.data(), given ? s.normals.data() : nullptr, kWidth, kHeight}, result);
    };
    const int frames = soak_frames();
    const int warm = 40;  // every scene with and without normals a few times: every buffer at its size
    for (int i = 0; i < warm; ++i) frame(i);
    const std::size_t before = resident_bytes();
    std::uint64_t segments = 0;
    for (int i = warm; i < warm + frames; ++i) {
        frame(i);
        segments += result.segment_count;
    }
    const std::size_t after = resident_bytes();
    // Allocator noise and lazily mapped driver pages stay well under this; a leak of 40 KB a frame (a tenth of a
    // frame's labels) over 120 frames does not.
    constexpr std::size_t kSlack = std::size_t{4} << 20;
    EXPECT_LE(after, before + kSlack) << GetParam() << ": resident memory grew from " << before << " to " << after
                                      << " bytes over " << frames << " frames";
    EXPECT_GT(segments, std::uint64_t(frames)) << "the frames must have segments";
}

INSTANTIATE_TEST_SUITE_P(Backends, Soak, ::testing::ValuesIn(available()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
