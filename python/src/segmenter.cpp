// pyrseg.Segmenter, its parameters and results, pyrseg.Error, the backends and presets.
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "args.hpp"
#include "arrays.hpp"
#include "bindings.hpp"
#include "device.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/cpu.hpp"
#include "pyrseg/depth.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/version.hpp"

namespace pyrseg::python {
namespace {

// Python objects made once when the module is imported and kept for the process's life: a frame then makes only
// its result arrays and tuple, through Python's allocator, and nothing through operator new (the tests count it).
struct Cached {
    PyObject* error = nullptr;         // pyrseg.Error
    PyObject* empty = nullptr;         // numpy.empty
    PyObject* result_type = nullptr;   // pyrseg.Result (a named tuple)
    PyObject* backend_type = nullptr;  // pyrseg.BackendInfo (a named tuple)
    PyObject* stats_dtype = nullptr;   // pyrseg.segment_stats_dtype
    PyObject* graph_dtype = nullptr;   // pyrseg.segment_graph_dtype
    PyObject* track_dtype = nullptr;   // pyrseg.segment_track_dtype
    PyObject* uint32 = nullptr;
    PyObject* uint8 = nullptr;
    PyObject* float32 = nullptr;
};
Cached cached;  // NOLINT: set once at import, as pybind11 modules keep their types

py::handle obj(PyObject* p) {
    return {p};
}

py::array new_array(PyObject* dtype, int height, int width, int channels = 0) {
    py::object shape =
        channels > 0 ? py::object(py::make_tuple(height, width, channels)) : py::object(py::make_tuple(height, width));
    return py::reinterpret_borrow<py::array>(obj(cached.empty)(shape, obj(dtype)));
}

// --- parameters -------------------------------------------------------------------------------------------------

std::string known_presets() {
    std::string s;
    for (const SensorKind k : sensor_kinds()) s += (s.empty() ? "" : ", ") + std::string(sensor_kind_name(k));
    return s;
}

constexpr const char* kInit = "Segmenter()";

SensorKind preset_kind(const std::string& name) {
    const auto kind = sensor_kind_from_name(name);
    if (!kind) raise(ErrorCode::invalid_parameter, "unknown preset '" + name + "'; presets: " + known_presets());
    return *kind;
}

// One keyword argument onto Params; false when `key` is not a parameter.
bool set_param(Params& p, const std::string& key, const py::handle& v) {
    const char* name = key.c_str();
    const auto whole = [&] { return int(integer(kInit, name, v, INT_MIN, INT_MAX)); };
    const auto optional_int = [&](std::optional<int>& field) {
        field = v.is_none() ? std::nullopt : std::optional<int>(whole());
    };
    if (key == "ct") {
        p.ct = number(kInit, name, v);
    } else if (key == "dt") {
        p.dt = number(kInit, name, v);
    } else if (key == "unit_mm") {
        p.unit_mm = number(kInit, name, v);
    } else if (key == "bridge_levels") {
        optional_int(p.bridge_levels);
    } else if (key == "unjoinable_gap") {
        optional_int(p.unjoinable_gap);
    } else if (key == "label_edges") {
        p.label_edges = boolean(kInit, name, v);
    } else if (key == "edge_rounds") {
        p.edge_rounds = whole();
    } else if (key == "edge_max_depth_step") {
        p.edge_max_depth_step = number(kInit, name, v);
    } else if (key == "compact") {
        p.compact = boolean(kInit, name, v);
    } else if (key == "normal_radius") {
        p.normal_radius = whole();
    } else if (key == "metric") {
        const auto m = text(kInit, name, v);
        if (m != "paper" && m != "robust") {
            raise(ErrorCode::invalid_parameter, "metric must be 'paper' or 'robust', got '" + m + "'");
        }
        p.metric = m == "robust" ? Metric::robust : Metric::paper;
    } else if (key == "normal_window") {
        p.normal_window = whole();
    } else if (key == "curvature_stride") {
        p.curvature_stride = whole();
    } else if (key == "dt_per_m2") {
        p.dt_per_m2 = number(kInit, name, v);
    } else if (key == "ct_growth_per_m2") {
        p.ct_growth_per_m2 = number(kInit, name, v);
    } else if (key == "merge") {
        p.merge = boolean(kInit, name, v);
    } else if (key == "merge_reach") {
        p.merge_reach = whole();
    } else if (key == "merge_tolerance_mm") {
        p.merge_tolerance_mm = number(kInit, name, v);
    } else if (key == "merge_tolerance_per_m2") {
        p.merge_tolerance_per_m2 = number(kInit, name, v);
    } else if (key == "merge_min_crossings") {
        p.merge_min_crossings = whole();
    } else if (key == "merge_max_bad_share") {
        p.merge_max_bad_share = number(kInit, name, v);
    } else if (key == "color_edge_threshold") {
        p.color_edge_threshold = whole();
    } else if (key == "color_edge_stride") {
        p.color_edge_stride = whole();
    } else if (key == "color_edge_curvature_share") {
        p.color_edge_curvature_share = number(kInit, name, v);
    } else if (key == "planar_tolerance_mm") {
        p.planar_tolerance_mm = number(kInit, name, v);
    } else if (key == "planar_tolerance_per_m2") {
        p.planar_tolerance_per_m2 = number(kInit, name, v);
    } else if (key == "track_max_distance_mm") {
        p.track_max_distance_mm = number(kInit, name, v);
    } else if (key == "track_hold_frames") {
        p.track_hold_frames = whole();
    } else {
        return false;
    }
    return true;
}

Outputs outputs_from(const py::handle& names) {
    Outputs o;
    if (py::isinstance<py::str>(names) || !py::isinstance<py::iterable>(names)) {
        throw py::type_error("Segmenter(): outputs must be a sequence of names (str), got " + type_name(names));
    }
    for (const py::handle& n : names) {
        if (!py::isinstance<py::str>(n)) {
            throw py::type_error("Segmenter(): outputs must be a sequence of names (str), got " + type_name(n) +
                                 " among them");
        }
        const auto name = n.cast<std::string>();
        if (name == "raw_labels") {
            o.raw_labels = true;
        } else if (name == "fillable_mask") {
            o.fillable_mask = true;
        } else if (name == "normals") {
            o.normals = true;
        } else if (name == "segment_stats") {
            o.segment_stats = true;
        } else if (name == "segment_graph") {
            o.segment_graph = true;
        } else if (name == "segment_tracks") {
            o.segment_tracks = true;
        } else if (name == "track_ids") {
            o.track_ids = true;
        } else {
            throw py::value_error("unknown output '" + name +
                                  "'; outputs: raw_labels, fillable_mask, normals, segment_stats, segment_graph, "
                                  "segment_tracks, track_ids");
        }
    }
    return o;
}

// preset= first (it sets every parameter, in unit_mm), then each parameter given over it.
// threads: the CPU backend's threads= (0 when not given).
Params params_from(const py::dict& kwargs, Outputs& outputs, py::object& cuda_stream, unsigned& threads) {
    double unit_mm = 1.0;
    if (kwargs.contains("unit_mm")) unit_mm = number(kInit, "unit_mm", kwargs["unit_mm"]);
    Params p;
    if (kwargs.contains("preset") && !kwargs["preset"].is_none()) {
        p = sensor_preset(preset_kind(text(kInit, "preset", kwargs["preset"])), unit_mm);
    }
    for (const auto& [k, v] : kwargs) {
        const auto key = k.cast<std::string>();
        if (key == "preset") continue;
        if (key == "outputs") {
            outputs = outputs_from(v);
        } else if (key == "cuda_stream") {
            cuda_stream = py::reinterpret_borrow<py::object>(v);
        } else if (key == "threads") {
            threads = v.is_none() ? 0u : unsigned(integer(kInit, "threads", v, 1, cpu::kMaxThreads));
        } else if (!set_param(p, key, v)) {
            throw py::type_error(
                "Segmenter() got an unexpected keyword argument '" + key +
                "'; parameters: ct, dt, unit_mm, bridge_levels, unjoinable_gap, label_edges, "
                "edge_rounds, edge_max_depth_step, compact, normal_radius, metric, normal_window, curvature_stride, "
                "dt_per_m2, ct_growth_per_m2, merge, merge_reach, merge_tolerance_mm, "
                "merge_tolerance_per_m2, merge_min_crossings, merge_max_bad_share, "
                "color_edge_threshold, color_edge_stride, color_edge_curvature_share, "
                "planar_tolerance_mm, planar_tolerance_per_m2, track_max_distance_mm, "
                "track_hold_frames; and preset, outputs, cuda_stream, threads");
        }
    }
    return p;
}

// The samples of `samples` (format, size, pointer, row step) with the scale and intrinsics of `camera`.
DepthView with_camera(DepthView samples, const DepthView& camera) {
    samples.metres_per_unit = camera.metres_per_unit;
    samples.fx = camera.fx;
    samples.fy = camera.fy;
    samples.cx = camera.cx;
    samples.cy = camera.cy;
    return samples;
}

// Device-resident frames take no colour image yet: a host colour beside a device frame would be a silent upload.
void no_device_color(const py::object& color) {
    if (!color.is_none()) {
        throw py::value_error(
            "color= is for host frames: a device-resident frame takes no colour image yet (segment it without "
            "color=, or pass host arrays)");
    }
}

// --- the Segmenter ----------------------------------------------------------------------------------------------

// The frame methods' parameters (Args binds them; their docstrings show them).
constexpr Param kSegment[] = {{"points"}, {"normals", "None"}, {"out", "None"}, {"count", "None"}, {"color", "None"}};
constexpr Param kSegmentDepth[] = {
    {"depth"},         {"fx"},           {"fy"}, {"cx"}, {"cy"}, {"metres_per_unit"}, {"out", "None"},
    {"count", "None"}, {"color", "None"}};
constexpr Param kSegmentMask[] = {{"mask"}, {"valid", "None"}, {"out", "None"}};

class PySegmenter {
public:
    PySegmenter(const py::object& width, const py::object& height, const py::object& backend,
                const py::kwargs& kwargs) {
        const int w = int(integer(kInit, "width", width, INT_MIN, INT_MAX));
        const int h = int(integer(kInit, "height", height, INT_MIN, INT_MAX));
        py::object cuda_stream = py::none();
        // preset="auto": the preset is chosen from the first frame's depth (pyrseg.measure_frame_noise), and the
        // Segmenter made then, with the parameters given beside it over the chosen preset.
        py::dict given = py::reinterpret_borrow<py::dict>(kwargs);
        if (kwargs.contains("preset") && py::isinstance<py::str>(kwargs["preset"]) &&
            kwargs["preset"].cast<std::string>() == "auto") {
            given = py::dict(kwargs);
            given.attr("pop")("preset");
            auto_overrides_ = given;
        } else if (kwargs.contains("preset") && !kwargs["preset"].is_none()) {
            preset_name_ = text(kInit, "preset", kwargs["preset"]);
        }
        params_ = params_from(given, outputs_, cuda_stream, threads_);
        const std::string requested = backend.is_none() ? std::string() : text(kInit, "backend", backend);
        // The device-array path needs the Segmenter pyrseg/cuda.hpp makes on a stream; it segments host frames
        // too, so every CUDA Segmenter is made that way.
        const std::string name = resolve_backend_name(requested);
        if (name == "cuda" && DeviceFrames::built()) {
            device_.emplace(cuda_stream);
        } else if (!cuda_stream.is_none()) {
            throw py::value_error("cuda_stream= is for the cuda backend; this Segmenter runs " + name);
        }
        if (threads_ != 0 && name != "cpu") {
            throw py::value_error("threads= is for the cpu backend; this Segmenter runs " + name);
        }
        width_ = w;
        height_ = h;
        backend_ = name;
        if (auto_overrides_) {
            check_plan();  // the size and the parameters given are checked now, not on the first frame
            return;
        }
        make_segmenter();
    }

