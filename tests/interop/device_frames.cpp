// The checks every GPU API's interop passes, once per adapter (device_frames.hpp): device-resident frames give the
// host path's labels and segment count byte for byte (clouds with and without normals, both metrics, padded rows,
// data from an offset into its buffer, depth images u16 and f32 with odd row steps and intrinsics that change
// between frames), several queued back to back before any is read, host and device frames alternating on one
// Segmenter; bad input is a pyrseg::Error that queues and writes nothing, after which the Segmenter still segments.
#include "interop/device_frames.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>

#include "pyrseg/presets.hpp"
#include "pyrseg/synthetic.hpp"
#include "shaders/pyr_types.h"
#include "support/oracle.hpp"

namespace pyrseg::test {

Region put(Adapter& api, const void* data, std::size_t bytes, std::size_t at) {
    const int buffer = api.allocate(at + bytes);
    api.upload(buffer, at, data, bytes);
    return {buffer, at};
}

std::vector<std::uint32_t> words(Adapter& api, int buffer, std::size_t offset, std::size_t count) {
    const std::vector<unsigned char> bytes = api.download(buffer, offset, 4 * count);
    std::vector<std::uint32_t> out(count);
    std::memcpy(out.data(), bytes.data(), bytes.size());
    return out;
}

std::vector<unsigned char> pitched(const void* packed, int width, int height, std::size_t item, std::size_t pitch) {
    std::vector<unsigned char> out(pitch * std::size_t(height), 0xCD);
    for (int y = 0; y < height; ++y) {
        std::memcpy(out.data() + std::size_t(y) * pitch,
                    static_cast<const unsigned char*>(packed) + std::size_t(y) * std::size_t(width) * item,
                    std::size_t(width) * item);
    }
    return out;
}

std::vector<std::uint32_t> unpitch(const unsigned char* bytes, int width, int height, std::size_t pitch) {
    std::vector<std::uint32_t> out(std::size_t(width) * std::size_t(height));
    for (int y = 0; y < height; ++y) {
        std::memcpy(out.data() + std::size_t(y) * std::size_t(width), bytes + std::size_t(y) * pitch,
                    4 * std::size_t(width));
    }
    return out;
}

Wall::Wall() : points(3 * kPixels) {
    for (std::size_t i = 0; i < kPixels; ++i) {
        points[3 * i] = float(2 * int(i % kWidth) - kWidth);
        points[3 * i + 1] = float(2 * int(i / kWidth) - kHeight);
        points[3 * i + 2] = 1000.0f;
    }
}

Refusals::Refusals(Adapter& adapter)
    : api(adapter),
      segmenter(api.make_segmenter(Wall::kWidth, Wall::kHeight, {})),
      cloud{put(api, wall.points.data(), 4 * wall.points.size()), {}, 0},
      depth{put(api, wall.depth.data(), 2 * wall.depth.size()), wall.view} {
    out.labels = put(api, wall.sentinel.data(), 4 * wall.sentinel.size());
    out.count = put(api, wall.sentinel.data(), 4);
}

void Refusals::expect(Segmenter& s, const Frame& frame, const std::string& words, ErrorCode code) {
    const std::vector<Way> ways = api.ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        SCOPED_TRACE(ways[way].name);
        expect_error([&] { api.run(s, std::span(&frame, 1), way); }, words, code);
        expect_untouched();
    }
}

void Refusals::expect_untouched() {
    EXPECT_EQ(test::words(api, out.labels.buffer, 0, Wall::kPixels), wall.sentinel) << "the labels buffer was written";
    EXPECT_EQ(test::words(api, out.count.buffer, 0, 1)[0], Wall::kSentinel) << "the count was written";
}

void Refusals::expect_still_segments() {
    const std::vector<Way> ways = api.ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        SCOPED_TRACE(ways[way].name);
        for (const Frame& f : {Frame{cloud, out}, Frame{depth, out}}) {
            api.upload(out.count.buffer, 0, wall.sentinel.data(), 4);
            api.run(segmenter, std::span(&f, 1), way);
            EXPECT_EQ(test::words(api, out.count.buffer, 0, 1)[0], 1u) << "a flat wall at 1 m: one segment";
        }
    }
}

namespace {

constexpr std::uint32_t kUntouched = 0xABABABABu;  // what the adapter's buffers hold before anything writes them

struct Scene {
    const char* what = "";
    int width = 0;
    int height = 0;
    synthetic::Sensor sensor = synthetic::Sensor::structured_light;
    bool normals = false;
    Params params;
    std::size_t cloud_pad = 0;   // extra bytes per row of points
    std::size_t labels_pad = 0;  // extra bytes per row of labels
};

const Scene kScenes[] = {
    {"paper metric, estimated normals, packed", 131, 97, synthetic::Sensor::structured_light, false, Params{}, 0, 0},
    {"given normals, padded rows", 67, 45, synthetic::Sensor::structured_light, true, Params{}, 20, 12},
    {"kinect-v1 preset (robust metric), padded", 101, 77, synthetic::Sensor::kinect_v1, false,
     sensor_preset(SensorKind::kinect_v1), 4, 4},
    {"a thin strip", 57, 9, synthetic::Sensor::structured_light, false, Params{}, 8, 0},
};

}  // namespace

