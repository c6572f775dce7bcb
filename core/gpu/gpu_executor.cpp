// The passes of every GPU backend, written once over gpu::Device: which kernel each pass dispatches with which
// argument words (shaders/pyr_entries.h lists them per kernel), the buffer table, the fills' convergence, compaction,
// statistics and read-back.
#include "core/gpu/gpu_executor.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/depth_tables.hpp"
#include "core/gpu/device_fault.hpp"
#include "core/gpu/host_frame.hpp"
#include "core/segment_graph.hpp"
#include "core/segment_stats.hpp"
#include "pyrseg/error.hpp"
#include "shaders/pyr_depth.h"

namespace pyrseg::gpu {

namespace {

using std::size_t;
using std::uint32_t;

struct KernelInfo {
    const char* entry;
    const char* glsl;
    int dims;
};

constexpr KernelInfo kRows[] = {
#define PYR_HOST_KERNEL_INFO(name, NAME, dims) {"pyr_k_" #name, #NAME, dims},
    PYR_KERNEL_TABLE(PYR_HOST_KERNEL_INFO)
#undef PYR_HOST_KERNEL_INFO
};
static_assert(std::size(kRows) == kKernelCount);

constexpr const char* kBufferNames[] = {
#define PYR_HOST_BUFFER_NAME(name, index, TYPE, QUAL) #name,
    PYR_BUFFER_TABLE(PYR_HOST_BUFFER_NAME)
#undef PYR_HOST_BUFFER_NAME
};
static_assert(std::size(kBufferNames) == kBufferCount);

Args args(std::initializer_list<uint32_t> words) {
    Args a;
    std::copy(words.begin(), words.end(), a.words.begin());
    return a;
}

uint32_t bits(float f) {
    return std::bit_cast<uint32_t>(f);
}

uint32_t bits(std::int32_t i) {
    return std::bit_cast<uint32_t>(i);
}

class GpuExecutor final : public core::PassExecutor {
public:
    GpuExecutor(const core::Plan& plan, std::unique_ptr<Device> device)
        : plan_(plan), device_(std::move(device)), limits_(device_->limits()) {
        const BufferSizes sizes = buffer_sizes(plan_, limits_);
        check_fits(plan_, sizes, limits_, device_->description());
        device_->allocate(sizes, uint32_t(plan_.width));
        const size_t px = plan_.pixel_count();
        staged_.resize(StagedResults::kBytesPerPixel * px);
        host_stats_.resize(plan_.stats_words());
        host_graph_.resize(size_t(PYR_GRAPH_SLOT_WORDS) * (plan_.graph_slots / 2));
    }

    // The device goes first: a frame an error abandoned may still have transfers queued into staged_ and the
    // other host buffers, which its destructor waits for.
    ~GpuExecutor() override { device_.reset(); }
    GpuExecutor(const GpuExecutor&) = delete;
    GpuExecutor& operator=(const GpuExecutor&) = delete;

    void bind_cloud(const CloudView& cloud) override {
        start_frame(false);
        upload_xyz(cloud, cloud.points, Buffer::points, host_points_);
        if (cloud.normals != nullptr) upload_xyz(cloud, cloud.normals, Buffer::normals, host_normals_);
        from_mask_ = false;
    }

    // The samples travel in the quant buffer, which the passes before the quantize pass (depth, normals) do not
    // otherwise use: 2 (u16) or 4 (f32) bytes a pixel instead of 12. The ray slopes stay in the sums buffer's tail
    // from one frame to the next and travel only when they change.
    void bind_depth(const DepthView& depth, const core::DepthTables& tables) override {
        start_frame(false);
        core::pack_depth(depth, host_depth_);
        device_->upload(Buffer::quant, 0, host_depth_.data(), 4 * host_depth_.size());
        set_depth(depth.format, tables);
    }

    // A device-resident depth frame: the samples copied on the device from the caller's buffer, packed as
    // core::pack_depth packs them.
    void bind_device_depth(const core::DeviceDepth& depth, const core::DepthTables& tables) override {
        start_frame(true);
        const size_t row = core::DepthTables::sample_bytes(depth.view.format) * size_t(width());
        const size_t pitch = depth.view.row_step_bytes == 0 ? row : depth.view.row_step_bytes;
        device_->copy_in(Buffer::quant, 0, depth.samples, pitch, row, height());
        set_depth(depth.view.format, tables);
    }

