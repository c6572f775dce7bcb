// An OpenCL application that owns its context, queue and buffers and hands them to pyrseg: each depth frame is
// written into the application's cl_mem (as a camera pipeline's own kernels would leave it), segmented on the
// device into the application's label buffer, and only then read back, once, by the application. pyrseg waits for
// the upload through its event and returns an event of its own; it never calls clFinish. The Segmenter also follows
// tracks: each frame's labels stay on the device for the next one, which counts its overlaps with them there; the
// application reads the statistics' and the tracks' words with the labels and decode_device_tracks gives each
// segment the id it keeps from frame to frame. The frames come from the synthetic Kinect v1 model, a camera panning
// over one scene, so that the example runs anywhere; each is checked against the host path.
#include <pyrseg/opencl.hpp>
#include <pyrseg/pyrseg.hpp>
#include <pyrseg/synthetic.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace {

constexpr int kSkipped = 77;  // ctest: no OpenCL device here

bool ok(cl_int err, const char* what) {
    if (err != CL_SUCCESS) std::fprintf(stderr, "opencl_app: %s failed (%d)\n", what, err);
    return err == CL_SUCCESS;
}

}  // namespace

int main() {
    // The application's OpenCL objects: the first device of the first platform that has one.
    cl_uint platform_count = 0;
    if (clGetPlatformIDs(0, nullptr, &platform_count) != CL_SUCCESS || platform_count == 0) {
        std::puts("opencl_app: skipped: no OpenCL platform");
        return kSkipped;
    }
    std::vector<cl_platform_id> platforms(platform_count);
    clGetPlatformIDs(platform_count, platforms.data(), nullptr);
    cl_device_id device = nullptr;
    for (cl_platform_id p : platforms) {
        if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, &device, nullptr) == CL_SUCCESS) break;
    }
    if (device == nullptr) {
        std::puts("opencl_app: skipped: no OpenCL device");
        return kSkipped;
    }
    cl_int err = CL_SUCCESS;
    cl_context context = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &err);
    if (!ok(err, "clCreateContext")) return 1;
    cl_command_queue queue = clCreateCommandQueue(context, device, 0, &err);
    if (!ok(err, "clCreateCommandQueue")) return 1;

    const int width = 320;
    const int height = 240;
    const int pan = 4;  // the camera's step to the side, in pixels a frame
    const int frames = 4;
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    const pyrseg::Params params = pyrseg::sensor_preset(pyrseg::SensorKind::kinect_v1);
    pyrseg::Outputs outputs;
    outputs.segment_stats = true;   // the tracks' second cue (centroids), decoded on the host
    outputs.segment_tracks = true;  // ids kept from frame to frame
    // Stands in for the camera: a scene wider than the frame, which the camera pans over.
    pyrseg::synthetic::SceneOptions camera;
    camera.width = width + pan * frames;
    camera.height = height;
    camera.sensor = pyrseg::synthetic::Sensor::kinect_v1;
    camera.seed = 1;
    const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(camera);
    int status = 0;
    {
        // pyrseg on the application's queue; its buffers live in the application's context.
        pyrseg::Segmenter segmenter =
            pyrseg::opencl::make_segmenter(width, height, {context, device, queue}, params, outputs);
        pyrseg::Segmenter host_path(width, height, params, "cpu", outputs);  // only to check the results

        const std::size_t stats_bytes = segmenter.device_statistics_bytes();
        const std::size_t tracks_bytes = segmenter.device_tracks_bytes();
        cl_mem depth_buffer = clCreateBuffer(context, CL_MEM_READ_ONLY, 2 * pixels, nullptr, &err);
        cl_mem label_buffer = clCreateBuffer(context, CL_MEM_WRITE_ONLY, 4 * pixels, nullptr, &err);
        cl_mem count_buffer = clCreateBuffer(context, CL_MEM_WRITE_ONLY, 4, nullptr, &err);
        cl_mem stats_buffer = clCreateBuffer(context, CL_MEM_WRITE_ONLY, stats_bytes, nullptr, &err);
        cl_mem tracks_buffer = clCreateBuffer(context, CL_MEM_WRITE_ONLY, tracks_bytes, nullptr, &err);
        std::vector<std::uint16_t> depth(pixels);
        std::vector<std::uint32_t> labels(pixels);
        std::vector<std::uint32_t> stats_words(stats_bytes / 4);
        std::vector<std::uint32_t> track_words(tracks_bytes / 4);
        std::vector<pyrseg::SegmentStats> segments;
        std::vector<pyrseg::SegmentTrack> tracks;
        for (int frame = 0; frame < frames && status == 0; ++frame) {
            // The frame's window of the scene, in whole millimetres (0: no data).
            const int x0 = pan * frame;
            for (int y = 0; y < height; ++y) {
                for (int x = 0; x < width; ++x) {
                    const float z =
                        scene.points[3 * (std::size_t(y) * std::size_t(camera.width) + std::size_t(x0 + x)) + 2];
                    depth[std::size_t(y) * std::size_t(width) + std::size_t(x)] =
                        std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
                }
            }
            cl_event uploaded = nullptr;
            if (!ok(clEnqueueWriteBuffer(queue, depth_buffer, CL_FALSE, 0, 2 * pixels, depth.data(), 0, nullptr,
                                         &uploaded),
                    "clEnqueueWriteBuffer"))
                return 1;

            pyrseg::opencl::DepthBuffer in;
            in.samples = depth_buffer;
            in.view.format = pyrseg::DepthFormat::u16;
            in.view.width = width;
            in.view.height = height;
            in.view.metres_per_unit = 0.001;
            in.view.fx = scene.fx;
            in.view.fy = scene.fy;
            in.view.cx = scene.cx - x0;  // the window's principal point
            in.view.cy = scene.cy;
            pyrseg::opencl::LabelBuffers out;
            out.labels = label_buffer;
            out.count = count_buffer;
            out.statistics = stats_buffer;
            out.tracks = tracks_buffer;
            const cl_event wait[] = {uploaded};
            cl_event segmented = pyrseg::opencl::segment(segmenter, in, out, wait);

            // The application's next step would use label_buffer on the device; here it reads it once, with K, the
            // statistics' words and the tracks' (all of them here; the header's word 3 says how many pairs follow).
            std::uint32_t count = 0;
            if (!ok(clEnqueueReadBuffer(queue, label_buffer, CL_FALSE, 0, 4 * pixels, labels.data(), 1, &segmented,
                                        nullptr),
                    "clEnqueueReadBuffer") ||
                !ok(clEnqueueReadBuffer(queue, stats_buffer, CL_FALSE, 0, stats_bytes, stats_words.data(), 0, nullptr,
                                        nullptr),
                    "clEnqueueReadBuffer") ||
                !ok(clEnqueueReadBuffer(queue, tracks_buffer, CL_FALSE, 0, tracks_bytes, track_words.data(), 0, nullptr,
                                        nullptr),
                    "clEnqueueReadBuffer") ||
                !ok(clEnqueueReadBuffer(queue, count_buffer, CL_TRUE, 0, 4, &count, 0, nullptr, nullptr),
                    "clEnqueueReadBuffer"))
                return 1;
            clReleaseEvent(segmented);
            clReleaseEvent(uploaded);
            // The tracks: matched on the host, frame by frame in the order the frames ran.
            segmenter.decode_device_statistics(stats_words.data(), count, segments);
            segmenter.decode_device_tracks(track_words.data(), segments, tracks);
            int kept = 0;
            for (const pyrseg::SegmentTrack& t : tracks) kept += t.how != pyrseg::TrackMatch::new_track ? 1 : 0;

            pyrseg::DepthView view = in.view;
            view.depth = depth.data();
            const pyrseg::Result expected = host_path.segment(view);
            const bool same = count == expected.segment_count && labels == expected.labels && tracks == expected.tracks;
            std::printf("frame %d: %u segments, %d of them kept their track id (%s)\n", frame, count, kept,
                        same ? "matches the host path" : "DIFFERS from the host path");
            if (!same) status = 1;
        }
        clReleaseMemObject(tracks_buffer);
        clReleaseMemObject(stats_buffer);
        clReleaseMemObject(count_buffer);
        clReleaseMemObject(label_buffer);
        clReleaseMemObject(depth_buffer);
    }
    clReleaseCommandQueue(queue);
    clReleaseContext(context);
    return status;
}