TEST_P(DeviceFrames, CloudFramesMatchTheHostPath) {
    const std::vector<Way> ways = api().ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        for (const Scene& s : kScenes) {
            SCOPED_TRACE(ways[way].name + ": " + s.what);
            synthetic::SceneOptions o;
            o.width = s.width;
            o.height = s.height;
            o.sensor = s.sensor;
            const synthetic::Scene scene = synthetic::generate(o);
            CloudView view;
            view.points = scene.points.data();
            view.normals = s.normals ? scene.normals.data() : nullptr;
            view.width = s.width;
            view.height = s.height;
            Segmenter cpu(s.width, s.height, s.params, "cpu");
            const Result expected = cpu.segment(view);
            ASSERT_GT(expected.segment_count, 0u);

            const std::size_t cloud_pitch = 12 * std::size_t(s.width) + s.cloud_pad;
            const std::size_t labels_pitch = 4 * std::size_t(s.width) + s.labels_pad;
            const std::size_t labels_bytes = labels_pitch * std::size_t(s.height);
            const auto points = pitched(scene.points.data(), s.width, s.height, 12, cloud_pitch);
            const auto normals = pitched(scene.normals.data(), s.width, s.height, 12, cloud_pitch);
            Segmenter segmenter = api().make_segmenter(s.width, s.height, s.params);
            EXPECT_EQ(segmenter.backend_name(), api().backend_name());
            CloudFrame in;
            in.points = put(points.data(), points.size(), 16);  // data need not start at the buffer's start
            if (s.normals) in.normals = put(normals.data(), normals.size());
            in.row_step_bytes = s.cloud_pad == 0 ? 0 : cloud_pitch;

            // Five frames into five label buffers from byte 8 on (K into the first and last), all queued before
            // anything is read: the later ones reuse pyrseg's buffers after the earlier ones, in queue order, and
            // a ring of pyrseg's command buffers comes round.
            constexpr std::size_t kFrames = 5;
            std::vector<Frame> frames;
            std::vector<int> counts;
            for (std::size_t f = 0; f < kFrames; ++f) {
                LabelFrame out;
                out.labels = {api().allocate(labels_bytes + 8), 8};
                out.row_step_bytes = s.labels_pad == 0 ? 0 : labels_pitch;
                counts.push_back(api().allocate(16));
                if (f == 0 || f + 1 == kFrames) out.count = {counts.back(), 8};
                frames.push_back({in, out});
            }
            api().run(segmenter, frames, way);
            EXPECT_TRUE(segmenter.last_timings().empty());
            for (std::size_t f = 0; f < kFrames; ++f) {
                SCOPED_TRACE("frame " + std::to_string(f));
                const int labels = frames[f].out.labels.buffer;
                const auto bytes = api().download(labels, 0, labels_bytes + 8);
                EXPECT_TRUE(same_bytes("labels", unpitch(bytes.data() + 8, s.width, s.height, labels_pitch),
                                       expected.labels, s.width));
                EXPECT_EQ(words(labels, 4, 1)[0], kUntouched) << "written before the offset";
                if (s.labels_pad != 0) {
                    EXPECT_EQ(words(labels, 8 + 4 * std::size_t(s.width), 1)[0], kUntouched)
                        << "written in a row's padding";
                }
                const std::uint32_t count = words(counts[f], 8, 1)[0];
                if (frames[f].out.count.buffer != Region::kNone) {
                    EXPECT_EQ(count, expected.segment_count);
                } else {
                    EXPECT_EQ(count, kUntouched) << "K written without a count buffer";
                }
            }
            // The same Segmenter's host path, on the application's queue, then a device frame again.
            const Result host = segmenter.segment(view);
            EXPECT_TRUE(same_bytes("host path labels", host.labels, expected.labels, s.width));
            EXPECT_EQ(host.segment_count, expected.segment_count);
            const std::vector<unsigned char> blank(labels_bytes + 8, 0xAB);
            api().upload(frames[0].out.labels.buffer, 0, blank.data(), blank.size());
            api().run(segmenter, std::span(frames).first(1), way);
            const auto bytes = api().download(frames[0].out.labels.buffer, 8, labels_bytes);
            EXPECT_TRUE(same_bytes("labels after a host frame", unpitch(bytes.data(), s.width, s.height, labels_pitch),
                                   expected.labels, s.width));
        }
    }
}