    // The colour image packed row by row (3 bytes a pixel) into the color buffer.
    void bind_color(const std::uint8_t* rgb, size_t row_step_bytes) override {
        const size_t row = 3 * size_t(width());
        host_color_.resize((row * size_t(height()) + 3) / 4);  // once per Segmenter
        auto* packed = reinterpret_cast<unsigned char*>(host_color_.data());
        for (size_t y = 0; y < size_t(height()); ++y) std::memcpy(packed + y * row, rgb + y * row_step_bytes, row);
        device_->upload(Buffer::color, 0, host_color_.data(), 4 * host_color_.size());
    }

    // A device-resident colour image: copied on the device, packed as bind_color packs it.
    void bind_device_color(const core::DeviceColor& color) override {
        const size_t row = 3 * size_t(width());
        const size_t pitch = color.row_step_bytes == 0 ? row : color.row_step_bytes;
        device_->copy_in(Buffer::color, 0, color.rgb, pitch, row, height());
    }

    void color_edges() override {
        dispatch(Kernel::color_edges, width(), height(),
                 args({height(), plan_.full().offset, uint32_t(plan_.params.color_edge_stride),
                       uint32_t(plan_.params.color_edge_threshold), plan_.thresholds.color_curvature_gate,
                       uint32_t(plan_.params.curvature_stride), bits(plan_.thresholds.curvature_base),
                       bits(plan_.thresholds.curvature_growth)}));
    }

    void depth_to_points() override {
        dispatch(Kernel::depth_points, width(), height(),
                 args({height(), depth_format_, bits(depth_scale_), rays_word()}));
    }

    // A device-resident cloud: copied on the device into the points (and normals) buffers, packed.
    void bind_device_cloud(const core::DeviceCloud& cloud) override {
        start_frame(true);
        const size_t row = 12 * size_t(width());
        const size_t pitch = cloud.row_step_bytes == 0 ? row : cloud.row_step_bytes;
        device_->copy_in(Buffer::points, 0, cloud.points, pitch, row, height());
        if (cloud.normals.handle != 0) device_->copy_in(Buffer::normals, 0, cloud.normals, pitch, row, height());
        from_mask_ = false;
    }

    // The labels (and K) into the caller's buffers, then the frame goes to the device; nothing waits.
    void write_device_labels(const core::DeviceLabels& labels) override {
        const size_t row = 4 * size_t(width());
        const size_t pitch = labels.row_step_bytes == 0 ? row : labels.row_step_bytes;
        device_->copy_out(labels.labels, pitch, Buffer::out, 0, row, height());
        if (labels.count.handle != 0)
            device_->copy_out(labels.count, 4, Buffer::sums, 4 * size_t(plan_.scan_chunks()), 4, 1);
        if (labels.statistics.handle != 0) {
            const size_t bytes = 4 * plan_.stats_words();
            device_->copy_out(labels.statistics, bytes, Buffer::lut, 4 * size_t(plan_.lut_size()), bytes, 1);
        }
        if (labels.graph.handle != 0) {
            const size_t bytes = 4 * plan_.graph_words();
            device_->copy_out(labels.graph, bytes, Buffer::fill, 0, bytes, 1);
        }
        if (labels.tracks.handle != 0) {
            const size_t bytes = 4 * plan_.track_list_words();
            device_->copy_out(labels.tracks, bytes, Buffer::fill, 4 * size_t(track_header_word()), bytes, 1);
        }
        device_->submit();
        frame_done();
    }

    // The caller's mask travels in the points buffer, which a mask frame does not otherwise use: one word per pixel,
    // bit 0 fillable, bit 1 valid.
    void bind_mask(const MaskView& mask) override {
        start_frame(false);
        const size_t w = size_t(plan_.width);
        const size_t stride = mask.row_stride == 0 ? w : mask.row_stride;
        host_mask_.resize(plan_.pixel_count());
        for (size_t y = 0; y < size_t(plan_.height); ++y) {
            for (size_t x = 0; x < w; ++x) {
                const bool valid = mask.valid == nullptr || mask.valid[y * stride + x] != 0;
                host_mask_[y * w + x] = (mask.fillable[y * stride + x] != 0 ? 1u : 0u) | (valid ? 2u : 0u);
            }
        }
        device_->upload(Buffer::points, 0, host_mask_.data(), 4 * host_mask_.size());
        dispatch(Kernel::bind_mask, pixels(), 1, args({pixels(), plan_.full().offset}));
        from_mask_ = true;
    }

