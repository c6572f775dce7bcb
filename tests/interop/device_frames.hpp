#pragma once
// The device-frame checks every GPU API's interop passes (device_frames.cpp), written once over an adapter that each
// API implements in its own file (opencl_adapter.cpp, vulkan_adapter.cpp, cuda_adapter.cpp), as OpenMM shares its
// test bodies across platforms. The adapter is the application's side: a context, queue and buffers it creates
// itself, and the API's ways of handing pyrseg a frame. Checks only one API has stay in test_<api>_interop.cpp.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::test {

// Where a frame's data is: one of the adapter's buffers (its index; kNone: no buffer) and the offset into it.
struct Region {
    static constexpr int kNone = -1;
    int buffer = kNone;
    std::size_t offset = 0;
};

struct CloudFrame {
    Region points;
    Region normals;  // kNone: normals are estimated
    std::size_t row_step_bytes = 0;
    Region color = {};  // kNone: no colour image
    std::size_t color_row_step_bytes = 0;
};

struct DepthFrame {
    Region samples;
    DepthView view;     // view.depth stays null: the samples are on the device
    Region color = {};  // kNone: no colour image
    std::size_t color_row_step_bytes = 0;
};

struct LabelFrame {
    Region labels;
    Region count;       // kNone: K is not written
    Region statistics;  // kNone: the statistics are not written (Segmenter::device_statistics_bytes() from it on)
    Region graph;       // kNone: the segment graph is not written (Segmenter::device_segment_graph_bytes() from it on)
    Region tracks;      // kNone: no tracks buffer (Segmenter::device_tracks_bytes() from it on)
    std::size_t row_step_bytes = 0;
};

struct Frame {
    std::variant<CloudFrame, DepthFrame> in;
    LabelFrame out;
};

// One of the API's ways to hand pyrseg frames. A way for refusals only cannot run a frame that is accepted (a
// Vulkan command buffer never begun: recording anything into it is an error of the caller's).
struct Way {
    std::string name;
    bool refusals_only = false;
};

class Adapter {
public:
    Adapter() = default;
    virtual ~Adapter() = default;
    Adapter(const Adapter&) = delete;
    Adapter& operator=(const Adapter&) = delete;

    // Makes the application's context; why there is none on this machine (the test is skipped), else empty.
    [[nodiscard]] virtual std::string open() = 0;
    [[nodiscard]] virtual std::string backend_name() const = 0;
    [[nodiscard]] virtual std::vector<Way> ways() const = 0;
    [[nodiscard]] virtual Segmenter make_segmenter(int width, int height, const Params& params,
                                                   const Outputs& outputs = {}) = 0;

    // A buffer of `bytes` on the application's context, every byte 0xAB; its index.
    [[nodiscard]] virtual int allocate(std::size_t bytes) = 0;
    [[nodiscard]] virtual std::size_t size(int buffer) const = 0;
    virtual void upload(int buffer, std::size_t offset, const void* data, std::size_t bytes) = 0;
    // Once everything queued on the application's queue is done.
    [[nodiscard]] virtual std::vector<unsigned char> download(int buffer, std::size_t offset, std::size_t bytes) = 0;

    // Hands pyrseg `frames` back to back in way `way` (an index into ways()), none waited for before the next is
    // queued, and returns once all of them completed. A refused frame throws the pyrseg::Error, having queued
    // nothing (what only the API can tell, a fence left unsignalled, the adapter checks itself).
    virtual void run(Segmenter& segmenter, std::span<const Frame> frames, std::size_t way) = 0;
};

// An API's adapter maker, named after the API in the tests' names.
struct AdapterMaker {
    const char* api;
    std::unique_ptr<Adapter> (*make)();
};
inline void PrintTo(const AdapterMaker& maker, std::ostream* os) {
    *os << maker.api;
}
inline std::string adapter_name(const ::testing::TestParamInfo<AdapterMaker>& info) {
    return info.param.api;
}

// A new buffer holding `bytes` of `data` from byte `at` on (0xAB before), as a region from `at`.
Region put(Adapter& api, const void* data, std::size_t bytes, std::size_t at = 0);
// `count` 32-bit words of a buffer from byte `offset` on.
std::vector<std::uint32_t> words(Adapter& api, int buffer, std::size_t offset, std::size_t count);

