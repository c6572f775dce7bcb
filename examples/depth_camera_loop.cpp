// A depth camera's loop with DepthView: the SDK's uint16 depth frames and intrinsics go to pyrseg as they are, are
// uploaded at 2 bytes a pixel and back-projected on the device; the preset of the kind of camera sets the
// parameters. The frames here come from the synthetic Kinect v1 model so that the example runs anywhere.
#include <pyrseg/pyrseg.hpp>
#include <pyrseg/synthetic.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

int main() {
    const int width = 640;
    const int height = 480;
    // The camera's preset; the points are in millimetres (unit_mm 1), whatever the depth unit.
    pyrseg::Segmenter segmenter(width, height, pyrseg::sensor_preset(pyrseg::SensorKind::kinect_v1));

    std::vector<std::uint16_t> depth(std::size_t(width) * std::size_t(height));
    pyrseg::Result result;  // reused: no allocation per frame once sized
    for (std::uint64_t frame = 1; frame <= 3; ++frame) {
        // Stands in for the SDK: a frame of whole millimetres (0: no data) and the camera's intrinsics.
        pyrseg::synthetic::SceneOptions camera;
        camera.sensor = pyrseg::synthetic::Sensor::kinect_v1;
        camera.seed = frame;
        const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(camera);
        for (std::size_t i = 0; i < depth.size(); ++i) {
            const float z = scene.points[3 * i + 2];
            depth[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
        }

        pyrseg::DepthView view;
        view.depth = depth.data();
        view.format = pyrseg::DepthFormat::u16;
        view.width = width;
        view.height = height;
        view.row_step_bytes = 0;       // packed rows; give the SDK's stride otherwise
        view.metres_per_unit = 0.001;  // the SDK's depth scale (RealSense: get_depth_scale())
        view.fx = scene.fx;            // the SDK's intrinsics
        view.fy = scene.fy;
        view.cx = scene.cx;
        view.cy = scene.cy;
        segmenter.segment(view, result);
        std::printf("frame %llu: %u segments on %s\n", static_cast<unsigned long long>(frame), result.segment_count,
                    segmenter.backend_name().c_str());
    }
    return 0;
}