    // A device-resident frame keeps no marks: its times are the caller's to take.
    void begin_pass(const char* pass) override {
        if (!device_frame_) device_->mark(pass);
    }

    void estimate_normals() override {
        if (plan_.params.metric == Metric::robust) {
            dispatch(Kernel::robust_texels, width(), height(),
                     args({height(), uint32_t(plan_.params.normal_radius), bits(plan_.thresholds.point_scale)}));
            dispatch(Kernel::normals_robust, width(), height(),
                     args({height(), uint32_t(plan_.params.normal_window), bits(plan_.thresholds.point_scale)}));
            return;
        }
        dispatch(Kernel::normals, width(), height(), args({height(), uint32_t(plan_.params.normal_radius)}));
    }

    void quantize() override { dispatch(Kernel::quantize, pixels(), 1, args({pixels()})); }

    void metric() override {
        const core::Thresholds t = plan_.thresholds;
        if (plan_.params.metric == Metric::robust) {
            dispatch(Kernel::metric_robust, width(), height(),
                     args({height(), plan_.full().offset, uint32_t(plan_.params.curvature_stride),
                           bits(t.curvature_base), bits(t.curvature_growth), bits(t.depth), bits(t.depth_growth)}));
            return;
        }
        dispatch(Kernel::metric, width(), height(),
                 args({height(), plan_.full().offset, bits(t.curvature), bits(t.depth)}));
    }

    void mip(int parent_level) override {
        const PyrLevel p = plan_.level(parent_level);
        const PyrLevel c = plan_.level(parent_level + 1);
        dispatch(Kernel::mip, p.width, p.height, args({p.width, p.height, p.offset, c.width, c.height, c.offset}));
    }

    void init_labels(int level, uint32_t mode) override {
        const PyrLevel l = plan_.level(level);
        const PyrLevel p = level > 1 ? plan_.level(level - 1) : PyrLevel{0, 0, 0};
        dispatch(Kernel::init_labels, l.width, l.height,
                 args({l.width, l.height, l.offset, p.width, p.height, p.offset, mode}));
    }

    // Steps 2 and 4: the fixed point directly, by union-find over the components of eligible texels (shaders/pyr_uf.h),
    // in five dispatches whatever the mask, with no host synchronisation.
    void fill_to_fixed_point(int level, uint32_t anchor_max) override {
        const PyrLevel l = plan_.level(level);
        const uint32_t n = l.width * l.height;
        if (anchor_max != 0) dispatch(Kernel::anchor, n, 1, args({l.offset, n, anchor_max}));
        dispatch(Kernel::uf_init, l.height, 1, args({l.width, l.height, l.offset, n}));
        dispatch(Kernel::uf_merge, l.width, l.height, args({l.width, l.height, l.offset, n}));
        dispatch(Kernel::uf_flatten, l.width, l.height, args({l.width, l.height, l.offset, n}));
        dispatch(Kernel::uf_resolve, l.width, l.height, args({l.width, l.height, l.offset, n}));
        dispatch(Kernel::uf_gather, n, 1, args({l.offset, n}));
    }

    // Steps 5 and 6a in one workgroup per row, then 6b in one per strip of 32 columns (shaders/pyr_entries.h:
    // final_lines, a segmented scan along each line).
    void final_fill(int level) override {
        const PyrLevel l = plan_.level(level);
        const PyrLevel p = plan_.level(level - 1);
        constexpr uint32_t kStrip = PYR_SCAN_STRIP;
        dispatch(Kernel::final_lines, l.height, 1,
                 args({l.width, l.height, l.offset, p.width, p.height, p.offset, 1u}));
        dispatch(Kernel::final_lines, (l.width + kStrip - 1) / kStrip, 1,
                 args({l.width, l.height, l.offset, p.width, p.height, p.offset, 0u}));
    }