    py::object segment(const py::args& args, const py::kwargs& kwargs) {
        const Args a("segment()", kSegment, args, kwargs);
        const py::object points = a.object(0), normals = a.object(1), count = a.object(3);
        py::object out = a.object(2);
        if (!segmenter_) {
            if (is_device_array(points)) refuse_auto_on_device();
            const CloudInput probe(points, normals, width(), height());
            Scratch scratch;
            choose_preset(measure_frame_noise(probe.view(scratch), params_.unit_mm));
        }
        if (is_device_array(points)) {
            no_device_color(a.object(4));
            device().segment_cloud(*segmenter_, points, normals, out, count);
            return out;
        }
        no_count(count);
        const CloudInput input(points, normals, width(), height());
        const ColorInput color(a.object(4), width(), height());
        if (!out.is_none()) color.refuse_alias(check_labels_out(out, width(), height()));
        return run(input, out, true, [&input, &color](Scratch& s, Segmenter& seg, Result& r) {
            CloudView view = input.view(s);
            view.color = color.data(s, view.color_row_step_bytes);
            seg.segment(view, r);
        });
    }

    py::object segment_depth(const py::args& args, const py::kwargs& kwargs) {
        const Args a("segment_depth()", kSegmentDepth, args, kwargs);
        const py::object depth = a.object(0), count = a.object(7);
        py::object out = a.object(6);
        DepthView camera;
        camera.fx = a.number(1);
        camera.fy = a.number(2);
        camera.cx = a.number(3);
        camera.cy = a.number(4);
        camera.metres_per_unit = a.number(5);
        if (!segmenter_) {
            if (is_device_array(depth)) refuse_auto_on_device();
            const DepthInput probe(depth);
            Scratch scratch;
            choose_preset(measure_frame_noise(with_camera(probe.view(scratch), camera)));
        }
        if (is_device_array(depth)) {
            no_device_color(a.object(8));
            device().segment_depth(*segmenter_, depth, camera, out, count);
            return out;
        }
        no_count(count);
        const DepthInput input(depth);
        warn_about_camera(input, camera);
        const ColorInput color(a.object(8), width(), height());
        if (!out.is_none()) color.refuse_alias(check_labels_out(out, width(), height()));
        return run(input, out, true, [&input, &camera, &color](Scratch& s, Segmenter& seg, Result& r) {
            DepthView view = with_camera(input.view(s), camera);
            view.color = color.data(s, view.color_row_step_bytes);
            seg.segment(view, r);
        });
    }