TEST_P(DeviceFrames, DepthFramesMatchTheHostPath) {
    synthetic::SceneOptions o;
    o.width = 93;
    o.height = 61;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene scene = synthetic::generate(o);
    const int w = o.width;
    const int h = o.height;
    std::vector<std::uint16_t> u16(std::size_t(w) * std::size_t(h));
    std::vector<float> f32(u16.size());
    for (std::size_t i = 0; i < u16.size(); ++i) {
        const float z = scene.points[3 * i + 2];
        u16[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
        f32[i] = i % 53 == 1 ? -z : z * 0.001f;  // metres; NaN and negative samples are missing data
    }
    const Params params = sensor_preset(SensorKind::kinect_v1);
    Segmenter cpu(w, h, params, "cpu");
    struct Case {
        const char* what;
        const void* samples;
        DepthFormat format;
        std::size_t sample;
        std::size_t pad;
        std::size_t offset;
        double metres_per_unit;
        double fx_scale;
        double cx_shift;
    };
    const Case cases[] = {
        {"u16 mm, packed", u16.data(), DepthFormat::u16, 2, 0, 0, 0.001, 1.0, 0.3},
        {"u16 mm, rows of 2W+6 bytes, from byte 6", u16.data(), DepthFormat::u16, 2, 6, 6, 0.001, 1.0, 0.3},
        {"f32 m, rows of 4W+12 bytes, other intrinsics", f32.data(), DepthFormat::f32, 4, 12, 8, 1.0, 1.2, 0.3},
        {"u16 mm again, first intrinsics", u16.data(), DepthFormat::u16, 2, 2, 2, 0.001, 1.0, 0.3},
        {"u16 mm, third intrinsics", u16.data(), DepthFormat::u16, 2, 0, 4, 0.001, 0.9, 0.3},
        {"u16 mm, rows of 2W+2 bytes, another cx", u16.data(), DepthFormat::u16, 2, 2, 2, 0.001, 1.0, -1.7},
    };
    // Every frame's buffers first; then, each way, every frame queued before any is read: each frame's ray table
    // goes with its own frame, in queue order, while the frames before may still run.
    std::vector<Frame> frames;
    std::vector<Result> expected;
    std::vector<std::vector<unsigned char>> host_samples;
    for (const Case& c : cases) {
        const std::size_t pitch = c.sample * std::size_t(w) + c.pad;
        host_samples.push_back(pitched(c.samples, w, h, c.sample, pitch));
        const std::vector<unsigned char>& bytes = host_samples.back();
        const DepthView view{
            bytes.data(),          c.format,      w, h, pitch, c.metres_per_unit, scene.fx * c.fx_scale, scene.fy,
            scene.cx + c.cx_shift, scene.cy - 0.2};
        expected.push_back(cpu.segment(view));
        EXPECT_GT(expected.back().segment_count, 1u) << c.what;
        DepthFrame in{put(bytes.data(), bytes.size(), c.offset), view};
        in.view.depth = nullptr;
        LabelFrame out;
        out.labels = {api().allocate(4 * std::size_t(w) * std::size_t(h)), 0};
        out.count = {api().allocate(4), 0};
        frames.push_back({in, out});
    }
    const auto check = [&](const std::string& how, std::size_t i) {
        SCOPED_TRACE(how + ": " + cases[i].what);
        const LabelFrame& out = frames[i].out;
        EXPECT_TRUE(
            same_bytes("labels", words(out.labels.buffer, 0, expected[i].labels.size()), expected[i].labels, w));
        EXPECT_EQ(words(out.count.buffer, 0, 1)[0], expected[i].segment_count);
        const std::vector<unsigned char> blank(api().size(out.labels.buffer), 0xAB);
        api().upload(out.labels.buffer, 0, blank.data(), blank.size());
        api().upload(out.count.buffer, 0, blank.data(), 4);
    };
    Segmenter segmenter = api().make_segmenter(w, h, params);
    const std::vector<Way> ways = api().ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        api().run(segmenter, frames, way);
        for (std::size_t i = 0; i < frames.size(); ++i) check(ways[way].name, i);
        // Host frames and device frames alternate on one Segmenter.
        for (std::size_t i = 0; i < frames.size(); ++i) {
            SCOPED_TRACE(ways[way].name + ", alternating: " + cases[i].what);
            DepthView view = std::get<DepthFrame>(frames[i].in).view;
            view.depth = host_samples[i].data();
            const Result host = segmenter.segment(view);
            EXPECT_TRUE(same_bytes("host labels", host.labels, expected[i].labels, w));
            api().run(segmenter, std::span(frames).subspan(i, 1), way);
            check(ways[way].name + ", alternating", i);
        }
    }
}