    void label_edges() override {
        const auto rounds = uint32_t(plan_.params.edge_rounds);
        const uint32_t step = bits(plan_.thresholds.edge_depth_step);
        for (uint32_t round = 1; round <= rounds; ++round) {
            dispatch(Kernel::edges, width(), height(), args({height(), plan_.full().offset, round, rounds, step}));
        }
    }

    void merge_segments() override {
        const core::Thresholds& t = plan_.thresholds;
        const uint32_t labels = plan_.lut_size();
        const uint32_t slots = plan_.merge_slots;
        const uint32_t words = labels + PYR_MERGE_SLOT_WORDS * slots;
        dispatch(Kernel::merge_clear, words, 1, args({words, labels}));
        dispatch(Kernel::merge_count, width(), height(),
                 args({height(), plan_.full().offset, uint32_t(plan_.params.merge_reach), bits(t.merge_point_scale),
                       bits(t.merge_tolerance_base), bits(t.merge_tolerance_growth), labels, slots - 1}));
        dispatch(Kernel::merge_link, slots, 1,
                 args({labels, slots, uint32_t(plan_.params.merge_min_crossings), t.merge_share}));
        dispatch(Kernel::merge_flatten, labels, 1, args({labels}));
        dispatch(Kernel::merge_apply, pixels(), 1, args({pixels(), plan_.full().offset}));
    }

    void compact(bool apply) override {
        const uint32_t count = plan_.lut_size();
        const uint32_t chunks = plan_.scan_chunks();
        device_->zero(Buffer::lut, 0, 4 * size_t(count));
        dispatch(Kernel::lut_mark, pixels(), 1, args({pixels(), plan_.full().offset}));
        dispatch(Kernel::scan_count, chunks, 1, args({count, PYR_SCAN_CHUNK, chunks}));
        dispatch(Kernel::scan_sums, 1, 1, args({chunks}));
        dispatch(Kernel::scan_number, chunks, 1, args({count, PYR_SCAN_CHUNK, chunks}));
        dispatch(Kernel::compact, pixels(), 1, args({pixels(), plan_.full().offset, apply ? 1u : 0u}));
        if (!device_frame_) device_->download(Buffer::sums, 4 * size_t(chunks), &segment_count_, 4);
    }

    // K is known on the device only: every slot is cleared, and read_back fetches the K used (a device frame's
    // go to the caller's statistics buffer, write_device_labels).
    void segment_stats() override {
        device_->zero(Buffer::lut, 4 * size_t(plan_.lut_size()), 4 * plan_.stats_words());
        const uint32_t runs = plan_.stats_runs_per_row() * height();
        dispatch(Kernel::stats, runs, 1,
                 args({height(), plan_.full().offset, runs, from_mask_ ? 0u : 1u, bits(plan_.stats_point_scale()),
                       plan_.lut_size(), plan_.stats_slots}));
    }

    // The graph's table and list in the fill buffer, which nothing needs after the merge, sized for K on the device
    // (pyr_graph_slots); read_back fetches the pair count with the labels, then the pairs (a device frame's go to
    // the caller's graph buffer, write_device_labels).
    void segment_graph() override {
        const core::Thresholds& t = plan_.thresholds;
        const uint32_t k_word = plan_.scan_chunks();
        const uint32_t max_slots = plan_.graph_slots;
        const uint32_t flags =
            (from_mask_ ? 0u : 1u) | (plan_.params.compact ? 2u : 0u) | (uint32_t(plan_.params.merge_reach) << 8);
        dispatch(Kernel::graph_clear, 1 + PYR_GRAPH_SLOT_WORDS * max_slots, 1, args({k_word, max_slots}));
        dispatch(Kernel::graph_count, width(), height(),
                 args({height(), plan_.full().offset, flags, k_word, bits(t.merge_point_scale),
                       bits(t.merge_tolerance_base), bits(t.merge_tolerance_growth), max_slots}));
        dispatch(Kernel::graph_gather, max_slots, 1, args({k_word, max_slots}));
    }

