#include "pyrseg/segmenter.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <utility>

#include "core/backend_registry.hpp"
#include "core/cloud_layout.hpp"
#include "core/depth_camera.hpp"
#include "core/depth_tables.hpp"
#include "core/pipeline.hpp"
#include "core/plan.hpp"
#include "core/segment_graph.hpp"
#include "core/segment_stats.hpp"
#include "core/segmenter_impl.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg {

namespace core {

namespace {

// Tracks (docs/algorithm.md section 11) from the frame's overlap pairs and statistics, then the id image.
void follow_tracks(Segmenter::Impl& impl, Result& out) {
    const std::optional<std::uint32_t> frame = impl.executor->track_frame();
    if (frame && *frame != impl.tracks.frame()) {
        throw Error(ErrorCode::invalid_argument,
                    "tracks: this host frame is frame " + std::to_string(*frame) +
                        " of the stream on the device, but the next frame the host matches is frame " +
                        std::to_string(impl.tracks.frame()) +
                        ": the device frames before it were not all decoded (decode_device_tracks); call "
                        "reset_tracks to start a new stream");
    }
    std::uint32_t pair_count = 0;
    const std::uint32_t* pairs = impl.executor->track_pairs(pair_count);
    impl.tracks.next(pairs, pair_count, out.segments, impl.plan.width, impl.plan.height, impl.plan.params, out.tracks);
    if (!impl.outputs.track_ids) {
        out.track_ids.clear();
        return;
    }
    out.track_ids.resize(out.labels.size());
    std::transform(out.labels.begin(), out.labels.end(), out.track_ids.begin(),
                   [&](std::uint32_t k) { return k == 0 ? 0u : out.tracks[k - 1].id; });
}

}  // namespace

}  // namespace core

namespace {

void check_frame_size(const char* what, int width, int height, const core::Plan& plan) {
    if (width != plan.width || height != plan.height) {
        throw Error(ErrorCode::size_mismatch, std::string(what) + " is " + std::to_string(width) + " x " +
                                                  std::to_string(height) + " but the Segmenter was created for " +
                                                  std::to_string(plan.width) + " x " + std::to_string(plan.height));
    }
}

void check_layout(const char* what, std::size_t row_stride, int point_stride, int width, int height) {
    if (row_stride != 0 && row_stride < std::size_t(width)) {
        throw Error(ErrorCode::invalid_argument, std::string(what) + " row_stride " + std::to_string(row_stride) +
                                                     " is smaller than the width " + std::to_string(width));
    }
    // The last element read must be addressable: ((height - 1) * stride + width) * point_stride floats.
    const std::size_t stride = row_stride == 0 ? std::size_t(width) : row_stride;
    const std::size_t limit = std::numeric_limits<std::size_t>::max() / sizeof(float) / std::size_t(point_stride);
    if (stride > (limit - std::size_t(width)) / std::size_t(height)) {
        throw Error(ErrorCode::invalid_argument,
                    std::string(what) + " row_stride " + std::to_string(row_stride) + " is too large to address");
    }
}

// Given normals are expected unit length (docs/algorithm.md section 1). The contract defines the labels of any
// normal (quantization clamps), so one off unit length only affects its own pixel; but a frame whose normals are all
// off, scaled (s < 1 makes every pixel an edge: the frame comes back silently unlabelled), is a caller's mistake and
// refused. 1% either way passes what real tools write; (0, 0, 0) and non-finite components mean "no normal".
constexpr float kMinNormalLength2 = 0.99f * 0.99f;
constexpr float kMaxNormalLength2 = 1.01f * 1.01f;

enum class NormalKind { none, unit, off_unit };

// The 1-norm s bounds the length (s / sqrt(3) <= |n| <= s), so outside [0.99, 1.75] it decides alone and inside it
// the squared length can neither overflow nor underflow; a NaN component makes s NaN, an infinite one s infinite.
NormalKind classify(const float* n) {
    const float x = std::abs(n[0]);
    const float y = std::abs(n[1]);
    const float z = std::abs(n[2]);
    const float s = x + y + z;
    if (!(s > 0.0f && s <= std::numeric_limits<float>::max())) return NormalKind::none;
    const float length2 = x * x + y * y + z * z;
    const bool unit = s >= 0.99f && s <= 1.75f && length2 >= kMinNormalLength2 && length2 <= kMaxNormalLength2;
    return unit ? NormalKind::unit : NormalKind::off_unit;
}

// Stops at the first unit normal, which for a frame of real normals is its first valid pixel: the check costs
// nothing per frame but on the frames it refuses (or that have hardly any normal).
void check_normals(const CloudView& cloud, const core::CloudLayout& layout) {
    std::size_t off = 0;
    std::size_t first_x = 0;
    std::size_t first_y = 0;
    for (std::size_t y = 0; y < std::size_t(cloud.height); ++y) {
        for (std::size_t x = 0; x < std::size_t(cloud.width); ++x) {
            const NormalKind kind = classify(cloud.normals + layout.at(x, y));
            if (kind == NormalKind::unit) return;
            if (kind == NormalKind::off_unit && off++ == 0) {
                first_x = x;
                first_y = y;
            }
        }
    }
    // A handful of normals says too little about how they were made (and a frame that small has hardly any labels).
    constexpr std::size_t kFewNormals = 16;
    if (off < kFewNormals) return;
    const float* n = cloud.normals + layout.at(first_x, first_y);
    const double length = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    throw Error(ErrorCode::invalid_argument, "cloud.normals: none of the frame's " + std::to_string(off) +
                                                 " normals is unit length (within 1%); the first, at pixel (" +
                                                 std::to_string(first_x) + ", " + std::to_string(first_y) +
                                                 "), has length " + std::to_string(length) +
                                                 ": normalise them, or give (0, 0, 0) or NaN for no normal");
}

// A frame's colour image: rows of at least 3 * width bytes, all of them addressable; returns the row step.
std::size_t check_color(const std::uint8_t* color, std::size_t row_step_bytes, int width, int height) {
    if (color == nullptr) {
        if (row_step_bytes != 0) {
            throw Error(ErrorCode::invalid_argument,
                        "color_row_step_bytes is " + std::to_string(row_step_bytes) + " but color is null");
        }
        return 0;
    }
    const std::size_t row = 3 * std::size_t(width);
    const std::size_t step = row_step_bytes == 0 ? row : row_step_bytes;
    if (step < row) {
        throw Error(ErrorCode::invalid_argument, "color_row_step_bytes " + std::to_string(row_step_bytes) +
                                                     " is smaller than a row of RGB8 (3 x width " +
                                                     std::to_string(width) + " = " + std::to_string(row) + ")");
    }
    if (step > (std::numeric_limits<std::size_t>::max() - row) / std::size_t(height)) {
        throw Error(ErrorCode::invalid_argument,
                    "color_row_step_bytes " + std::to_string(row_step_bytes) + " is too large to address");
    }
    return step;
}

}  // namespace

