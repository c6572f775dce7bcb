// pyrseg.describe_scene (pyrseg/scene.hpp): a frame's supports and objects as numpy structured arrays, from
// Result.segments, with the boxes fitted to the points when the caller gives them.
#include <cstddef>
#include <cstring>
#include <span>
#include <vector>

#include "bindings.hpp"
#include "pyrseg/scene.hpp"

namespace pyrseg::python {
namespace {

py::dtype make_dtype(const std::vector<std::tuple<const char*, const char*, std::size_t>>& fields,
                     std::size_t itemsize) {
    py::list names, formats, offsets;
    for (const auto& [name, format, offset] : fields) {
        names.append(name);
        formats.append(format);
        offsets.append(offset);
    }
    py::dict spec;
    spec["names"] = names;
    spec["formats"] = formats;
    spec["offsets"] = offsets;
    spec["itemsize"] = itemsize;
    return py::reinterpret_steal<py::dtype>(py::module_::import("numpy").attr("dtype")(spec).release());
}

py::dtype support_dtype() {
    return make_dtype({{"label", "<u4", offsetof(SceneSupport, label)},
                       {"pixel_count", "<u4", offsetof(SceneSupport, pixel_count)},
                       {"normal", "(3,)<f8", offsetof(SceneSupport, normal)},
                       {"offset", "<f8", offsetof(SceneSupport, offset)},
                       {"rms", "<f8", offsetof(SceneSupport, rms)},
                       {"centroid", "(3,)<f8", offsetof(SceneSupport, centroid)},
                       {"axes", "(3,3)<f8", offsetof(SceneSupport, axes)},
                       {"extents", "(3,)<f8", offsetof(SceneSupport, extents)},
                       {"level", "?", offsetof(SceneSupport, level)}},
                      sizeof(SceneSupport));
}

py::dtype object_dtype() {
    return make_dtype({{"label", "<u4", offsetof(SceneObject, label)},
                       {"pixel_count", "<u4", offsetof(SceneObject, pixel_count)},
                       {"support", "<i4", offsetof(SceneObject, support)},
                       {"touches", "?", offsetof(SceneObject, touches)},
                       {"centroid", "(3,)<f8", offsetof(SceneObject, centroid)},
                       {"box_centre", "(3,)<f8", offsetof(SceneObject, box_centre)},
                       {"axes", "(3,3)<f8", offsetof(SceneObject, axes)},
                       {"extents", "(3,)<f8", offsetof(SceneObject, extents)},
                       {"height", "<f8", offsetof(SceneObject, height)}},
                      sizeof(SceneObject));
}

template <class T>
py::array to_array(const std::vector<T>& items, const py::dtype& dtype) {
    py::array a(dtype, std::vector<py::ssize_t>{py::ssize_t(items.size())});
    if (!items.empty()) std::memcpy(a.mutable_data(), items.data(), items.size() * sizeof(T));
    return a;
}

}  // namespace

void bind_scene(py::module_& m) {
    static_assert(std::is_trivially_copyable_v<SegmentStats> && std::is_trivially_copyable_v<SceneSupport> &&
                  std::is_trivially_copyable_v<SceneObject>);
    const py::dtype supports = support_dtype();
    const py::dtype objects = object_dtype();
    m.attr("scene_support_dtype") = supports;
    m.attr("scene_object_dtype") = objects;
    const py::object scene_type =
        py::module_::import("collections")
            .attr("namedtuple")("Scene", py::make_tuple("supports", "objects"), py::arg("module") = m.attr("__name__"));
    scene_type.attr("__doc__") =
        "A frame's scene. supports: scene_support_dtype entries, largest first; objects: scene_object_dtype entries "
        "by label (support: an index into supports, -1 for none).";
    m.attr("Scene") = scene_type;
    m.def(
        "describe_scene",
        [supports, objects, scene_type](const py::object& segments, double unit_mm, const py::object& points,
                                        const py::object& labels, const py::object& fillable, double support_min_share,
                                        double support_flatness, double contact_mm, double max_height_mm,
                                        double level_degrees, std::uint32_t object_min_pixels) {
            const py::dtype stats = segment_stats_dtype();
            if (!py::isinstance<py::array>(segments) || !py::dtype(segments.attr("dtype")).equal(stats)) {
                throw py::type_error(
                    "describe_scene(): segments must be Result.segments, an array of "
                    "pyrseg.segment_stats_dtype (outputs=('segment_stats',))");
            }
            const auto table = py::array::ensure(segments, py::array::c_style);
            if (table.ndim() != 1) throw py::value_error("describe_scene(): segments must be one-dimensional");
            std::vector<SegmentStats> list(std::size_t(table.shape(0)));
            if (!list.empty()) std::memcpy(list.data(), table.data(), list.size() * sizeof(SegmentStats));
            if (points.is_none() != labels.is_none()) {
                throw py::value_error(
                    "describe_scene(): points and labels go together (the boxes are fitted to "
                    "the points of each object's labelled pixels)");
            }
            Params params;
            params.unit_mm = unit_mm;
            SceneParams sp;
            sp.support_min_share = support_min_share;
            sp.support_flatness = support_flatness;
            sp.contact_mm = contact_mm;
            sp.max_height_mm = max_height_mm;
            sp.level_degrees = level_degrees;
            sp.object_min_pixels = object_min_pixels;
            Scene scene;
            describe_scene(list, params, sp, scene);
            if (!points.is_none()) {
                const auto xyz = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(points);
                const auto ids = py::array_t<std::uint32_t, py::array::c_style>::ensure(labels);
                if (!xyz || xyz.ndim() != 3 || xyz.shape(2) != 3) {
                    throw py::value_error("describe_scene(): points must be an H x W x 3 float array");
                }
                if (!py::isinstance<py::array>(labels) || !ids ||
                    !py::dtype(labels.attr("dtype")).equal(py::dtype::of<std::uint32_t>()) || ids.ndim() != 2 ||
                    ids.shape(0) != xyz.shape(0) || ids.shape(1) != xyz.shape(1)) {
                    throw py::value_error(
                        "describe_scene(): labels must be Result.labels, H x W uint32 of the "
                        "points' size");
                }
                std::span<const std::uint8_t> mask;
                py::array_t<std::uint8_t, py::array::c_style> fillable_array;
                if (!fillable.is_none()) {
                    fillable_array = py::array_t<std::uint8_t, py::array::c_style>::ensure(fillable);
                    if (!py::isinstance<py::array>(fillable) || !fillable_array || fillable_array.ndim() != 2 ||
                        fillable_array.shape(0) != ids.shape(0) || fillable_array.shape(1) != ids.shape(1)) {
                        throw py::value_error(
                            "describe_scene(): fillable must be Result.fillable_mask, H x W uint8 "
                            "of the labels' size");
                    }
                    mask = {fillable_array.data(), std::size_t(fillable_array.size())};
                }
                fit_object_boxes({xyz.data(), std::size_t(xyz.size())}, {ids.data(), std::size_t(ids.size())}, mask,
                                 scene);
            }
            return scene_type(to_array(scene.supports, supports), to_array(scene.objects, objects));
        },
        py::arg("segments"), py::kw_only(), py::arg("unit_mm") = 1.0, py::arg("points") = py::none(),
        py::arg("labels") = py::none(), py::arg("fillable") = py::none(),
        py::arg("support_min_share") = SceneParams{}.support_min_share,
        py::arg("support_flatness") = SceneParams{}.support_flatness, py::arg("contact_mm") = SceneParams{}.contact_mm,
        py::arg("max_height_mm") = SceneParams{}.max_height_mm, py::arg("level_degrees") = SceneParams{}.level_degrees,
        py::arg("object_min_pixels") = SceneParams{}.object_min_pixels,
        R"(The scene of one frame (docs/algorithm.md section 10c): its supports (large flat segments; level ones
parallel to the largest: a table, a floor) and the objects standing over them, each with a box from its support's
plane to its top. From Result.segments (outputs=('segment_stats',)) alone; with points (H x W x 3, the frame's xyz in
the units the statistics came in) and labels (Result.labels), each object's box is fitted to its points; with
fillable (Result.fillable_mask, outputs=('fillable_mask',)) too, to its fillable pixels' points only (edge pixels are
mixed pixels that stretch a box towards the background). unit_mm:
the frame's unit (the Segmenter's unit_mm). Returns Scene(supports, objects), numpy structured arrays of
scene_support_dtype and scene_object_dtype; lengths in the frame's units.)");
}

}  // namespace pyrseg::python