    py::object segment_mask(const py::args& args, const py::kwargs& kwargs) {
        const Args a("segment_mask()", kSegmentMask, args, kwargs);
        if (!segmenter_) {
            throw py::value_error(
                "preset='auto' chooses the preset from a frame's depth, and a mask has none: segment a cloud or a "
                "depth image first, or name the preset");
        }
        const MaskInput input(a.object(0), a.object(1));
        // A mask has no points, so no normals: Result.normals is None for it whatever outputs= asks.
        return run(input, a.object(2), false,
                   [&input](Scratch& s, Segmenter& seg, Result& r) { seg.segment_mask(input.view(s), r); });
    }

    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    [[nodiscard]] const std::string& backend() const { return segmenter_ ? segmenter_->backend_name() : backend_; }
    // None until preset="auto" has chosen, on the first frame.
    [[nodiscard]] py::object params() const {
        return segmenter_ ? py::object(params_to_dict(segmenter_->params())) : py::object(py::none());
    }
    // The preset named, or the one preset="auto" chose (None before the first frame, or without a preset), and why.
    [[nodiscard]] py::object preset() const {
        return preset_name_ ? py::object(py::str(*preset_name_)) : py::object(py::none());
    }
    [[nodiscard]] py::object preset_reason() const {
        return preset_reason_ ? py::object(py::str(*preset_reason_)) : py::object(py::none());
    }
    [[nodiscard]] py::tuple outputs() const {
        py::list names;
        if (outputs_.raw_labels) names.append("raw_labels");
        if (outputs_.fillable_mask) names.append("fillable_mask");
        if (outputs_.normals) names.append("normals");
        if (outputs_.segment_stats) names.append("segment_stats");
        if (outputs_.segment_graph) names.append("segment_graph");
        if (outputs_.segment_tracks) names.append("segment_tracks");
        if (outputs_.track_ids) names.append("track_ids");
        return py::tuple(names);
    }
    // The next frame starts a new stream of tracks (ids from 1 again). Before preset="auto" has made the Segmenter,
    // there is no stream to restart.
    void reset_tracks() {
        const py::gil_scoped_release nogil;
        const std::lock_guard<std::mutex> lock(mutex_);
        if (segmenter_) segmenter_->reset_tracks();
    }
    [[nodiscard]] bool last_input_copied() const { return last_copied_; }
    [[nodiscard]] py::dict timings() {
        std::vector<PassTiming> copy;
        {
            // Without the GIL first: a frame holding the lock may be waiting for it.
            const py::gil_scoped_release nogil;
            const std::lock_guard<std::mutex> lock(mutex_);
            if (segmenter_) copy = segmenter_->last_timings();
        }
        py::dict d;
        for (const PassTiming& t : copy) d[t.pass] = t.milliseconds;
        return d;
    }
    [[nodiscard]] std::string repr() const {
        return "pyrseg.Segmenter(" + std::to_string(width()) + ", " + std::to_string(height()) + ", backend='" +
               backend() + "')";
    }

private:
    // A GPU backend's setup (devices, kernels, buffers) can take a while: other Python threads go on meanwhile,
    // except on preset="auto"'s first frame (release_gil false), where another thread's frame must wait for it.
    void make_segmenter(bool release_gil = true) {
        std::optional<py::gil_scoped_release> nogil;
        if (release_gil) nogil.emplace();
        if (device_) {
            segmenter_.emplace(device_->make_segmenter(width_, height_, params_, outputs_));
        } else if (threads_ != 0) {
            segmenter_.emplace(cpu::make_segmenter(width_, height_, threads_, params_, outputs_));
        } else {
            segmenter_.emplace(width_, height_, params_, backend_, outputs_);
        }
    }

    // preset="auto" on its first frame: the preset the frame's depth suggests, the parameters given over it. The
    // GIL stays held, so that two threads' first frames cannot both choose.
    void choose_preset(const FrameNoise& noise) {
        if (segmenter_) return;
        Outputs outputs;
        py::object cuda_stream = py::none();
        unsigned threads = 0;
        py::dict with_preset(*auto_overrides_);
        with_preset["preset"] = sensor_kind_name(noise.suggested);
        params_ = params_from(with_preset, outputs, cuda_stream, threads);
        preset_name_ = sensor_kind_name(noise.suggested);
        preset_reason_ = noise.reason;
        make_segmenter(false);
    }

