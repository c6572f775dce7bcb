// pyrseg.synthetic: the seeded bin-picking scenes of pyrseg/synthetic.hpp, with ground truth, as numpy arrays: the
// frames the tests and examples segment without a camera.
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::python {
namespace {

synthetic::Sensor sensor_of(const std::string& name) {
    const auto s = synthetic::sensor_from_name(name);
    if (!s) {
        throw py::value_error("unknown sensor '" + name +
                              "'; sensors: structured-light, kinect-v1, realsense-d435, azure-kinect");
    }
    return *s;
}

}  // namespace

void bind_synthetic(py::module_& synthetic) {
    synthetic.doc() = "Seeded synthetic bin-picking scenes with exact normals and per-pixel ground truth.";
    synthetic.attr("FLOOR_ID") = synthetic::kFloorId;
    synthetic.attr("BIN_BOTTOM_ID") = synthetic::kBinBottomId;
    synthetic.attr("FIRST_WALL_ID") = synthetic::kFirstWallId;
    synthetic.attr("FIRST_OBJECT_ID") = synthetic::kFirstObjectId;
    synthetic.def(
        "generate",
        [](int width, int height, std::uint64_t seed, int object_count, double noise_mm, double hole_fraction,
           bool touching, bool bin, const std::string& sensor, double camera_distance_mm, bool shadows, int threads) {
            synthetic::SceneOptions o;
            o.width = width;
            o.height = height;
            o.seed = seed;
            o.object_count = object_count;
            o.noise_mm = noise_mm;
            o.hole_fraction = hole_fraction;
            o.touching = touching;
            o.bin = bin;
            o.sensor = sensor_of(sensor);
            o.camera_distance_mm = camera_distance_mm;
            o.shadows = shadows;
            o.threads = threads;
            synthetic::Scene s;
            {
                const py::gil_scoped_release nogil;
                s = synthetic::generate(o);
            }
            py::dict d;
            d["points"] = array_of(s.points.data(), s.height, s.width, 3);
            d["normals"] = array_of(s.normals.data(), s.height, s.width, 3);
            d["object_id"] = array_of(s.object_id.data(), s.height, s.width);
            d["fx"] = s.fx;
            d["fy"] = s.fy;
            d["cx"] = s.cx;
            d["cy"] = s.cy;
            d["objects_placed"] = s.objects_placed;
            return py::module_::import("types").attr("SimpleNamespace")(**d);
        },
        py::arg("width") = 640, py::arg("height") = 480, py::arg("seed") = 1, py::arg("object_count") = 12,
        py::arg("noise_mm") = 0.1, py::arg("hole_fraction") = 0.01, py::arg("touching") = true, py::arg("bin") = true,
        py::arg("sensor") = "structured-light", py::arg("camera_distance_mm") = 1200.0, py::arg("shadows") = true,
        py::arg("threads") = 0,
        R"(A scene as a depth camera about 1.2 m above a bin sees it, in millimetres. Returns a namespace with
points and normals (H x W x 3 float32, NaN where no data), object_id (H x W uint32 ground truth: 0 no data, 1 floor,
2 bin bottom, 3..6 walls, 7.. objects), fx, fy, cx, cy (the pinhole intrinsics) and objects_placed.)");
}

}  // namespace pyrseg::python
