#include "core/device_frame.hpp"

#include <limits>
#include <string>
#include <utility>

#include "core/executor.hpp"
#include "core/pipeline.hpp"
#include "core/segmenter_impl.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::core {
namespace {

[[noreturn]] void bad(const std::string& what) {
    throw Error(ErrorCode::invalid_argument, what);
}

std::string frame_name(int width, int height) {
    return std::to_string(width) + " x " + std::to_string(height);
}

// `rows` rows of `row_bytes`, `pitch` bytes apart, from the buffer's offset on; pitch and offset multiples of
// `align`.
void check_rows(const char* what, const ExternalBuffer& b, std::size_t pitch, std::size_t row_bytes, std::size_t rows,
                std::size_t align, int width, int height) {
    const std::string name = std::string("the ") + what + " buffer";
    if (b.handle == 0) bad(name + " is missing (a null handle)");
    if (pitch < row_bytes) {
        bad(name + "'s row step of " + std::to_string(pitch) + " bytes is smaller than a row (" +
            std::to_string(row_bytes) + " bytes)");
    }
    if (pitch % align != 0 || b.offset % align != 0) {
        bad(name + "'s row step (" + std::to_string(pitch) + ") and offset (" + std::to_string(b.offset) +
            ") must be multiples of " + std::to_string(align) + " bytes");
    }
    const std::size_t max = std::numeric_limits<std::size_t>::max();
    if (rows > 1 && pitch > (max - row_bytes) / (rows - 1)) bad(name + "'s row step is too large to address");
    const std::size_t needed = (rows - 1) * pitch + row_bytes;
    if (b.bytes < needed) {
        bad(name + " holds " + std::to_string(b.bytes) + " bytes from its offset " + std::to_string(b.offset) +
            " on, but a " + frame_name(width, height) + " frame needs " + std::to_string(needed));
    }
}

Segmenter::Impl& impl_of(Segmenter& segmenter) {
    return SegmenterAccess::impl(segmenter);
}

template <class Bind>
void run(Segmenter::Impl& impl, InputKind input, const Bind& bind, const DeviceColor& color,
         const DeviceLabels& labels) {
    bind();
    const bool with_color = color.rgb.handle != 0;
    if (with_color) impl.executor->bind_device_color(color);
    run_pipeline(impl.plan, input, with_color, *impl.executor, impl.timings);
    impl.executor->write_device_labels(labels);
    impl.timings.clear();  // host times of queued work: meaningless, and no device times were kept
}

void check_device_cloud(const DeviceCloud& cloud, int width, int height) {
    const std::size_t row = 12 * std::size_t(width);
    const std::size_t pitch = cloud.row_step_bytes == 0 ? row : cloud.row_step_bytes;
    check_rows("points", cloud.points, pitch, row, std::size_t(height), 4, width, height);
    if (cloud.normals.handle != 0)
        check_rows("normals", cloud.normals, pitch, row, std::size_t(height), 4, width, height);
}

void check_device_depth(const DeviceDepth& depth, int width, int height) {
    const std::size_t sample = DepthTables::sample_bytes(depth.view.format);
    const std::size_t row = sample * std::size_t(width);
    const std::size_t pitch = depth.view.row_step_bytes == 0 ? row : depth.view.row_step_bytes;
    check_rows("depth samples", depth.samples, pitch, row, std::size_t(height), sample, width, height);
}

void check_device_color(const DeviceColor& color, int width, int height) {
    if (color.rgb.handle == 0) {
        if (color.row_step_bytes != 0) bad("the colour image's row step is set but it has no buffer");
        return;
    }
    const std::size_t row = 3 * std::size_t(width);
    const std::size_t pitch = color.row_step_bytes == 0 ? row : color.row_step_bytes;
    check_rows("colour image", color.rgb, pitch, row, std::size_t(height), 1, width, height);
}

// The words of one of the Segmenter's outputs (`words` of them; 0 when it was made without `output`), when the
// caller gives their buffer.
void check_output_words(const char* what, const ExternalBuffer& b, const char* output, std::size_t words,
                        const Plan& plan) {
    if (b.handle == 0) return;
    if (words == 0) bad(std::string("a ") + what + " buffer was given but the Segmenter was made without " + output);
    const std::size_t bytes = 4 * words;
    check_rows(what, b, bytes, bytes, 1, 4, plan.width, plan.height);
}

void check_device_labels(const DeviceLabels& labels, const Plan& plan) {
    const int width = plan.width;
    const int height = plan.height;
    const std::size_t row = 4 * std::size_t(width);
    const std::size_t pitch = labels.row_step_bytes == 0 ? row : labels.row_step_bytes;
    check_rows("labels", labels.labels, pitch, row, std::size_t(height), 4, width, height);
    if (labels.count.handle != 0) check_rows("segment count", labels.count, 4, 4, 1, 4, width, height);
    check_output_words("statistics", labels.statistics, "Outputs::segment_stats", plan.stats_words(), plan);
    check_output_words("segment graph", labels.graph, "Outputs::segment_graph", plan.graph_words(), plan);
    if (plan.track_slots != 0 && labels.tracks.handle == 0) {
        bad("the Segmenter follows tracks (Outputs::segment_tracks or track_ids): each device frame needs a "
            "tracks buffer of Segmenter::device_tracks_bytes() for Segmenter::decode_device_tracks");
    }
    check_output_words("tracks", labels.tracks, "Outputs::segment_tracks or track_ids", plan.track_list_words(), plan);
}

}  // namespace