// Frames with a colour image on the device (the colour edge term, docs/algorithm.md section 2c): packed and in
// padded rows from an odd offset, a frame without colour between them (nothing of the colour stays), a cloud with
// colour; each as the CPU's host path segments it.
TEST_P(DeviceFrames, ColourFramesMatchTheHostPath) {
    synthetic::SceneOptions o;
    o.width = 87;
    o.height = 59;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene scene = synthetic::generate(o);
    const int w = o.width;
    const int h = o.height;
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    std::vector<std::uint16_t> u16(pixels);
    std::vector<std::uint8_t> rgb(3 * pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        const float z = scene.points[3 * i + 2];
        u16[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
        // Each object its own colour, and a stripe across every object: colour edges inside surfaces too.
        const std::uint32_t id = scene.object_id[i] * 2654435761u + ((i % std::size_t(w)) / 9 % 2 == 0 ? 0x404040u : 0);
        for (std::size_t c = 0; c < 3; ++c) rgb[3 * i + c] = std::uint8_t(id >> (8 * c));
    }
    Params params = sensor_preset(SensorKind::kinect_v1);
    params.color_edge_threshold = 60;
    Segmenter cpu(w, h, params, "cpu");
    DepthView view{u16.data(), DepthFormat::u16, w, h, 0, 0.001, scene.fx, scene.fy, scene.cx, scene.cy};
    const Result plain = cpu.segment(view);
    view.color = rgb.data();
    const Result coloured = cpu.segment(view);
    ASSERT_FALSE(same_bytes("colour changes the labels", plain.labels, coloured.labels, w));
    CloudView cloud;
    cloud.points = scene.points.data();
    cloud.width = w;
    cloud.height = h;
    cloud.color = rgb.data();
    const Result cloud_coloured = cpu.segment(cloud);

    const std::size_t padded_pitch = 3 * std::size_t(w) + 5;
    const std::vector<unsigned char> padded = pitched(rgb.data(), w, h, 3, padded_pitch);
    DepthView device_view = view;
    device_view.depth = nullptr;
    device_view.color = nullptr;
    const Region samples = put(u16.data(), 2 * pixels);
    DepthFrame packed{samples, device_view, put(rgb.data(), rgb.size()), 0};
    DepthFrame rows{samples, device_view, put(padded.data(), padded.size(), 3), padded_pitch};
    DepthFrame none{samples, device_view};
    CloudFrame cloud_in;
    cloud_in.points = put(scene.points.data(), 12 * pixels);
    cloud_in.color = packed.color;
    const auto out = [&] {
        LabelFrame l;
        l.labels = {api().allocate(4 * pixels), 0};
        return l;
    };
    std::vector<Frame> frames = {{packed, out()}, {none, out()}, {rows, out()}, {cloud_in, out()}};
    const std::vector<const Result*> expected = {&coloured, &plain, &coloured, &cloud_coloured};
    const char* what[] = {"depth, packed colour", "depth, no colour", "depth, colour rows of 3W+5 from byte 3",
                          "cloud, packed colour"};
    Segmenter segmenter = api().make_segmenter(w, h, params);
    const std::vector<Way> ways = api().ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        api().run(segmenter, frames, way);
        for (std::size_t i = 0; i < frames.size(); ++i) {
            SCOPED_TRACE(ways[way].name + ": " + what[i]);
            EXPECT_TRUE(same_bytes("labels", words(frames[i].out.labels.buffer, 0, pixels), expected[i]->labels, w));
        }
    }
    // A colour image too short for the frame is refused.
    DepthFrame short_color{samples, device_view, put(rgb.data(), rgb.size() - 1), 0};
    std::vector<Frame> bad = {{short_color, out()}};
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        try {
            api().run(segmenter, bad, way);
            ADD_FAILURE() << ways[way].name << ": a short colour buffer was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("colour image"), std::string::npos) << e.what();
        }
    }
}

