// The README's example, compiled with the project so that it cannot rot: segment a stream of frames with one
// Segmenter and one Result, reused, so no frame allocates.
#include <pyrseg/pyrseg.hpp>
#include <pyrseg/synthetic.hpp>

#include <cstdio>

int main() {
    pyrseg::Params params;                          // defaults from the paper: ct 0.25 rad, dt 10 mm
    params.unit_mm = 1.0;                           // these clouds are in millimetres; 1000 for metres
    pyrseg::Segmenter segmenter(640, 480, params);  // backend: $PYRSEG_BACKEND, else the best available

    pyrseg::Result result;  // reused: no allocation per frame once sized
    for (std::uint64_t frame = 1; frame <= 3; ++frame) {
        pyrseg::synthetic::SceneOptions scene_options;  // stands in for a camera
        scene_options.seed = frame;
        const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(scene_options);

        pyrseg::CloudView view;
        view.points = scene.points.data();  // x y z floats per pixel, row-major; NaN or z <= 0 means no data
        view.normals = nullptr;             // or your own normals; estimated when null
        view.width = scene.width;
        view.height = scene.height;
        segmenter.segment(view, result);
        // result.labels: width * height uint32, 0 = no segment, 1..result.segment_count
        std::printf("frame %llu: %u segments on %s\n", static_cast<unsigned long long>(frame), result.segment_count,
                    segmenter.backend_name().c_str());
    }
    return 0;
}
