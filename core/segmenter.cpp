#include "pyrseg/segmenter.hpp"

#include <chrono>
#include <limits>
#include <string>
#include <utility>

#include "core/backend_registry.hpp"
#include "core/cloud_layout.hpp"
#include "core/depth_tables.hpp"
#include "core/pipeline.hpp"
#include "core/plan.hpp"
#include "core/segmenter_impl.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg {

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

}  // namespace

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// One frame: the input to the backend, the passes, the results back; all timed ("upload" and "download" after
// the passes).
template <class Bind>
void run_frame(Segmenter::Impl& impl, core::InputKind input, const Bind& bind, Result& out) {
    const auto upload_start = std::chrono::steady_clock::now();
    bind();
    const double upload_ms = milliseconds_since(upload_start);
    core::run_pipeline(impl.plan, input, *impl.executor, impl.timings);
    const auto download_start = std::chrono::steady_clock::now();
    impl.executor->read_back(out, impl.outputs);
    impl.timings.push_back(PassTiming{"upload", upload_ms});
    impl.timings.push_back(PassTiming{"download", milliseconds_since(download_start)});
    impl.executor->device_timings(impl.timings);
}

}  // namespace

Segmenter::Segmenter(int width, int height, const Params& params, std::string_view backend, const Outputs& outputs)
    : impl_(std::make_unique<Impl>()) {
    impl_->plan = core::make_plan(width, height, params, outputs);
    impl_->backend = resolve_backend_name(backend);
    impl_->outputs = outputs;
    impl_->executor = core::make_executor(impl_->backend, impl_->plan);
    impl_->timings.reserve(16);
}

Segmenter::Segmenter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Segmenter::~Segmenter() = default;
Segmenter::Segmenter(Segmenter&&) noexcept = default;
Segmenter& Segmenter::operator=(Segmenter&&) noexcept = default;

void Segmenter::segment(const CloudView& cloud, Result& out) {
    if (cloud.points == nullptr) throw Error(ErrorCode::invalid_argument, "cloud.points is null");
    check_frame_size("the cloud", cloud.width, cloud.height, impl_->plan);
    (void)core::cloud_layout(cloud);  // throws when the steps do not fit
    const auto input =
        cloud.normals != nullptr ? core::InputKind::cloud_with_normals : core::InputKind::cloud_without_normals;
    run_frame(
        *impl_, input, [&] { impl_->executor->bind_cloud(cloud); }, out);
}

void Segmenter::segment(const DepthView& depth, Result& out) {
    check_frame_size("the depth image", depth.width, depth.height, impl_->plan);
    core::make_depth_tables(depth, impl_->plan.params.unit_mm, impl_->depth_tables);
    run_frame(
        *impl_, core::InputKind::depth, [&] { impl_->executor->bind_depth(depth, impl_->depth_tables); }, out);
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
    if (mask.fillable == nullptr) throw Error(ErrorCode::invalid_argument, "mask.fillable is null");
    check_frame_size("the mask", mask.width, mask.height, impl_->plan);
    check_layout("the mask's", mask.row_stride, 1, mask.width, mask.height);
    run_frame(
        *impl_, core::InputKind::mask, [&] { impl_->executor->bind_mask(mask); }, out);
}

int Segmenter::width() const noexcept {
    return impl_->plan.width;
}
int Segmenter::height() const noexcept {
    return impl_->plan.height;
}
const Params& Segmenter::params() const noexcept {
    return impl_->plan.params;
}
const std::string& Segmenter::backend_name() const noexcept {
    return impl_->backend;
}
const std::vector<PassTiming>& Segmenter::last_timings() const noexcept {
    return impl_->timings;
}
std::uint32_t Segmenter::last_fill_rounds() const {
    return impl_->executor->fill_rounds();
}
std::uint32_t Segmenter::last_dispatches() const {
    return impl_->executor->dispatches();
}
std::uint32_t Segmenter::last_host_syncs() const {
    return impl_->executor->host_syncs();
}

}  // namespace pyrseg