TEST_P(DeviceFrames, BadInputIsAnErrorAndQueuesAndWritesNothing) {
    Refusals r(api());
    constexpr int kW = Wall::kWidth;
    const auto cloud_refused = [&](const CloudFrame& c, const LabelFrame& o, const std::string& words) {
        r.expect({c, o}, words);
    };
    CloudFrame c = r.cloud;
    c.points = {api().allocate(4 * r.wall.points.size() - 4), 0};
    cloud_refused(c, r.out, "needs");  // one float short
    c = r.cloud;
    c.points.offset = 8;
    cloud_refused(c, r.out, "needs");  // the offset leaves too little
    c = r.cloud;
    c.row_step_bytes = 12 * kW - 4;
    cloud_refused(c, r.out, "smaller than a row");
    c = r.cloud;
    c.row_step_bytes = 12 * kW + 2;
    cloud_refused(c, r.out, "multiples of 4");
    c = r.cloud;
    c.points = {};
    cloud_refused(c, r.out, "points buffer is missing");
    LabelFrame o = r.out;
    o.row_step_bytes = 4 * kW + 4;  // rows that no longer fit the buffer
    cloud_refused(r.cloud, o, "needs");
    o = r.out;
    o.row_step_bytes = 4 * kW + 2;
    cloud_refused(r.cloud, o, "multiples of 4");
    o = r.out;
    o.labels = {};
    cloud_refused(r.cloud, o, "labels buffer is missing");

    DepthFrame d = r.depth;
    for (const double m : {0.0, -0.001, std::nan(""), double(INFINITY)}) {
        d = r.depth;
        d.view.metres_per_unit = m;
        r.expect({d, r.out}, "metres_per_unit", ErrorCode::invalid_parameter);
    }
    d = r.depth;
    d.view.fx = 0;
    r.expect({d, r.out}, "fx", ErrorCode::invalid_parameter);
    d = r.depth;
    d.view.fy = std::nan("");
    r.expect({d, r.out}, "fy", ErrorCode::invalid_parameter);
    d = r.depth;
    d.view.cx = INFINITY;
    r.expect({d, r.out}, "cx", ErrorCode::invalid_parameter);
    d = r.depth;
    d.view.depth = r.wall.depth.data();
    r.expect({d, r.out}, "must be null");
    d = r.depth;
    d.view.row_step_bytes = 2 * kW + 1;
    r.expect({d, r.out}, "multiples of 2");
    d = r.depth;
    d.view.width = kW - 1;
    r.expect({d, r.out}, "31 x 24", ErrorCode::size_mismatch);

    // Statistics: a buffer for a Segmenter made without them, or one word too small for a Segmenter made with them.
    o = r.out;
    o.statistics = {api().allocate(64), 0};
    cloud_refused(r.cloud, o, "without Outputs::segment_stats");
    Outputs stats;
    stats.segment_stats = true;
    Segmenter with_stats = api().make_segmenter(Wall::kWidth, Wall::kHeight, {}, stats);
    o.statistics = {api().allocate(with_stats.device_statistics_bytes() - 4), 0};
    r.expect(with_stats, {r.cloud, o}, "statistics buffer holds");

    // The segment graph: the same two.
    o = r.out;
    o.graph = {api().allocate(64), 0};
    cloud_refused(r.cloud, o, "without Outputs::segment_graph");
    Outputs graph;
    graph.segment_graph = true;
    Segmenter with_graph = api().make_segmenter(Wall::kWidth, Wall::kHeight, {}, graph);
    o.graph = {api().allocate(with_graph.device_segment_graph_bytes() - 4), 0};
    r.expect(with_graph, {r.cloud, o}, "segment graph buffer holds");

    // Tracks: a buffer for a Segmenter made without them; none, or one word too small, for a Segmenter made with them.
    o = r.out;
    o.tracks = {api().allocate(64), 0};
    cloud_refused(r.cloud, o, "without Outputs::segment_tracks");
    Outputs tracks;
    tracks.segment_tracks = true;
    Segmenter with_tracks = api().make_segmenter(Wall::kWidth, Wall::kHeight, {}, tracks);
    r.expect(with_tracks, {r.cloud, r.out}, "needs a tracks buffer");
    r.expect(with_tracks, {r.depth, r.out}, "needs a tracks buffer");
    o.tracks = {api().allocate(with_tracks.device_tracks_bytes() - 4), 0};
    r.expect(with_tracks, {r.cloud, o}, "tracks buffer holds");

    // A Segmenter on another API.
    Segmenter cpu(Wall::kWidth, Wall::kHeight, {}, "cpu");
    r.expect(cpu, {r.cloud, r.out}, "does not run on");
    r.expect(cpu, {r.depth, r.out}, "does not run on");

    r.expect_still_segments();
}

namespace {

// A kinect-v1 scene as a cloud and as a uint16 depth image in millimetres, each segmented on the CPU (the host
// results device frames must give), and its inputs in the adapter's buffers.
struct HostResults {
    synthetic::Scene scene;
    std::vector<std::uint16_t> depth;
    Params params = sensor_preset(SensorKind::kinect_v1);
    Result from_cloud;
    Result from_depth;
    CloudFrame cloud_in;
    DepthFrame depth_in;
};

HostResults host_results(Adapter& api, const Outputs& outputs) {
    synthetic::SceneOptions o;
    o.width = 96;
    o.height = 72;
    o.sensor = synthetic::Sensor::kinect_v1;
    HostResults h;
    h.scene = synthetic::generate(o);
    h.depth.resize(std::size_t(o.width) * std::size_t(o.height));
    for (std::size_t i = 0; i < h.depth.size(); ++i) {
        const float z = h.scene.points[3 * i + 2];
        h.depth[i] = z > 0 && z < 65535 ? std::uint16_t(z) : 0;
    }
    const DepthView view{h.depth.data(), DepthFormat::u16, o.width,    o.height,   0,
                         0.001,          h.scene.fx,       h.scene.fy, h.scene.cx, h.scene.cy};
    Segmenter cpu(o.width, o.height, h.params, "cpu", outputs);
    h.from_cloud = cpu.segment(CloudView{h.scene.points.data(), nullptr, o.width, o.height});
    h.from_depth = cpu.segment(view);
    h.cloud_in.points = put(api, h.scene.points.data(), 4 * h.scene.points.size(), 0);
    h.depth_in = {put(api, h.depth.data(), 2 * h.depth.size(), 0), view};
    h.depth_in.view.depth = nullptr;
    return h;
}

// Four frames, cloud and depth image in turn, each with its labels and K; `more` adds each frame's other buffers.
std::vector<Frame> alternating_frames(Adapter& api, const HostResults& h,
                                      const std::function<void(LabelFrame&)>& more) {
    std::vector<Frame> frames;
    for (int f = 0; f < 4; ++f) {
        LabelFrame out;
        out.labels = {api.allocate(4 * h.depth.size()), 0};
        out.count = {api.allocate(4), 0};
        more(out);
        frames.push_back(f % 2 == 0 ? Frame{h.cloud_in, out} : Frame{h.depth_in, out});
    }
    return frames;
}

}  // namespace