namespace {

// Every member goes through here: a moved-from Segmenter has no Impl, and a clear error beats a null dereference.
Segmenter::Impl& live(const std::unique_ptr<Segmenter::Impl>& impl) {
    if (!impl) {
        throw Error(ErrorCode::invalid_argument,
                    "the Segmenter was moved from: it holds no backend; use the one it was moved to");
    }
    return *impl;
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The host memory a backend's buffers, staging or a frame's results need but cannot get is ErrorCode::out_of_memory
// on every backend (the GPU backends' host vectors let std::bad_alloc through, Python saw a MemoryError), here once
// for all of them.
template <class Work>
void with_host_memory(const Segmenter::Impl& impl, const Work& work) {
    try {
        work();
    } catch (const std::bad_alloc&) {
        throw Error(ErrorCode::out_of_memory, "segmenting a " + std::to_string(impl.plan.width) + " x " +
                                                  std::to_string(impl.plan.height) + " frame on the " + impl.backend +
                                                  " backend: the host's memory ran out");
    }
}

// One frame: the input to the backend, the passes, the results back; all timed ("upload" and "download" after
// the passes).
template <class Bind>
void run_frame(Segmenter::Impl& impl, core::InputKind input, const Bind& bind, Result& out,
               const std::uint8_t* color = nullptr, std::size_t color_row_step_bytes = 0) {
    with_host_memory(impl, [&] {
        const auto upload_start = std::chrono::steady_clock::now();
        bind();
        if (color != nullptr) impl.executor->bind_color(color, color_row_step_bytes);
        const double upload_ms = milliseconds_since(upload_start);
        core::run_pipeline(impl.plan, input, color != nullptr, *impl.executor, impl.timings);
        const auto download_start = std::chrono::steady_clock::now();
        impl.executor->read_back(out, impl.outputs);
        const double download_ms = milliseconds_since(download_start);
        impl.timings.push_back(PassTiming{"upload", upload_ms});
        impl.timings.push_back(PassTiming{"download", download_ms});
        if (impl.plan.track_slots != 0) {
            const auto match_start = std::chrono::steady_clock::now();
            core::follow_tracks(impl, out);
            impl.timings.push_back(PassTiming{"track_matching", milliseconds_since(match_start)});
        } else {
            out.tracks.clear();
            out.track_ids.clear();
        }
        impl.executor->device_timings(impl.timings);
    });
}

}  // namespace

// A function try block: the host's memory can run out from the first member on.
Segmenter::Segmenter(int width, int height, const Params& params, std::string_view backend, const Outputs& outputs) try
    : impl_(std::make_unique<Impl>()) {
    impl_->plan = core::make_plan(width, height, params, outputs);
    impl_->backend = resolve_backend_name(backend);
    impl_->outputs = outputs;
    impl_->executor = core::make_executor(impl_->backend, impl_->plan);
    impl_->timings.reserve(16);
} catch (const std::bad_alloc&) {
    throw Error(ErrorCode::out_of_memory, "making a " + std::to_string(width) + " x " + std::to_string(height) +
                                              " Segmenter: the host's memory ran out");
}

Segmenter::Segmenter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Segmenter::~Segmenter() = default;
Segmenter::Segmenter(Segmenter&&) noexcept = default;
Segmenter& Segmenter::operator=(Segmenter&&) noexcept = default;

void Segmenter::segment(const CloudView& cloud, Result& out) {
    Impl& impl = live(impl_);
    if (cloud.points == nullptr) throw Error(ErrorCode::invalid_argument, "cloud.points is null");
    check_frame_size("the cloud", cloud.width, cloud.height, impl.plan);
    const core::CloudLayout layout = core::cloud_layout(cloud);  // throws when the steps do not fit
    if (cloud.normals != nullptr) check_normals(cloud, layout);
    const std::size_t color_step = check_color(cloud.color, cloud.color_row_step_bytes, cloud.width, cloud.height);
    const auto input =
        cloud.normals != nullptr ? core::InputKind::cloud_with_normals : core::InputKind::cloud_without_normals;
    run_frame(
        impl, input, [&] { impl.executor->bind_cloud(cloud); }, out, cloud.color, color_step);
}

void Segmenter::segment(const DepthView& depth, Result& out) {
    Impl& impl = live(impl_);
    check_frame_size("the depth image", depth.width, depth.height, impl.plan);
    const std::size_t color_step = check_color(depth.color, depth.color_row_step_bytes, depth.width, depth.height);
    core::make_depth_tables(depth, impl.plan.params.unit_mm, impl.depth_tables);
    // The sampled median catches a wrong depth scale. That is a property of the camera, not of each frame's content:
    // once a frame with enough data has passed, the same camera is not checked again (a covered lens later in a
    // stream cannot stop it).
    if (!impl.checked_camera.same(depth) && check_depth_camera(depth).median_depth_m > 0) {
        impl.checked_camera.remember(depth);
    }
    run_frame(
        impl, core::InputKind::depth, [&] { impl.executor->bind_depth(depth, impl.depth_tables); }, out, depth.color,
        color_step);
}

Result Segmenter::segment(const DepthView& depth) {
    Result out;
    segment(depth, out);
    return out;
}

Result Segmenter::segment(const CloudView& cloud) {
    Result out;
    segment(cloud, out);
    return out;
}

void Segmenter::segment_mask(const MaskView& mask, Result& out) {
    Impl& impl = live(impl_);
    if (mask.fillable == nullptr) throw Error(ErrorCode::invalid_argument, "mask.fillable is null");
    if (impl.plan.params.merge) {
        throw Error(ErrorCode::invalid_parameter,
                    "merge measures the boundaries on points and normals: a mask has none (segment a cloud or a "
                    "depth image, or turn merge off)");
    }
    if (uses_edge_depth_step(impl.plan.params)) {
        throw Error(ErrorCode::invalid_parameter,
                    "edge_max_depth_step compares the depths of edge pixels: a mask has none (segment a cloud or a "
                    "depth image, or set edge_max_depth_step to 0)");
    }
    check_frame_size("the mask", mask.width, mask.height, impl.plan);
    check_layout("the mask's", mask.row_stride, 1, mask.width, mask.height);
    run_frame(
        impl, core::InputKind::mask, [&] { impl.executor->bind_mask(mask); }, out);
}

void Segmenter::reset_tracks() {
    Impl& impl = live(impl_);
    impl.tracks.reset();
    impl.executor->forget_previous_labels();
}

int Segmenter::width() const {
    return live(impl_).plan.width;
}
int Segmenter::height() const {
    return live(impl_).plan.height;
}
const Params& Segmenter::params() const {
    return live(impl_).plan.params;
}
const std::string& Segmenter::backend_name() const {
    return live(impl_).backend;
}
const std::vector<PassTiming>& Segmenter::last_timings() const {
    return live(impl_).timings;
}
std::uint32_t Segmenter::last_fill_rounds() const {
    return live(impl_).executor->fill_rounds();
}
std::uint32_t Segmenter::last_dispatches() const {
    return live(impl_).executor->dispatches();
}
std::uint32_t Segmenter::last_host_syncs() const {
    return live(impl_).executor->host_syncs();
}

std::size_t Segmenter::device_statistics_bytes() const {
    return 4 * live(impl_).plan.stats_words();
}

void Segmenter::decode_device_statistics(const std::uint32_t* words, std::uint32_t count,
                                         std::vector<SegmentStats>& out) const {
    const core::Plan& plan = live(impl_).plan;
    if (plan.stats_slots == 0) {
        throw Error(ErrorCode::invalid_argument,
                    "decode_device_statistics: the Segmenter was made without Outputs::segment_stats");
    }
    if (count > plan.stats_slots) {
        throw Error(ErrorCode::invalid_argument, "decode_device_statistics: a segment count of " +
                                                     std::to_string(count) + " is more than the Segmenter's " +
                                                     std::to_string(plan.stats_slots) + " statistics slots");
    }
    if (words == nullptr && count != 0) throw Error(ErrorCode::invalid_argument, "decode_device_statistics: no words");
    core::decode_segment_stats(words, count, plan, true, out);  // device frames are clouds or depth images
}

std::size_t Segmenter::device_segment_graph_bytes() const {
    return 4 * live(impl_).plan.graph_words();
}

// The words as the device left them (shaders/pyr_graph.h): the pair count, the table of the slots K needs, then the
// gathered pairs.
void Segmenter::decode_device_segment_graph(const std::uint32_t* words, std::uint32_t count,
                                            std::vector<SegmentEdge>& out) const {
    const core::Plan& plan = live(impl_).plan;
    if (plan.graph_slots == 0) {
        throw Error(ErrorCode::invalid_argument,
                    "decode_device_segment_graph: the Segmenter was made without Outputs::segment_graph");
    }
    if (count > plan.max_label) {
        throw Error(ErrorCode::invalid_argument, "decode_device_segment_graph: a segment count of " +
                                                     std::to_string(count) + " is more than the Segmenter's " +
                                                     std::to_string(plan.max_label) + " labels");
    }
    if (words == nullptr) throw Error(ErrorCode::invalid_argument, "decode_device_segment_graph: no words");
    const std::uint32_t pairs = std::min(words[0], plan.graph_slots / 2);
    const std::size_t list = 1 + std::size_t(PYR_GRAPH_SLOT_WORDS) * pyr_graph_slots(count, plan.graph_slots);
    core::decode_segment_graph(words + list, pairs, out);
}

std::size_t Segmenter::device_tracks_bytes() const {
    return 4 * live(impl_).plan.track_list_words();
}

// The words as the device left them (shaders/pyr_types.h: PYR_TRACK_HEADER_WORDS): the frame's number in its stream,
// K', K, the pair count, then the pairs.
void Segmenter::decode_device_tracks(const std::uint32_t* words, const std::vector<SegmentStats>& segments,
                                     std::vector<SegmentTrack>& out) {
    Impl& impl = live(impl_);
    const core::Plan& plan = impl.plan;
    const auto fail = [](const std::string& what) {
        throw Error(ErrorCode::invalid_argument, "decode_device_tracks: " + what);
    };
    if (plan.track_slots == 0) fail("the Segmenter was made without Outputs::segment_tracks or track_ids");
    if (words == nullptr) fail("no words");
    const std::uint32_t frame = words[PYR_TRACK_FRAME];
    if (frame != impl.tracks.frame()) {
        fail("the words are of frame " + std::to_string(frame) + " of the stream, but the next to decode is frame " +
             std::to_string(impl.tracks.frame()) +
             ": decode each device frame's tracks once, in the order the frames ran");
    }
    if (words[PYR_TRACK_COUNT] != segments.size()) {
        fail("the frame has " + std::to_string(words[PYR_TRACK_COUNT]) + " segments but " +
             std::to_string(segments.size()) + " statistics were given (decode_device_statistics of the same frame)");
    }
    const std::uint32_t pairs = std::min(words[PYR_TRACK_PAIRS], plan.track_pair_capacity());
    impl.tracks.next(words + PYR_TRACK_HEADER_WORDS, pairs, segments, plan.width, plan.height, plan.params, out);
}

}  // namespace pyrseg