    // The checks a Segmenter makes of its size and parameters, before preset="auto" has one.
    void check_plan() const { (void)Segmenter(width_, height_, params_, "cpu"); }

    [[noreturn]] static void refuse_auto_on_device() {
        throw py::value_error(
            "preset='auto' chooses the preset from the first frame's depth on the host: give that frame as a host "
            "array, or name the preset");
    }

    DeviceFrames& device() {
        if (!device_) {
            raise(ErrorCode::invalid_argument,
                  "a CUDA device array (__cuda_array_interface__) was given but this Segmenter runs the " + backend() +
                      " backend: create it with backend='cuda', or copy the array to the host (cupy: .get(), "
                      "torch: .cpu().numpy())");
        }
        return *device_;
    }

    // The warnings of pyrseg::check_depth_camera (a depth scale or intrinsics that are legal but unusual) as Python
    // warnings, once per camera; its errors are raised as the Segmenter would raise them. A stream's warm frames
    // with the same camera skip it (and allocate nothing).
    void warn_about_camera(const DepthInput& input, const DepthView& camera) {
        const std::array<double, 5> now = {camera.fx, camera.fy, camera.cx, camera.cy, camera.metres_per_unit};
        if (camera_checked_ && now == checked_camera_) return;
        Scratch scratch;  // the Segmenter's own may be in use by another thread's frame
        const DepthCameraCheck check = check_depth_camera(with_camera(input.view(scratch), camera));
        for (const std::string& w : check.warnings) {
            if (PyErr_WarnEx(PyExc_UserWarning, ("pyrseg: segment_depth(): " + w).c_str(), 2) != 0) {
                throw py::error_already_set();
            }
        }
        if (check.median_depth_m > 0) {  // as the Segmenter: a frame without data says nothing about the scale
            camera_checked_ = true;
            checked_camera_ = now;
        }
    }

    static void no_count(const py::object& count) {
        if (!count.is_none()) throw py::value_error("count= is for device frames; a host frame's is segment_count");
    }

    // One host frame: the result arrays made with the GIL, the frame and the copies into them without it.
    template <class Input, class Frame>
    py::object run(const Input& input, const py::object& out, bool has_normals, const Frame& frame) {
        const int w = width(), h = height();
        py::array labels = out.is_none() ? new_array(cached.uint32, h, w) : check_labels_out(out, w, h);
        if (!out.is_none()) input.refuse_alias(labels);
        py::object raw = py::none(), mask = py::none(), normals = py::none(), segments = py::none(), graph = py::none();
        py::object tracks = py::none(), track_ids = py::none();
        void* raw_data = nullptr;
        void* mask_data = nullptr;
        void* normals_data = nullptr;
        void* track_ids_data = nullptr;
        if (outputs_.raw_labels) {
            auto a = new_array(cached.uint32, h, w);
            raw_data = a.mutable_data();
            raw = std::move(a);
        }
        if (outputs_.fillable_mask) {
            auto a = new_array(cached.uint8, h, w);
            mask_data = a.mutable_data();
            mask = std::move(a);
        }
        if (outputs_.normals && has_normals) {
            auto a = new_array(cached.float32, h, w, 3);
            normals_data = a.mutable_data();
            normals = std::move(a);
        }
        if (outputs_.track_ids) {
            auto a = new_array(cached.uint32, h, w);
            track_ids_data = a.mutable_data();
            track_ids = std::move(a);
        }
        std::uint32_t count = 0;
        const std::size_t pixels = std::size_t(w) * std::size_t(h);
        {
            const py::gil_scoped_release nogil;
            const std::lock_guard<std::mutex> lock(mutex_);
            frame(scratch_, *segmenter_, result_);
            last_copied_ = input.copies();
            // A Result keeps its buffers' capacity from frame to frame: a size the frame did not give would copy
            // an earlier frame's data, or read past the end.
            const auto check = [](const auto& from, std::size_t n, const char* what) {
                if (from.size() != n) {
                    raise(ErrorCode::internal, std::string("the frame gave ") + std::to_string(from.size()) + " " +
                                                   what + " values, not " + std::to_string(n));
                }
            };
            const auto copy = [&check](void* to, const auto& from, std::size_t n, const char* what) {
                check(from, n, what);
                std::memcpy(to, from.data(), n * sizeof(from[0]));
            };
            check(result_.labels, pixels, "label");
            copy_labels(result_.labels.data(), labels);
            if (raw_data != nullptr) copy(raw_data, result_.raw_labels, pixels, "raw label");
            if (mask_data != nullptr) copy(mask_data, result_.fillable_mask, pixels, "fillable mask");
            if (normals_data != nullptr) copy(normals_data, result_.normals, pixels * 3, "normal");
            if (track_ids_data != nullptr) copy(track_ids_data, result_.track_ids, pixels, "track id");
            count = result_.segment_count;
            // Under the lock, so that another thread's frame cannot overwrite the records being read: a structured
            // array of `dtype` holding a copy of them.
            const auto records = [](const auto& from, PyObject* dtype) {
                const py::gil_scoped_acquire gil;
                const auto k = py::ssize_t(from.size());
                auto a = py::reinterpret_steal<py::array>(PyObject_CallFunction(cached.empty, "nO", k, dtype));
                if (!a) throw py::error_already_set();
                if (k > 0) std::memcpy(a.mutable_data(), from.data(), std::size_t(k) * sizeof(from[0]));
                return py::object(std::move(a));
            };
            if (outputs_.segment_stats) segments = records(result_.segments, cached.stats_dtype);
            if (outputs_.segment_graph) graph = records(result_.graph, cached.graph_dtype);
            // track_ids implies segment_tracks (pyrseg::Outputs): the tracks the ids are of come with them.
            if (outputs_.segment_tracks || outputs_.track_ids) {
                check(result_.tracks, count, "track");
                tracks = records(result_.tracks, cached.track_dtype);
            }
        }
        return obj(cached.result_type)(labels, count, segments, normals, mask, raw, graph, tracks, track_ids);
    }

