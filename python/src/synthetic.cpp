// pyrseg.synthetic: the seeded bin-picking scenes of pyrseg/synthetic.hpp, with ground truth, as numpy arrays: the
// frames the tests and examples segment without a camera.
#include <string>

#include "args.hpp"
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
    static constexpr Param kGenerate[] = {{"width", "640"},
                                          {"height", "480"},
                                          {"seed", "1"},
                                          {"object_count", "12"},
                                          {"noise_mm", "0.1"},
                                          {"hole_fraction", "0.01"},
                                          {"touching", "True"},
                                          {"bin", "True"},
                                          {"sensor", "'structured-light'"},
                                          {"camera_distance_mm", "1200.0"},
                                          {"shadows", "True"},
                                          {"threads", "0"}};
    def_args(synthetic, "generate", kGenerate,
             R"(A scene as a depth camera about 1.2 m above a bin sees it, in millimetres. Returns a namespace with
points and normals (H x W x 3 float32, NaN where no data), object_id (H x W uint32 ground truth: 0 no data, 1 floor,
2 bin bottom, 3..6 walls, 7.. objects), fx, fy, cx, cy (the pinhole intrinsics) and objects_placed.)",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const Args a("generate()", kGenerate, args, kwargs);
                 synthetic::SceneOptions o;
                 o.width = a.integer(0, 640);
                 o.height = a.integer(1, 480);
                 o.seed = a.given(2) ? unsigned_integer(a.function(), "seed", a.object(2)) : 1;
                 o.object_count = a.integer(3, 12);
                 o.noise_mm = a.number(4, 0.1);
                 o.hole_fraction = a.number(5, 0.01);
                 o.touching = a.boolean(6, true);
                 o.bin = a.boolean(7, true);
                 o.sensor = sensor_of(a.text(8, "structured-light"));
                 o.camera_distance_mm = a.number(9, 1200.0);
                 o.shadows = a.boolean(10, true);
                 o.threads = a.integer(11, 0);
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
             });
}

}  // namespace pyrseg::python