    // Tracks' overlaps (shaders/pyr_track.h) in the fill buffer after the graph's words, in the slots the previous
    // frame's K and this frame's need, then gathered after the header; the device keeps K for the next frame, so
    // that device frames need no host in between. read_back fetches the header with the labels, then the pairs (a
    // device frame's go to the caller's tracks buffer, write_device_labels). The dispatches cover the slots of the
    // largest K' and K the host cannot rule out; the kernels use those the device's K' and K need.
    void track_overlaps() override {
        const uint32_t k_word = plan_.scan_chunks();
        const uint32_t max_slots = plan_.track_slots;
        const uint32_t table = track_table_word();
        const uint32_t has_previous = stream_started_ ? 1u : 0u;
        const uint32_t allowed = pyr_track_slots(previous_bound_, plan_.stats_slots, max_slots);
        const Args common = args({k_word, has_previous, max_slots, table, pixels()});
        dispatch(Kernel::track_clear, PYR_TRACK_SLOT_WORDS * allowed, 1, common);
        const uint32_t runs = plan_.stats_runs_per_row() * height();
        dispatch(Kernel::track_count, runs, 1,
                 args({height(), runs, k_word, has_previous, max_slots, table, pixels()}));
        dispatch(Kernel::track_gather, allowed, 1, common);
        dispatch(Kernel::track_advance, 1, 1, common);
        // The host knows K once a host frame is read back; until then (a device frame) any K' is possible.
        previous_bound_ = plan_.stats_slots;
        stream_started_ = true;
    }
    void forget_previous_labels() override {
        previous_bound_ = 0;
        stream_started_ = false;
    }
    [[nodiscard]] const uint32_t* track_pairs(uint32_t& count) const override {
        count = track_pairs_;
        return host_tracks_.data();
    }
    [[nodiscard]] std::optional<uint32_t> track_frame() const override { return track_header_[PYR_TRACK_FRAME]; }

    void read_back(Result& out, const Outputs& outputs) override {
        device_->mark("download");
        const size_t px = plan_.pixel_count();
        const size_t full = plan_.full().offset;
        const size_t texel = limits_.mask_texel_bytes;
        using S = StagedResults;
        unsigned char* staged = staged_.data();
        device_->download(Buffer::out, 0, staged + S::kLabels * px, 4 * px);
        if (outputs.raw_labels) device_->download(Buffer::labels, 4 * full, staged + S::kRawLabels * px, 4 * px);
        if (outputs.fillable_mask) device_->download(Buffer::mask, texel * full, staged + S::kMask * px, texel * px);
        if (outputs.normals && !from_mask_) device_->download(Buffer::normals, 0, staged + S::kNormals * px, 12 * px);
        graph_count_ = 0;
        if (plan_.graph_slots != 0) device_->download(Buffer::fill, 0, &graph_count_, 4);
        track_header_ = {};
        if (plan_.track_slots != 0)
            device_->download(Buffer::fill, 4 * size_t(track_header_word()), track_header_.data(),
                              sizeof track_header_);
        device_->mark(nullptr);
        finish();
        frame_done();
        out.width = plan_.width;
        out.height = plan_.height;
        out.segment_count = segment_count_;
        unstage_results(staged, px, texel == 4, outputs, !from_mask_, out);
        out.segments.clear();
        out.graph.clear();
        // The statistics of the K segments and the pairs the graph gathered, now that both counts are known: one
        // more wait.
        const size_t stats_words =
            plan_.stats_slots == 0 ? 0 : std::min(plan_.stats_words(), size_t(segment_count_) * PYR_STATS_WORDS);
        const uint32_t pairs = std::min(graph_count_, plan_.graph_slots / 2);
        if (stats_words != 0)
            device_->download(Buffer::lut, 4 * size_t(plan_.lut_size()), host_stats_.data(), 4 * stats_words);
        if (pairs != 0) {
            const size_t list = 1 + size_t(PYR_GRAPH_SLOT_WORDS) * pyr_graph_slots(segment_count_, plan_.graph_slots);
            device_->download(Buffer::fill, 4 * list, host_graph_.data(), 4 * size_t(PYR_GRAPH_SLOT_WORDS) * pairs);
        }
        // The tracks' gathered pairs; the executor's labels are the previous frame's from now on, and their K known.
        track_pairs_ = std::min(track_header_[PYR_TRACK_PAIRS], plan_.track_pair_capacity());
        if (track_pairs_ != 0) {
            const size_t words = size_t(PYR_TRACK_SLOT_WORDS) * track_pairs_;
            if (host_tracks_.size() < words) host_tracks_.resize(words);  // grows with the most pairs a frame had
            device_->download(Buffer::fill, 4 * (size_t(track_header_word()) + PYR_TRACK_HEADER_WORDS),
                              host_tracks_.data(), 4 * words);
        }
        if (plan_.track_slots != 0) previous_bound_ = segment_count_;
        // The same waits whatever the graph and the tracks hold.
        if (stats_words != 0 || plan_.graph_slots != 0 || plan_.track_slots != 0) finish();
        if (plan_.stats_slots != 0)
            core::decode_segment_stats(host_stats_.data(), segment_count_, plan_, !from_mask_, out.segments);
        if (plan_.graph_slots != 0) core::decode_segment_graph(host_graph_.data(), pairs, out.graph);
    }