    Params params_;
    Outputs outputs_;
    int width_ = 0;
    int height_ = 0;
    std::string backend_;                       // resolved at construction
    unsigned threads_ = 0;                      // threads=: the CPU backend's arena of its own (0: the default)
    std::optional<py::dict> auto_overrides_;    // preset="auto": the other keyword arguments, for the first frame
    std::optional<std::string> preset_name_;    // named, or chosen by "auto"
    std::optional<std::string> preset_reason_;  // why "auto" chose it
    std::optional<DeviceFrames> device_;        // before segmenter_: the Segmenter is destroyed first, on its stream
    std::optional<Segmenter> segmenter_;
    Result result_;
    Scratch scratch_;
    bool camera_checked_ = false;  // warn_about_camera: the camera its warnings were last given for
    std::array<double, 5> checked_camera_{};
    std::atomic<bool> last_copied_{false};
    std::mutex mutex_;  // one frame at a time: Python threads may share a Segmenter, and run without the GIL
};

PySegmenter& segmenter_of(py::handle self) {
    return live<PySegmenter>(self, "pyrseg.Segmenter",
                             "the Segmenter was not initialised: call pyrseg.Segmenter(width, height, ...)");
}

// The package pyrseg re-exports its extension _pyrseg's names: its types say pyrseg.X, as users import them.
std::string public_name(const py::module_& m) {
    const auto name = m.attr("__name__").cast<std::string>();
    return name == "_pyrseg" || name == "pyrseg._pyrseg" ? "pyrseg" : name;
}

// --- module-level functions -------------------------------------------------------------------------------------

py::object stats_dtype() {
    py::list names, formats, offsets;
    const auto field = [&](const char* name, const char* format, std::size_t offset) {
        names.append(name);
        formats.append(format);
        offsets.append(offset);
    };
    field("label", "<u4", offsetof(SegmentStats, label));
    field("pixel_count", "<u4", offsetof(SegmentStats, pixel_count));
    field("x_min", "<i4", offsetof(SegmentStats, x_min));
    field("y_min", "<i4", offsetof(SegmentStats, y_min));
    field("x_max", "<i4", offsetof(SegmentStats, x_max));
    field("y_max", "<i4", offsetof(SegmentStats, y_max));
    field("point_sum", "(3,)<i8", offsetof(SegmentStats, point_sum));
    field("normal_sum", "(3,)<i8", offsetof(SegmentStats, normal_sum));
    field("point_shift", "<i4", offsetof(SegmentStats, point_shift));
    field("fillable_count", "<u4", offsetof(SegmentStats, fillable_count));
    // Each exact 128-bit sum as its two halves, value = high * 2**64 + low.
    static_assert(sizeof(WideSum) == 16 && offsetof(WideSum, high) == 8);
    const py::object np = py::module_::import("numpy");
    py::list wide_fields;
    wide_fields.append(py::make_tuple("low", "<u8"));
    wide_fields.append(py::make_tuple("high", "<i8"));
    names.append("point_product_sum");
    formats.append(np.attr("dtype")(py::make_tuple(np.attr("dtype")(wide_fields), py::make_tuple(6))));
    offsets.append(offsetof(SegmentStats, point_product_sum));
    field("z_fixed_min", "<i4", offsetof(SegmentStats, z_fixed_min));
    field("z_fixed_max", "<i4", offsetof(SegmentStats, z_fixed_max));
    field("centroid", "(3,)<f8", offsetof(SegmentStats, centroid));
    field("mean_normal", "(3,)<f8", offsetof(SegmentStats, mean_normal));
    field("covariance", "(6,)<f8", offsetof(SegmentStats, covariance));
    field("z_min", "<f8", offsetof(SegmentStats, z_min));
    field("z_max", "<f8", offsetof(SegmentStats, z_max));
    field("plane_normal", "(3,)<f8", offsetof(SegmentStats, plane_normal));
    field("plane_offset", "<f8", offsetof(SegmentStats, plane_offset));
    field("plane_rms", "<f8", offsetof(SegmentStats, plane_rms));
    field("curvature", "<f8", offsetof(SegmentStats, curvature));
    field("axes", "(3,3)<f8", offsetof(SegmentStats, axes));
    field("extents", "(3,)<f8", offsetof(SegmentStats, extents));
    field("planar", "?", offsetof(SegmentStats, planar));
    py::dict spec;
    spec["names"] = names;
    spec["formats"] = formats;
    spec["offsets"] = offsets;
    spec["itemsize"] = sizeof(SegmentStats);
    return np.attr("dtype")(spec);
}

py::object graph_dtype() {
    py::list names, formats, offsets;
    for (const auto& [name, offset] : {std::pair{"a", offsetof(SegmentEdge, a)},
                                       {"b", offsetof(SegmentEdge, b)},
                                       {"length", offsetof(SegmentEdge, length)},
                                       {"flat", offsetof(SegmentEdge, flat)},
                                       {"convex", offsetof(SegmentEdge, convex)},
                                       {"concave", offsetof(SegmentEdge, concave)},
                                       {"step", offsetof(SegmentEdge, step)}}) {
        names.append(name);
        formats.append("<u4");
        offsets.append(offset);
    }
    py::dict spec;
    spec["names"] = names;
    spec["formats"] = formats;
    spec["offsets"] = offsets;
    spec["itemsize"] = sizeof(SegmentEdge);
    return py::module_::import("numpy").attr("dtype")(spec);
}

py::object track_dtype() {
    py::list names, formats, offsets;
    for (const auto& [name, offset] : {std::pair{"label", offsetof(SegmentTrack, label)},
                                       {"id", offsetof(SegmentTrack, id)},
                                       {"first_frame", offsetof(SegmentTrack, first_frame)},
                                       {"age", offsetof(SegmentTrack, age)},
                                       {"hidden_frames", offsetof(SegmentTrack, hidden_frames)}}) {
        names.append(name);
        formats.append("<u4");
        offsets.append(offset);
    }
    // TrackMatch's value (pyrseg.TrackMatch): one byte.
    static_assert(sizeof(TrackMatch) == 1 && std::is_trivially_copyable_v<SegmentTrack>);
    names.append("how");
    formats.append("u1");
    offsets.append(offsetof(SegmentTrack, how));
    py::dict spec;
    spec["names"] = names;
    spec["formats"] = formats;
    spec["offsets"] = offsets;
    spec["itemsize"] = sizeof(SegmentTrack);
    return py::module_::import("numpy").attr("dtype")(spec);
}

py::list backends() {
    py::list l;
    for (const BackendInfo& b : list_backends()) {
        l.append(obj(cached.backend_type)(b.name, b.available, b.reason, py::cast(b.devices), b.emulated,
                                          b.emulated_device));
    }
    return l;
}

py::dict frame_noise_dict(const FrameNoise& n) {
    py::dict d;
    d["samples"] = n.samples;
    d["median_depth_mm"] = n.median_depth_mm;
    d["second_difference_mm"] = n.second_difference_mm;
    d["whole_mm_share"] = n.whole_mm_share;
    d["level_step_mm_per_m2"] = n.level_step_mm_per_m2;
    d["shadow_holes"] = n.shadow_holes;
    d["left_shadow_share"] = n.left_shadow_share;
    d["suggested"] = sensor_kind_name(n.suggested);
    d["reason"] = n.reason;
    return d;
}

}  // namespace

void bind_segmenter(py::module_& m) {
    m.attr("__version__") = kVersion;
    const py::object numpy = py::module_::import("numpy");
    const py::object namedtuple = py::module_::import("collections").attr("namedtuple");
    const py::str module_name(public_name(m));
    const auto keep = [](const py::object& o) { return o.inc_ref().ptr(); };
    cached.empty = keep(numpy.attr("empty"));
    cached.uint32 = keep(numpy.attr("dtype")("uint32"));
    cached.uint8 = keep(numpy.attr("dtype")("uint8"));
    cached.float32 = keep(numpy.attr("dtype")("float32"));
    cached.stats_dtype = keep(stats_dtype());
    m.attr("segment_stats_dtype") = obj(cached.stats_dtype);
    cached.graph_dtype = keep(graph_dtype());
    m.attr("segment_graph_dtype") = obj(cached.graph_dtype);
    cached.track_dtype = keep(track_dtype());
    m.attr("segment_track_dtype") = obj(cached.track_dtype);
    // How a segment got its id, as segment_track_dtype's `how` holds it: an IntEnum, so that numpy compares the
    // field with it (tracks["how"] == pyrseg.TrackMatch.overlap) and TrackMatch(code).name names a code.
    py::list matches;
    matches.append(py::make_tuple("new_track", int(TrackMatch::new_track)));
    matches.append(py::make_tuple("overlap", int(TrackMatch::overlap)));
    matches.append(py::make_tuple("position", int(TrackMatch::position)));
    const py::object track_match =
        py::module_::import("enum").attr("IntEnum")("TrackMatch", matches, py::arg("module") = module_name);
    track_match.attr("__doc__") =
        "How a segment got its track id (segment_track_dtype's how): new_track (it matched no track), overlap (a "
        "previous frame's segment it shares pixels with, taken greedily by the pixels times the track's age), "
        "position (a track not matched by "
        "overlap, found where the camera's motion put it) (docs/algorithm.md section 11).";
    m.attr("TrackMatch") = track_match;
    cached.result_type = keep(namedtuple("Result",
                                         py::make_tuple("labels", "segment_count", "segments", "normals",
                                                        "fillable_mask", "raw_labels", "graph", "tracks", "track_ids"),
                                         py::arg("module") = module_name));
    m.attr("Result") = obj(cached.result_type);
    m.attr("Result").attr("__doc__") =
        "One frame's results. labels: H x W uint32 (the out= array when given), 0 for no segment; segment_count: "
        "K; segments: K entries of segment_stats_dtype, segment k at k - 1 (outputs 'segment_stats', else None); "
        "normals: H x W x 3 float32, fillable_mask: H x W uint8, raw_labels: H x W uint32 (each None unless asked "
        "for in outputs=); graph: the segment graph, one segment_graph_dtype entry per pair of touching segments "
        "(a < b, their labels; length, the crossings of their boundary; flat, convex, concave, step, the crossings "
        "of each kind), by increasing (a, b) (outputs 'segment_graph', else None); tracks: K entries of "
        "segment_track_dtype, segment k at k - 1 (label, its track id, first_frame, age, hidden_frames, how: a "
        "TrackMatch) (outputs 'segment_tracks' or 'track_ids', else None); track_ids: H x W uint32, each labelled "
        "pixel's track id, 0 where unlabelled (outputs 'track_ids', else None).";
    cached.backend_type = keep(namedtuple(
        "BackendInfo", py::make_tuple("name", "available", "reason", "devices", "emulated", "emulated_device"),
        py::arg("module") = module_name));
    m.attr("BackendInfo") = obj(cached.backend_type);

    // The backend names come from the build's list; pybind11 keeps the pointer, so the text lives as long as the
    // module.
    static std::string segmenter_doc = R"(A segmenter for one backend and one frame size.

Segmenter(width, height, backend=None, *, preset=None, outputs=(), cuda_stream=None, threads=None, **params)

backend: @BACKENDS@"auto", or None for $PYRSEG_BACKEND (else "auto").
preset: a sensor preset (pyrseg.presets()); the parameters given beside it override it. "auto" chooses one from
the first frame's depth (pyrseg.measure_frame_noise) and keeps it: .preset and .preset_reason say which and why,
and .params is None until then.
params: ct, dt, unit_mm, bridge_levels, unjoinable_gap, label_edges, edge_rounds, edge_max_depth_step (edge
rounds after the first stay on surfaces whose depth is within this share), compact, normal_radius, metric ("paper" or
"robust"), normal_window, curvature_stride, dt_per_m2, ct_growth_per_m2; merge (join segments
that meet along a convex or flat boundary), merge_reach, merge_tolerance_mm, merge_tolerance_per_m2,
merge_min_crossings, merge_max_bad_share; color_edge_threshold, color_edge_stride, color_edge_curvature_share (the
colour edge term on frames given color=, and its curvature gate); planar_tolerance_mm, planar_tolerance_per_m2 (when
a segment's statistics call it planar); track_max_distance_mm, track_hold_frames (tracks: how far a segment may be
from where a track was predicted, and how many frames a track unseen is kept) (docs/algorithm.md).
outputs: names among "raw_labels", "fillable_mask", "normals", "segment_stats", "segment_graph", "segment_tracks"
(ids that carry over from frame to frame: the Segmenter's frames are one stream until reset_tracks(); a backend
without tracks raises pyrseg.Error, backend_unavailable), "track_ids" (an image of them).
cuda_stream: the CUDA stream device frames go on (backend "cuda" only): an int cudaStream_t, or a cupy/torch
stream; None is the legacy default stream.
threads: the CPU backend's threads, 1 to 1024, an arena of its own (backend "cpu" only); None shares the oneTBB
threads of the process ($PYRSEG_THREADS, when set, gives every Segmenter that many). The labels do not depend on it.

Every argument of the wrong type is a TypeError naming it; a Segmenter made by Segmenter.__new__ alone raises
TypeError from every member, and a second __init__ on a Segmenter raises TypeError (make a new one).)";
    std::string quoted_names;
    for (const std::string& name : backend_names()) quoted_names += "\"" + name + "\", ";
    segmenter_doc.replace(segmenter_doc.find("@BACKENDS@"), 10, quoted_names);
    py::class_<PySegmenter> segmenter(m, "Segmenter", kLocal, segmenter_doc.c_str());
    segmenter.def(py::init<const py::object&, const py::object&, const py::object&, const py::kwargs&>(),
                  py::arg("width"), py::arg("height"), py::arg("backend") = py::none());
    def_args(segmenter, "segment", kSegment,
             R"(Segments an organized cloud and returns a pyrseg.Result.

points: H x W x 3 (xyz), H x W x 4 (xyz and a pad, PCL's PointXYZ) or H x W x 6 (xyz then normals), float32 (read in
place, any strides) or float64 (converted); normals: None (estimated) or H x W x 3. out: an H x W uint32 array
to write the labels into (its elements distinct, sharing no memory with the inputs). A CUDA device array (backend
"cuda") is segmented on the device, asynchronously on the Segmenter's stream: out= (an H x W uint32 device array) is
then required and returned, and count= (a uint32 device array) receives the segment count. color: None or an H x W x 3
uint8 image registered to the points (R, G, B), for the colour edge term (color_edge_threshold; host frames only).)",
             [](const py::object& self, const py::args& args, const py::kwargs& kwargs) {
                 return segmenter_of(self).segment(args, kwargs);
             });
    def_args(segmenter, "segment_depth", kSegmentDepth,
             R"(Segments a depth image back-projected with the pinhole intrinsics: H x W uint16 or float32 in place,
float64 converted, any other integer dtype converted to uint16 when its values are 0..65535 (PIL gives int32 for
16-bit PNGs). metres_per_unit is the SDK's depth scale (0.001 for millimetres, 1 for float metres). color: None or an
H x W x 3 uint8 image registered to the depth (R, G, B), for the colour edge term (color_edge_threshold).)",
             [](const py::object& self, const py::args& args, const py::kwargs& kwargs) {
                 return segmenter_of(self).segment_depth(args, kwargs);
             });
    def_args(segmenter, "segment_mask", kSegmentMask,
             "Labels a caller-made fillable mask (H x W bool or uint8); valid: which other pixels edge labelling "
             "may label (None: all). The result's fillable_mask is the mask (0 or 1) and its normals None: a mask has "
             "no points.",
             [](const py::object& self, const py::args& args, const py::kwargs& kwargs) {
                 return segmenter_of(self).segment_mask(args, kwargs);
             });
    segmenter.def(
        "reset_tracks", [](const py::object& self) { segmenter_of(self).reset_tracks(); },
        "With outputs 'segment_tracks' or 'track_ids', the next frame starts a new stream: no track carries over "
        "into it, and its ids start at 1 again.");
    segmenter.def_property_readonly("width", [](const py::object& self) { return segmenter_of(self).width(); })
        .def_property_readonly("height", [](const py::object& self) { return segmenter_of(self).height(); })
        .def_property_readonly("backend", [](const py::object& self) { return segmenter_of(self).backend(); })
        .def_property_readonly("params", [](const py::object& self) { return segmenter_of(self).params(); })
        .def_property_readonly("preset", [](const py::object& self) { return segmenter_of(self).preset(); })
        .def_property_readonly("preset_reason",
                               [](const py::object& self) { return segmenter_of(self).preset_reason(); })
        .def_property_readonly("outputs", [](const py::object& self) { return segmenter_of(self).outputs(); })
        .def_property_readonly(
            "timings", [](const py::object& self) { return segmenter_of(self).timings(); },
            "Milliseconds of each pass of the last host frame, in pass order.")
        .def_property_readonly(
            "last_input_copied", [](const py::object& self) { return segmenter_of(self).last_input_copied(); },
            "Whether the last host frame had to be converted (float64, another integer depth, or a layout pyrseg's "
            "views cannot describe) rather than read in place.")
        .def("__repr__", [](const py::object& self) {
            if (py::isinstance<PySegmenter>(self) && !initialised(self))
                return std::string("<pyrseg.Segmenter, not initialised>");
            return segmenter_of(self).repr();
        });
    refuse_second_init(segmenter, "pyrseg.Segmenter");

    m.def("backends", &backends, "Every backend pyrseg knows, in preference order, and whether it can run here.");
    static constexpr Param kChooseBackend[] = {{"requested", "None"}};
    def_args(m, "choose_backend", kChooseBackend, "The backend a request resolves to, and why: (name, reason).",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const Args a("choose_backend()", kChooseBackend, args, kwargs);
                 const py::object requested = a.object(0);
                 const BackendChoice c = choose_backend(requested.is_none() ? std::string() : a.text(0, ""));
                 return py::make_tuple(c.name, c.reason);
             });
    m.def(
        "presets",
        [] {
            py::dict d;
            for (const SensorKind k : sensor_kinds()) d[sensor_kind_name(k)] = sensor_kind_summary(k);
            return d;
        },
        "The sensor presets: name -> what it suits.");
    static constexpr Param kPreset[] = {{"name"}, {"unit_mm", "1.0"}};
    def_args(m, "preset", kPreset, "A sensor preset's parameters, for clouds in units of unit_mm mm.",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const Args a("preset()", kPreset, args, kwargs);
                 return params_to_dict(sensor_preset(preset_kind(a.text(0, "")), a.number(1, 1.0)));
             });
    m.def(
        "default_params", [] { return params_to_dict(Params{}); }, "The algorithm contract's default parameters.");
    static constexpr Param kFrameNoise[] = {{"points"}, {"unit_mm", "1.0"}};
    def_args(m, "measure_frame_noise", kFrameNoise,
             "How noisy a frame's depth is, and which preset it suggests (pyrseg/presets.hpp).",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const Args a("measure_frame_noise()", kFrameNoise, args, kwargs);
                 const double unit_mm = a.number(1, 1.0);
                 const CloudInput input(a.object(0), py::none(), -1, -1);
                 Scratch scratch;
                 FrameNoise n;
                 {
                     const py::gil_scoped_release nogil;
                     n = measure_frame_noise(input.view(scratch), unit_mm);
                 }
                 return frame_noise_dict(n);
             });
    static constexpr Param kDepthNoise[] = {{"depth"}, {"metres_per_unit"}};
    def_args(m, "measure_depth_noise", kDepthNoise,
             "measure_frame_noise for a depth image (H x W uint16 or float32 samples, metres_per_unit as in "
             "Segmenter.segment_depth): which preset it suggests, and why.",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const Args a("measure_depth_noise()", kDepthNoise, args, kwargs);
                 const DepthInput input(a.object(0));
                 Scratch scratch;
                 DepthView view = input.view(scratch);
                 view.metres_per_unit = a.number(1);
                 FrameNoise n;
                 {
                     const py::gil_scoped_release nogil;
                     n = measure_frame_noise(view);
                 }
                 return frame_noise_dict(n);
             });
}