// A test for each adapter: INSTANTIATE_TEST_SUITE_P(<Api>, DeviceFrames,
// ::testing::Values(AdapterMaker{"<api>", &make_<api>_adapter}), adapter_name).
class DeviceFrames : public ::testing::TestWithParam<AdapterMaker> {
protected:
    void SetUp() override {
        adapter_ = GetParam().make();
        const std::string why = adapter_->open();
        if (!why.empty()) GTEST_SKIP() << why;
    }
    // The adapter's own checks (the validation layer's messages) run as it closes, inside the test.
    void TearDown() override { adapter_.reset(); }

    [[nodiscard]] Adapter& api() { return *adapter_; }
    Region put(const void* data, std::size_t bytes, std::size_t at = 0) { return test::put(api(), data, bytes, at); }
    std::vector<std::uint32_t> words(int buffer, std::size_t offset, std::size_t count) {
        return test::words(api(), buffer, offset, count);
    }

private:
    std::unique_ptr<Adapter> adapter_;
};

// One API's own tests on the same adapter, outside the shared suite.
template <class A>
class ApiTest : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string why = api_.emplace().open();
        if (!why.empty()) GTEST_SKIP() << why;
    }
    void TearDown() override { api_.reset(); }
    [[nodiscard]] A& api() { return *api_; }

private:
    std::optional<A> api_;
};

// Rows of `width` items of `item` bytes copied `pitch` bytes apart (the rest 0xCD), as an SDK pads them.
std::vector<unsigned char> pitched(const void* packed, int width, int height, std::size_t item, std::size_t pitch);

// The labels of a device frame's buffer, rows `pitch` bytes apart, packed again.
std::vector<std::uint32_t> unpitch(const unsigned char* bytes, int width, int height, std::size_t pitch);

// A camera panning over one kinect-v1 scene, for the tracks: a kWidth x kHeight frame at each column given (at most
// 16) as a cloud and as a uint16 depth image in millimetres (its principal point moved with the window), the
// kinect-v1 preset, and the outputs tracks need (the statistics and the tracks).
struct Window {
    std::vector<float> points;
    std::vector<std::uint16_t> depth;
    DepthView view;
};
struct PanningStream {
    static constexpr int kWidth = 96;
    static constexpr int kHeight = 72;
    Params params;
    Outputs outputs;
    std::vector<Window> windows;
    [[nodiscard]] CloudView cloud(std::size_t f) const { return {windows[f].points.data(), nullptr, kWidth, kHeight}; }
};
PanningStream panning_stream(std::initializer_list<int> columns);

// Expects `call` to throw a pyrseg::Error of `code` whose message names `words`.
template <class Call>
void expect_error(const Call& call, const std::string& words, ErrorCode code = ErrorCode::invalid_argument) {
    SCOPED_TRACE(words);
    try {
        call();
        ADD_FAILURE() << "no error; expected one naming " << words;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        EXPECT_EQ(e.code(), code) << to_string(e.code()) << ": " << e.what();
    }
}

// The frame the refusal checks start from: a flat wall 1 m away, 2 mm between pixels, one segment.
struct Wall {
    static constexpr int kWidth = 32;
    static constexpr int kHeight = 24;
    static constexpr std::size_t kPixels = std::size_t(kWidth) * kHeight;
    static constexpr std::uint32_t kSentinel = 0xDEADBEEFu;
    std::vector<float> points;
    std::vector<std::uint16_t> depth = std::vector<std::uint16_t>(kPixels, 1000);
    std::vector<std::uint32_t> sentinel = std::vector<std::uint32_t>(kPixels, kSentinel);
    DepthView view{nullptr, DepthFormat::u16, kWidth, kHeight, 0, 0.001, 500, 500, 16, 12};  // depth on the device
    Wall();
};

// The refusal checks on one adapter: a Segmenter for the wall, good frames of it in the adapter's buffers, labels
// and count holding a sentinel that no refused frame may change.
class Refusals {
public:
    explicit Refusals(Adapter& api);
    // `frame` refused with an Error of `code` naming `words` in each of the adapter's ways, nothing written.
    void expect(Segmenter& segmenter, const Frame& frame, const std::string& words,
                ErrorCode code = ErrorCode::invalid_argument);
    void expect(const Frame& frame, const std::string& words, ErrorCode code = ErrorCode::invalid_argument) {
        expect(segmenter, frame, words, code);
    }
    void expect_untouched();
    // After the refusals: both good frames in every way give the wall's one segment.
    void expect_still_segments();

    Adapter& api;
    const Wall wall;
    Segmenter segmenter;
    CloudFrame cloud;
    DepthFrame depth;
    LabelFrame out;
};

}  // namespace pyrseg::test