    bool device_timings(std::vector<PassTiming>& timings) override { return device_->pass_times(timings); }
    [[nodiscard]] Device* gpu_device() override { return device_.get(); }
    [[nodiscard]] uint32_t dispatches() const override { return dispatches_; }
    [[nodiscard]] uint32_t host_syncs() const override { return host_syncs_; }

private:
    void start_frame(bool device_frame) {
        // A frame abandoned by an error may or may not have written new rays: forget what the device holds.
        if (rays_pending_) rays_on_device_.clear();
        rays_pending_ = false;
        device_frame_ = device_frame;
        dispatches_ = 0;
        host_syncs_ = 0;
        device_->begin_frame();
        if (!device_frame_) device_->mark("upload");
    }

    // The frame is on its way (device frames) or done (host frames): what it uploaded is what the device holds.
    void frame_done() {
        if (rays_pending_) rays_on_device_ = host_rays_;
        rays_pending_ = false;
    }

    void set_depth(DepthFormat format, const core::DepthTables& tables) {
        host_rays_.assign(tables.ku.begin(), tables.ku.end());
        host_rays_.insert(host_rays_.end(), tables.kv.begin(), tables.kv.end());
        const size_t offset = 4 * size_t(rays_word());
        const size_t bytes = 4 * host_rays_.size();
        if (device_frame_) {
            // Every device frame carries its own slopes, inline with its commands (W + H floats): it may run long
            // after this call (a recorded command buffer, a CUDA graph replayed later), in any order with other
            // recordings, so it cannot count on what an earlier frame left. It leaves the device state unknown.
            constexpr size_t kChunk = 65536;
            const auto* src = reinterpret_cast<const unsigned char*>(host_rays_.data());
            for (size_t done = 0; done < bytes; done += kChunk)
                device_->upload_inline(Buffer::sums, offset + done, src + done, std::min(kChunk, bytes - done));
            rays_on_device_.clear();
        } else if (host_rays_ != rays_on_device_) {
            device_->upload(Buffer::sums, offset, host_rays_.data(), bytes);
            rays_pending_ = true;
        }
        depth_format_ = format == DepthFormat::u16 ? PYR_DEPTH_U16 : PYR_DEPTH_F32;
        depth_scale_ = tables.scale;
        from_mask_ = false;
    }

    // Where the tracks' table starts in the fill buffer: after the segment graph's words; its header and gathered
    // pairs after the table at its largest.
    [[nodiscard]] uint32_t track_table_word() const { return uint32_t(plan_.graph_words()); }
    [[nodiscard]] uint32_t track_header_word() const {
        return track_table_word() + PYR_TRACK_SLOT_WORDS * plan_.track_slots;
    }

    // Where the ray slopes start in the sums buffer: after the scan's chunk sums and K.
    [[nodiscard]] uint32_t rays_word() const { return plan_.scan_chunks() + 1; }

    void dispatch(Kernel k, uint32_t nx, uint32_t ny, const Args& a) {
        if (nx == 0 || ny == 0) return;
        device_->dispatch(k, nx, ny, a);
        ++dispatches_;
    }

    void finish() {
        device_->finish();
        ++host_syncs_;
    }