// The statistics of device frames (a Segmenter made with Outputs::segment_stats): the words go to the caller's buffer
// with the labels, and Segmenter::decode_device_statistics gives the host path's segments from them, field for field;
// a cloud and a depth image, several frames queued before any is read.
TEST_P(DeviceFrames, StatisticsMatchTheHostPath) {
    Outputs outputs;
    outputs.segment_stats = true;
    const HostResults h = host_results(api(), outputs);
    ASSERT_GT(h.from_cloud.segment_count, 2u);
    Segmenter segmenter = api().make_segmenter(h.scene.width, h.scene.height, h.params, outputs);
    const std::size_t bytes = segmenter.device_statistics_bytes();
    ASSERT_GT(bytes, 0u);
    std::vector<Frame> frames = alternating_frames(api(), h, [&](LabelFrame& out) {
        out.statistics = {api().allocate(bytes + 12), 12};
    });
    const std::vector<Way> ways = api().ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        api().run(segmenter, frames, way);
        for (std::size_t f = 0; f < frames.size(); ++f) {
            SCOPED_TRACE(ways[way].name + ", frame " + std::to_string(f));
            const Result& expected = f % 2 == 0 ? h.from_cloud : h.from_depth;
            const std::uint32_t count = words(frames[f].out.count.buffer, 0, 1)[0];
            ASSERT_EQ(count, expected.segment_count);
            EXPECT_EQ(words(frames[f].out.statistics.buffer, 8, 1)[0], kUntouched) << "written before the offset";
            const std::vector<std::uint32_t> stats = words(frames[f].out.statistics.buffer, 12, bytes / 4);
            std::vector<SegmentStats> segments;
            segmenter.decode_device_statistics(stats.data(), count, segments);
            ASSERT_EQ(segments.size(), expected.segments.size());
            for (std::size_t k = 0; k < segments.size(); ++k) {
                const SegmentStats& a = segments[k];
                const SegmentStats& e = expected.segments[k];
                EXPECT_EQ(a.label, e.label);
                EXPECT_EQ(a.pixel_count, e.pixel_count);
                EXPECT_EQ(a.fillable_count, e.fillable_count);
                EXPECT_EQ(a.point_sum, e.point_sum);
                EXPECT_EQ(a.normal_sum, e.normal_sum);
                EXPECT_EQ(a.point_product_sum, e.point_product_sum);
                EXPECT_EQ(a.plane_normal, e.plane_normal);
                EXPECT_EQ(a.extents, e.extents);
                EXPECT_EQ(a.planar, e.planar);
            }
            std::vector<unsigned char> blank(bytes, 0xAB);
            api().upload(frames[f].out.statistics.buffer, 12, blank.data(), blank.size());
        }
    }
    std::vector<SegmentStats> none;
    EXPECT_THROW(segmenter.decode_device_statistics(nullptr, 1u << 30, none), Error);
    Segmenter without = api().make_segmenter(h.scene.width, h.scene.height, h.params);
    EXPECT_EQ(without.device_statistics_bytes(), 0u);
}

