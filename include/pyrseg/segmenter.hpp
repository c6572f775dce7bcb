#pragma once
// A Segmenter is created once for a backend and a resolution, then segments frame after frame without
// allocating (after the first frame has sized the Result it is given).
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "pyrseg/cloud.hpp"
#include "pyrseg/depth.hpp"
#include "pyrseg/export.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"

namespace pyrseg {

namespace core {
struct SegmenterAccess;  // the library's own access to a Segmenter's insides (core/segmenter_impl.hpp)
}

struct PassTiming {
    // "depth" (a DepthView's back-projection), "normals", "quantize", "metric" (or "points_to_mask": the three as one
    // pass, on a backend that fuses them), "color", "mip", "labels", "fill", "final_fill", "edges", "merge",
    // "compact", "stats", "graph", "tracks", then "upload" (the frame to the backend), "download" (the results
    // back) and, with tracks, "track_matching" (on the host, docs/algorithm.md section 11).
    const char* pass;
    double milliseconds;
};

class PYRSEG_EXPORT Segmenter {
public:
    // backend: one of backend_names() (pyrseg/backend.hpp), "auto", or empty for $PYRSEG_BACKEND (else "auto").
    // Throws pyrseg::Error for invalid parameters, sizes that do not fit, or an unavailable backend.
    Segmenter(int width, int height, const Params& params = {}, std::string_view backend = {},
              const Outputs& outputs = {});
    // A Segmenter on the caller's own GPU context: made by the interop functions (pyrseg/opencl.hpp,
    // pyrseg/vulkan.hpp, pyrseg/cuda.hpp), not directly.
    struct Impl;
    explicit Segmenter(std::unique_ptr<Impl> impl);
    ~Segmenter();
    Segmenter(Segmenter&&) noexcept;
    Segmenter& operator=(Segmenter&&) noexcept;
    Segmenter(const Segmenter&) = delete;
    Segmenter& operator=(const Segmenter&) = delete;

    // Segments one frame into `out`. The frame must have the Segmenter's size.
    void segment(const CloudView& cloud, Result& out);
    [[nodiscard]] Result segment(const CloudView& cloud);
    // Segments a depth image, back-projected on the device (docs/algorithm.md section 1b) into points in the
    // Segmenter's unit_mm; normals are estimated. Throws pyrseg::Error for bad metres_per_unit or intrinsics.
    void segment(const DepthView& depth, Result& out);
    [[nodiscard]] Result segment(const DepthView& depth);
    // Labels a caller-made fillable mask (the pyramid without the normals and metric passes).
    void segment_mask(const MaskView& mask, Result& out);

    // With Outputs::segment_tracks, the next frame starts a new stream: no track carries over into it.
    void reset_tracks();

    // Every member of a moved-from Segmenter throws pyrseg::Error (ErrorCode::invalid_argument); only destroying it
    // or assigning another to it are allowed.
    [[nodiscard]] int width() const;
    [[nodiscard]] int height() const;
    [[nodiscard]] const Params& params() const;
    [[nodiscard]] const std::string& backend_name() const;
    // Host wall time of each pass of the last frame, in pass order (accumulated per pass name).
    [[nodiscard]] const std::vector<PassTiming>& last_timings() const;
    // Rounds of row and column sweeps the fixed-point fills of the last frame took; 0 for the union-find fills every
    // backend uses (only the CPU's PYRSEG_CPU_FILL=sweeps, kept as a cross-check, sweeps).
    [[nodiscard]] std::uint32_t last_fill_rounds() const;
    // What the last frame cost a GPU backend besides its kernels: the dispatches (kernel launches) it queued, and
    // the times the host waited for the device (1 per frame; 2 with Outputs::segment_stats, segment_graph or
    // segment_tracks, whose words are fetched once the segment count and the graph's pair count are known). Neither
    // depends on the image's content. Both 0 on the CPU backend.
    [[nodiscard]] std::uint32_t last_dispatches() const;
    [[nodiscard]] std::uint32_t last_host_syncs() const;

    // Device-resident frames (pyrseg/cuda.hpp, vulkan.hpp, opencl.hpp) of a Segmenter made with
    // Outputs::segment_stats write the statistics' words into the caller's statistics buffer, on the device, with
    // the labels: this many bytes (0 without Outputs::segment_stats). Once the frame is done and the caller has the
    // words and K on the host (the first K slots suffice), decode_device_statistics gives Result::segments as a host
    // frame would (docs/algorithm.md sections 10 and 10b). Throws pyrseg::Error when the Segmenter has no
    // statistics or `count` is more than its slots.
    [[nodiscard]] std::size_t device_statistics_bytes() const;
    void decode_device_statistics(const std::uint32_t* words, std::uint32_t count,
                                  std::vector<SegmentStats>& out) const;
    // The same for the segment graph: device frames of a Segmenter made with Outputs::segment_graph write the graph's
    // words into the caller's graph buffer, this many bytes of them (0 without Outputs::segment_graph); with the
    // words and K on the host, decode_device_segment_graph gives Result::graph as a host frame would (section 10d).
    // Throws pyrseg::Error when the Segmenter has no graph, `words` is null or `count` is more than its labels.
    [[nodiscard]] std::size_t device_segment_graph_bytes() const;
    void decode_device_segment_graph(const std::uint32_t* words, std::uint32_t count,
                                     std::vector<SegmentEdge>& out) const;
    // Tracks on device frames: a Segmenter made with Outputs::segment_tracks or track_ids writes each device frame's
    // overlaps with the previous frame into the caller's tracks buffer, this many bytes at most (0 without tracks),
    // and keeps the frame's labels, K and number in the stream on the device for the next frame, so that frames queued
    // back to back, or recorded once and run many times, follow one another (a frame recorded as a stream's first,
    // after reset_tracks or the Segmenter's first, starts a stream each time it runs). The host then matches them,
    // frame by frame in the order they ran: decode_device_tracks(words, segments, tracks) gives Result::tracks as a
    // host frame would (docs/algorithm.md section 11), `segments` the frame's statistics (decode_device_statistics)
    // and `words` the buffer's first PYR_TRACK_HEADER_WORDS + 3 * words[3] words (the header, then the pairs).
    // Throws pyrseg::Error when the Segmenter has no tracks, `words` is null, the words are not those of the stream's
    // next frame to decode (skipped, repeated or out of order; reset_tracks starts a new stream) or `segments` does
    // not hold the frame's K. A host frame after device frames not all decoded is an error too.
    [[nodiscard]] std::size_t device_tracks_bytes() const;
    void decode_device_tracks(const std::uint32_t* words, const std::vector<SegmentStats>& segments,
                              std::vector<SegmentTrack>& out);

private:
    friend struct core::SegmenterAccess;
    std::unique_ptr<Impl> impl_;
};

}  // namespace pyrseg