void bind_errors(py::module_& m) {
    py::enum_<ErrorCode>(m, "ErrorCode", kLocal)
        .value("invalid_argument", ErrorCode::invalid_argument)
        .value("invalid_parameter", ErrorCode::invalid_parameter)
        .value("size_mismatch", ErrorCode::size_mismatch)
        .value("image_too_large", ErrorCode::image_too_large)
        .value("backend_unavailable", ErrorCode::backend_unavailable)
        .value("out_of_memory", ErrorCode::out_of_memory)
        .value("io", ErrorCode::io)
        .value("format", ErrorCode::format)
        .value("internal", ErrorCode::internal);
    const std::string qualified = public_name(m) + ".Error";
    cached.error = PyErr_NewExceptionWithDoc(qualified.c_str(),
                                             "A pyrseg failure: .code (pyrseg.ErrorCode) and .message, as the C++ "
                                             "pyrseg::Error carries them.",
                                             PyExc_RuntimeError, nullptr);
    if (cached.error == nullptr) throw py::error_already_set();
    m.attr("Error") = obj(cached.error);
    // NOLINTNEXTLINE(performance-unnecessary-value-param): pybind11 takes void(*)(std::exception_ptr)
    // std::bad_alloc too: a backend or the bindings themselves may let one out where the library's own checks
    // (Error(out_of_memory)) did not foresee it, and every backend should say the same for the same failure.
    // NOLINTNEXTLINE(performance-unnecessary-value-param): pybind11's translator type takes it by value
    py::register_local_exception_translator([](std::exception_ptr p) {
        const auto set = [](const Error& e) {
            const py::object instance = obj(cached.error)(e.what());
            instance.attr("code") = py::cast(e.code());
            instance.attr("message") = e.what();
            PyErr_SetObject(cached.error, instance.ptr());
        };
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error& e) {
            set(e);
        } catch (const std::bad_alloc&) {
            set(Error(ErrorCode::out_of_memory,
                      "out of memory: allocating the buffers of this image size failed "
                      "(std::bad_alloc)"));
        }
    });
}