// The segment graph of device frames (a Segmenter made with Outputs::segment_graph, here beside the statistics): its
// words go to the caller's buffer with the labels, and Segmenter::decode_device_segment_graph gives the host path's
// graph from them, edge for edge; a cloud and a depth image, several frames queued before any is read.
TEST_P(DeviceFrames, SegmentGraphMatchesTheHostPath) {
    Outputs outputs;
    outputs.segment_stats = true;
    outputs.segment_graph = true;
    const HostResults h = host_results(api(), outputs);
    ASSERT_GT(h.from_cloud.graph.size(), 2u);
    ASSERT_GT(h.from_depth.graph.size(), 2u);
    Segmenter segmenter = api().make_segmenter(h.scene.width, h.scene.height, h.params, outputs);
    const std::size_t bytes = segmenter.device_segment_graph_bytes();
    ASSERT_GT(bytes, 0u);
    std::vector<Frame> frames = alternating_frames(api(), h, [&](LabelFrame& out) {
        out.statistics = {api().allocate(segmenter.device_statistics_bytes()), 0};
        out.graph = {api().allocate(bytes + 12), 12};
    });
    const std::vector<Way> ways = api().ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        api().run(segmenter, frames, way);
        for (std::size_t f = 0; f < frames.size(); ++f) {
            SCOPED_TRACE(ways[way].name + ", frame " + std::to_string(f));
            const Result& expected = f % 2 == 0 ? h.from_cloud : h.from_depth;
            const std::uint32_t count = words(frames[f].out.count.buffer, 0, 1)[0];
            ASSERT_EQ(count, expected.segment_count);
            EXPECT_EQ(words(frames[f].out.graph.buffer, 8, 1)[0], kUntouched) << "written before the offset";
            const std::vector<std::uint32_t> graph_words = words(frames[f].out.graph.buffer, 12, bytes / 4);
            std::vector<SegmentEdge> graph;
            segmenter.decode_device_segment_graph(graph_words.data(), count, graph);
            ASSERT_EQ(graph.size(), expected.graph.size());
            for (std::size_t k = 0; k < graph.size(); ++k) {
                SCOPED_TRACE("edge " + std::to_string(k));
                EXPECT_EQ(graph[k].a, expected.graph[k].a);
                EXPECT_EQ(graph[k].b, expected.graph[k].b);
                EXPECT_EQ(graph[k].length, expected.graph[k].length);
                EXPECT_EQ(graph[k].flat, expected.graph[k].flat);
                EXPECT_EQ(graph[k].convex, expected.graph[k].convex);
                EXPECT_EQ(graph[k].concave, expected.graph[k].concave);
                EXPECT_EQ(graph[k].step, expected.graph[k].step);
            }
            std::vector<unsigned char> blank(bytes, 0xAB);
            api().upload(frames[f].out.graph.buffer, 12, blank.data(), blank.size());
        }
    }
    std::vector<SegmentEdge> none;
    const std::vector<std::uint32_t> zeros(bytes / 4, 0);
    EXPECT_THROW(segmenter.decode_device_segment_graph(zeros.data(), 1u << 30, none), Error);
    EXPECT_THROW(segmenter.decode_device_segment_graph(nullptr, 1, none), Error);
    segmenter.decode_device_segment_graph(zeros.data(), 0, none);
    EXPECT_TRUE(none.empty());
    Segmenter without = api().make_segmenter(h.scene.width, h.scene.height, h.params);
    EXPECT_EQ(without.device_segment_graph_bytes(), 0u);
    EXPECT_THROW(without.decode_device_segment_graph(zeros.data(), 1, none), Error);
}

namespace {

Window window_of(const synthetic::Scene& wide, int x0, int width) {
    Window w;
    w.points.resize(3 * std::size_t(width) * std::size_t(wide.height));
    w.depth.resize(std::size_t(width) * std::size_t(wide.height));
    for (int y = 0; y < wide.height; ++y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t from = std::size_t(y) * std::size_t(wide.width) + std::size_t(x0 + x);
            const std::size_t to = std::size_t(y) * std::size_t(width) + std::size_t(x);
            std::copy_n(wide.points.data() + 3 * from, 3, w.points.data() + 3 * to);
            const float z = wide.points[3 * from + 2];
            w.depth[to] = z > 0 && z < 65535 ? std::uint16_t(z) : 0;
        }
    }
    w.view = {w.depth.data(), DepthFormat::u16, width, wide.height, 0, 0.001, wide.fx, wide.fy, wide.cx - x0, wide.cy};
    return w;
}

}  // namespace

PanningStream panning_stream(std::initializer_list<int> columns) {
    synthetic::SceneOptions o;
    o.width = PanningStream::kWidth + 16;
    o.height = PanningStream::kHeight;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene wide = synthetic::generate(o);
    PanningStream stream;
    stream.params = sensor_preset(SensorKind::kinect_v1);
    stream.outputs.segment_stats = true;
    stream.outputs.segment_tracks = true;
    for (const int x0 : columns) stream.windows.push_back(window_of(wide, x0, PanningStream::kWidth));
    return stream;
}