Segmenter::Impl& SegmenterAccess::impl(Segmenter& segmenter) {
    if (!segmenter.impl_) throw Error(ErrorCode::invalid_argument, "the Segmenter was moved from");
    return *segmenter.impl_;
}

Segmenter make_segmenter(int width, int height, const Params& params, const Outputs& outputs,
                         const std::string& backend,
                         const std::function<std::unique_ptr<PassExecutor>(const Plan&)>& make_executor) {
    auto impl = std::make_unique<Segmenter::Impl>();
    impl->plan = make_plan(width, height, params, outputs);
    impl->backend = backend;
    impl->outputs = outputs;
    impl->executor = make_executor(impl->plan);
    impl->timings.reserve(16);
    return Segmenter(std::move(impl));
}

PassExecutor& executor_of(Segmenter& segmenter) {
    return *impl_of(segmenter).executor;
}

void run_device_frame(Segmenter& segmenter, const DeviceCloud& cloud, const DeviceLabels& labels,
                      const std::function<void()>& checked) {
    Segmenter::Impl& impl = impl_of(segmenter);
    check_device_cloud(cloud, impl.plan.width, impl.plan.height);
    check_device_color(cloud.color, impl.plan.width, impl.plan.height);
    check_device_labels(labels, impl.plan);
    const InputKind input =
        cloud.normals.handle != 0 ? InputKind::cloud_with_normals : InputKind::cloud_without_normals;
    if (checked) checked();
    run(
        impl, input, [&] { impl.executor->bind_device_cloud(cloud); }, cloud.color, labels);
}

void run_device_frame(Segmenter& segmenter, const DeviceDepth& depth, const DeviceLabels& labels,
                      const std::function<void()>& checked) {
    Segmenter::Impl& impl = impl_of(segmenter);
    if (depth.view.width != impl.plan.width || depth.view.height != impl.plan.height) {
        throw Error(ErrorCode::size_mismatch, "the depth image is " + frame_name(depth.view.width, depth.view.height) +
                                                  " but the Segmenter was created for " +
                                                  frame_name(impl.plan.width, impl.plan.height));
    }
    make_depth_tables(depth.view, impl.plan.params.unit_mm, impl.depth_tables, true);
    check_device_depth(depth, impl.plan.width, impl.plan.height);
    if (depth.view.color != nullptr) bad("a device depth frame's colour goes in its color buffer, not view.color");
    check_device_color(depth.color, impl.plan.width, impl.plan.height);
    check_device_labels(labels, impl.plan);
    if (checked) checked();
    run(
        impl, InputKind::depth, [&] { impl.executor->bind_device_depth(depth, impl.depth_tables); }, depth.color,
        labels);
}

void PassExecutor::bind_device_cloud(const DeviceCloud& /*cloud*/) {
    throw Error(ErrorCode::invalid_argument, "this Segmenter's backend takes no device buffers");
}
void PassExecutor::bind_device_depth(const DeviceDepth& /*depth*/, const DepthTables& /*tables*/) {
    throw Error(ErrorCode::invalid_argument, "this Segmenter's backend takes no device buffers");
}
void PassExecutor::bind_device_color(const DeviceColor& /*color*/) {
    throw Error(ErrorCode::invalid_argument, "this Segmenter's backend takes no device buffers");
}
void PassExecutor::write_device_labels(const DeviceLabels& /*labels*/) {
    throw Error(ErrorCode::invalid_argument, "this Segmenter's backend takes no device buffers");
}
void PassExecutor::track_overlaps() {
    throw Error(ErrorCode::backend_unavailable, "this Segmenter's backend has no tracks");
}

}  // namespace pyrseg::core