namespace {

const char* metric_name(Metric m) {
    return m == Metric::robust ? "robust" : "paper";
}

}  // namespace

py::dict params_to_dict(const Params& p) {
    py::dict d;
    d["ct"] = p.ct;
    d["dt"] = p.dt;
    d["unit_mm"] = p.unit_mm;
    d["bridge_levels"] = p.bridge_levels ? py::object(py::int_(*p.bridge_levels)) : py::object(py::none());
    d["unjoinable_gap"] = p.unjoinable_gap ? py::object(py::int_(*p.unjoinable_gap)) : py::object(py::none());
    d["label_edges"] = p.label_edges;
    d["edge_rounds"] = p.edge_rounds;
    d["edge_max_depth_step"] = p.edge_max_depth_step;
    d["compact"] = p.compact;
    d["normal_radius"] = p.normal_radius;
    d["metric"] = metric_name(p.metric);
    d["normal_window"] = p.normal_window;
    d["curvature_stride"] = p.curvature_stride;
    d["dt_per_m2"] = p.dt_per_m2;
    d["ct_growth_per_m2"] = p.ct_growth_per_m2;
    d["merge"] = p.merge;
    d["merge_reach"] = p.merge_reach;
    d["merge_tolerance_mm"] = p.merge_tolerance_mm;
    d["merge_tolerance_per_m2"] = p.merge_tolerance_per_m2;
    d["merge_min_crossings"] = p.merge_min_crossings;
    d["merge_max_bad_share"] = p.merge_max_bad_share;
    d["color_edge_threshold"] = p.color_edge_threshold;
    d["color_edge_stride"] = p.color_edge_stride;
    d["color_edge_curvature_share"] = p.color_edge_curvature_share;
    d["planar_tolerance_mm"] = p.planar_tolerance_mm;
    d["planar_tolerance_per_m2"] = p.planar_tolerance_per_m2;
    d["track_max_distance_mm"] = p.track_max_distance_mm;
    d["track_hold_frames"] = p.track_hold_frames;
    return d;
}

py::dtype segment_stats_dtype() {
    return py::reinterpret_borrow<py::dtype>(obj(cached.stats_dtype));
}

void raise(ErrorCode code, const std::string& message) {
    throw Error(code, message);
}

}  // namespace pyrseg::python