// Tracks of device frames (a Segmenter made with Outputs::segment_tracks and the statistics): a panning stream of
// clouds and depth images in turn, all queued before any is read; Segmenter::decode_device_tracks, frame by frame in
// order, gives the tracks a host stream of the same frames gets on the CPU, and a host frame after them continues the
// stream. Decoding out of order, twice, or with another frame's statistics is refused, as is a host frame after a
// device frame not decoded.
TEST_P(DeviceFrames, TracksMatchTheHostPath) {
    const PanningStream stream = panning_stream({0, 2, 3, 5, 8, 9, 12});  // the last one a host frame
    const std::vector<Window>& windows = stream.windows;
    const std::size_t frame_count = windows.size();
    const auto is_cloud = [](std::size_t f) { return f % 2 == 0; };

    std::vector<Result> expected(frame_count);
    Segmenter cpu(PanningStream::kWidth, PanningStream::kHeight, stream.params, "cpu", stream.outputs);
    std::size_t matched = 0;
    for (std::size_t f = 0; f < frame_count; ++f) {
        const Window& w = windows[f];
        expected[f] = is_cloud(f) ? cpu.segment(stream.cloud(f)) : cpu.segment(w.view);
        for (const SegmentTrack& t : expected[f].tracks) matched += t.how != TrackMatch::new_track ? 1 : 0;
    }
    ASSERT_GT(matched, 10u) << "a stream whose tracks carry over";

    Segmenter segmenter =
        api().make_segmenter(PanningStream::kWidth, PanningStream::kHeight, stream.params, stream.outputs);
    const std::size_t bytes = segmenter.device_tracks_bytes();
    ASSERT_GT(bytes, 0u);
    std::vector<Frame> frames;
    for (std::size_t f = 0; f + 1 < frame_count; ++f) {
        const Window& w = windows[f];
        LabelFrame out;
        out.labels = {api().allocate(4 * w.depth.size()), 0};
        out.count = {api().allocate(4), 0};
        out.statistics = {api().allocate(segmenter.device_statistics_bytes()), 0};
        out.tracks = {api().allocate(bytes + 12), 12};
        if (is_cloud(f)) {
            frames.push_back({CloudFrame{put(w.points.data(), 4 * w.points.size()), {}, 0}, out});
        } else {
            DepthFrame d{put(w.depth.data(), 2 * w.depth.size()), w.view};
            d.view.depth = nullptr;
            frames.push_back({d, out});
        }
    }
    const std::vector<Way> ways = api().ways();
    for (std::size_t way = 0; way < ways.size(); ++way) {
        if (ways[way].refusals_only) continue;
        SCOPED_TRACE(ways[way].name);
        segmenter.reset_tracks();
        api().run(segmenter, frames, way);
        std::vector<std::vector<std::uint32_t>> words_of;
        std::vector<std::vector<SegmentStats>> segments_of;
        for (const Frame& frame : frames) {
            const std::uint32_t count = words(frame.out.count.buffer, 0, 1)[0];
            EXPECT_EQ(words(frame.out.tracks.buffer, 8, 1)[0], kUntouched) << "written before the offset";
            const std::vector<std::uint32_t> head = words(frame.out.tracks.buffer, 12, PYR_TRACK_HEADER_WORDS);
            words_of.push_back(words(frame.out.tracks.buffer, 12,
                                     PYR_TRACK_HEADER_WORDS + PYR_TRACK_SLOT_WORDS * head[PYR_TRACK_PAIRS]));
            const std::vector<std::uint32_t> stats =
                words(frame.out.statistics.buffer, 0, segmenter.device_statistics_bytes() / 4);
            segments_of.emplace_back();
            segmenter.decode_device_statistics(stats.data(), count, segments_of.back());
        }
        std::vector<SegmentTrack> tracks;
        expect_error([&] { segmenter.decode_device_tracks(words_of[1].data(), segments_of[1], tracks); }, "frame 1",
                     ErrorCode::invalid_argument);
        expect_error([&] { segmenter.decode_device_tracks(words_of[0].data(), segments_of[1], tracks); }, "statistics",
                     ErrorCode::invalid_argument);
        for (std::size_t f = 0; f < frames.size(); ++f) {
            SCOPED_TRACE("frame " + std::to_string(f));
            segmenter.decode_device_tracks(words_of[f].data(), segments_of[f], tracks);
            EXPECT_EQ(tracks, expected[f].tracks);
        }
        expect_error([&] { segmenter.decode_device_tracks(words_of.back().data(), segments_of.back(), tracks); },
                     "next to decode is frame 6", ErrorCode::invalid_argument);
        const CloudView host_frame = stream.cloud(frame_count - 1);
        const Result host = segmenter.segment(host_frame);
        EXPECT_EQ(host.tracks, expected.back().tracks) << "a host frame after the device frames";
        api().run(segmenter, std::span(frames.data(), 1), way);
        expect_error([&] { (void)segmenter.segment(host_frame); }, "not all decoded", ErrorCode::invalid_argument);
    }
    std::vector<SegmentTrack> none;
    EXPECT_THROW(segmenter.decode_device_tracks(nullptr, {}, none), Error);
    Segmenter without = api().make_segmenter(PanningStream::kWidth, PanningStream::kHeight, stream.params);
    EXPECT_EQ(without.device_tracks_bytes(), 0u);
    const std::vector<std::uint32_t> zeros(PYR_TRACK_HEADER_WORDS, 0);
    EXPECT_THROW(without.decode_device_tracks(zeros.data(), {}, none), Error);
}

}  // namespace pyrseg::test