    // Packed clouds go straight from the caller's memory; strided ones through staging sized once per Segmenter.
    void upload_xyz(const CloudView& cloud, const float* data, Buffer b, std::vector<float>& staging) {
        const float* src = data;
        if (!is_packed_xyz(cloud)) {
            staging.resize(3 * plan_.pixel_count());
            pack_xyz(cloud, data, staging.data());
            src = staging.data();
        }
        device_->upload(b, 0, src, 12 * plan_.pixel_count());
    }

    [[nodiscard]] uint32_t width() const { return uint32_t(plan_.width); }
    [[nodiscard]] uint32_t height() const { return uint32_t(plan_.height); }
    [[nodiscard]] uint32_t pixels() const { return uint32_t(plan_.pixel_count()); }

    const core::Plan& plan_;
    std::unique_ptr<Device> device_;
    DeviceLimits limits_;
    std::vector<float> host_points_, host_normals_;  // staging for strided clouds
    std::vector<std::uint32_t> host_depth_;          // a depth frame's samples, packed
    std::vector<std::uint32_t> host_color_;          // a frame's colour image, packed
    std::vector<float> host_rays_;                   // its ku then kv
    std::vector<float> rays_on_device_;              // the ku and kv the sums buffer holds (empty: unknown)
    bool rays_pending_ = false;                      // the frame being queued uploads new ones
    bool device_frame_ = false;                      // the frame reads and writes the caller's buffers
    uint32_t depth_format_ = PYR_DEPTH_U16;
    float depth_scale_ = 0;
    std::vector<uint32_t> host_mask_;
    std::vector<unsigned char> staged_;  // the frame's results, laid out as StagedResults
    std::vector<uint32_t> host_stats_;
    std::vector<uint32_t> host_graph_;  // the graph's pairs as gathered
    uint32_t segment_count_ = 0;
    uint32_t graph_count_ = 0;
    std::array<uint32_t, PYR_TRACK_HEADER_WORDS> track_header_{};  // the last host frame's, as the device left it
    std::vector<uint32_t> host_tracks_;                            // its gathered pairs
    uint32_t track_pairs_ = 0;                                     // how many
    uint32_t previous_bound_ = 0;  // the most segments the previous buffer's labels can have
    bool stream_started_ = false;  // a frame was queued since the stream started: the previous buffer holds its labels
    uint32_t dispatches_ = 0;
    uint32_t host_syncs_ = 0;
    bool from_mask_ = false;
};

}  // namespace

const char* kernel_entry_name(Kernel k) {
    return kRows[size_t(k)].entry;
}
const char* kernel_glsl_name(Kernel k) {
    return kRows[size_t(k)].glsl;
}
int kernel_dims(Kernel k) {
    return kRows[size_t(k)].dims;
}
const char* buffer_name(Buffer b) {
    return kBufferNames[size_t(b)];
}

namespace {
// A switch without a default, so that a buffer added to the table without a size does not build (-Wswitch).
size_t buffer_bytes(Buffer b, const core::Plan& plan, const DeviceLimits& limits) {
    const size_t px = plan.pixel_count();
    const size_t texels = size_t(plan.total_texels);
    switch (b) {
        case Buffer::points:  // also a mask frame's input words (4 per pixel)
        case Buffer::normals:
            return 12 * px;
        case Buffer::quant:
            return 8 * px;  // two words per pixel (shaders/pyr_types.h: pyr_pack_q16)
        case Buffer::mask:
            return limits.mask_texel_bytes * texels;
        case Buffer::labels:
            return 4 * texels;
        case Buffer::lut:
            return 4 * (size_t(plan.lut_size()) + plan.stats_words());  // then the statistics words
        case Buffer::sums:
            // The scan's chunk sums, K, then the depth frames' ray slopes (W + H floats).
            return 4 * (size_t(plan.scan_chunks()) + 1 + size_t(plan.width) + size_t(plan.height));
        case Buffer::fill: {
            // The fills' parents and minima, for the largest level a fill runs on (N - 1, or N in the fallback).
            // The merge's label parents and pair table (shaders/pyr_merge_table.h) reuse it after the fills.
            const PyrLevel& fill_level = plan.small_image ? plan.full() : plan.level(plan.level_count - 1);
            // So do the segment graph's table and list (shaders/pyr_graph.h), after compaction, and the tracks'
            // table after them (shaders/pyr_track.h).
            const size_t merge = size_t(plan.lut_size()) + size_t(PYR_MERGE_SLOT_WORDS) * plan.merge_slots;
            const size_t tracks = plan.track_words();
            return 4 * std::max({size_t(2) * fill_level.width * fill_level.height, plan.merge_slots != 0 ? merge : 0,
                                 plan.graph_words() + tracks});
        }
        case Buffer::out:
            return 4 * px;
        case Buffer::texels:
            // The robust normals' texels (shaders/pyr_robust.h), only for the robust metric.
            return plan.params.metric == Metric::robust ? 4 * size_t(PYR_TEXEL_WORDS) * px : 0;
        case Buffer::color:
            return (3 * px + 3) / 4 * 4;  // R, G, B per pixel, whole words
        case Buffer::previous:
            return plan.track_slots != 0 ? 4 * (px + 2) : 0;  // then their K and frame (shaders/pyr_entries.h)
        case Buffer::count:
            break;
    }
    throw Error(ErrorCode::internal, "no size for GPU buffer " + std::to_string(uint32_t(b)));
}
}  // namespace

BufferSizes buffer_sizes(const core::Plan& plan, const DeviceLimits& limits) {
    BufferSizes s{};
    for (size_t b = 0; b < kBufferCount; ++b) s[b] = std::max<size_t>(buffer_bytes(Buffer(b), plan, limits), 4);
    return s;
}

void check_fits(const core::Plan& plan, const BufferSizes& sizes, const DeviceLimits& limits,
                const std::string& device) {
    const auto mib = [](size_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; };
    const std::string image = "a " + std::to_string(plan.width) + " x " + std::to_string(plan.height) + " image";
    size_t total = 0;
    for (size_t b = 0; b < kBufferCount; ++b) {
        total += sizes[b];
        if (sizes[b] > limits.max_buffer_bytes[b]) {
            std::string message = image;
            message += " needs a ";
            message += buffer_name(Buffer(b));
            message += " buffer of " + mib(sizes[b]) + " but ";
            message += device;
            message += " takes at most " + mib(limits.max_buffer_bytes[b]) + " there (" + limits.max_buffer_what + ")";
            throw Error(ErrorCode::out_of_memory, message);
        }
    }
    if (total > limits.memory_bytes) {
        throw Error(ErrorCode::out_of_memory, image + " needs " + mib(total) + " of buffers but " + device + " has " +
                                                  mib(limits.memory_bytes) + " (" + limits.memory_what + ")");
    }
}

std::unique_ptr<core::PassExecutor> make_gpu_executor(const core::Plan& plan, std::unique_ptr<Device> device) {
    return std::make_unique<GpuExecutor>(plan, with_fault_plan(std::move(device)));
}

namespace {
[[noreturn]] void no_device_buffers(const Device& device) {
    throw Error(ErrorCode::invalid_argument, device.description() +
                                                 " was not made on a caller's context: it takes no device buffers "
                                                 "(make the Segmenter with pyrseg/opencl.hpp, vulkan.hpp or cuda.hpp)");
}
}  // namespace

void Device::copy_in(Buffer /*dst*/, size_t /*offset*/, const core::ExternalBuffer& /*src*/, size_t /*pitch*/,
                     size_t /*row_bytes*/, size_t /*rows*/) {
    no_device_buffers(*this);
}
void Device::copy_out(const core::ExternalBuffer& /*dst*/, size_t /*pitch*/, Buffer /*src*/, size_t /*offset*/,
                      size_t /*row_bytes*/, size_t /*rows*/) {
    no_device_buffers(*this);
}
void Device::upload_inline(Buffer /*b*/, size_t /*offset*/, const void* /*src*/, size_t /*bytes*/) {
    no_device_buffers(*this);
}
void Device::submit() {
    no_device_buffers(*this);
}
void Device::fail_like(Fault fault, const char* what) const {
    throw Error(ErrorCode::internal, description() + ": " + what + " failed: " + fault_name(fault) +
                                         " (this backend cannot fail in its API's words)");
}

const char* fault_name(Fault f) {
    return f == Fault::out_of_memory ? "out of memory" : "device lost";
}

}  // namespace pyrseg::gpu
