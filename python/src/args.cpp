#include "args.hpp"

#include <climits>
#include <cstring>
#include <utility>

#include <pybind11/stl/filesystem.h>

namespace pyrseg::python {
namespace {

[[noreturn]] void wrong_type(const char* function, const char* name, const char* want, py::handle v) {
    throw py::type_error(std::string(function) + ": " + name + " must be " + want + ", got " + type_name(v));
}

bool is_numpy_bool(py::handle v) {
    const char* n = Py_TYPE(v.ptr())->tp_name;
    return std::strcmp(n, "numpy.bool_") == 0 || std::strcmp(n, "numpy.bool") == 0;
}

}  // namespace

std::string type_name(py::handle v) {
    return v ? Py_TYPE(v.ptr())->tp_name : "nothing";
}

double number(const char* function, const char* name, py::handle v) {
    // Not strings: float("1") would parse one. __float__ and __index__ serve (numpy scalars among them).
    if (!v || v.is_none() || PyUnicode_Check(v.ptr()) || PyBytes_Check(v.ptr())) {
        wrong_type(function, name, "a number (int or float)", v);
    }
    const double d = PyFloat_AsDouble(v.ptr());
    if (d == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        wrong_type(function, name, "a number (int or float)", v);
    }
    return d;
}

long long integer(const char* function, const char* name, py::handle v, long long lo, long long hi) {
    // Not floats, even integral ones, as range() takes none; __index__ serves (numpy integers).
    if (!v || v.is_none() || PyFloat_Check(v.ptr()) || !PyIndex_Check(v.ptr())) {
        wrong_type(function, name, "an integer", v);
    }
    const py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
    if (!i) {
        PyErr_Clear();
        wrong_type(function, name, "an integer", v);
    }
    int overflow = 0;
    const long long value = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
    if (value == -1 && PyErr_Occurred()) throw py::error_already_set();
    if (overflow != 0 || value < lo || value > hi) {
        throw py::value_error(std::string(function) + ": " + name + " must be in " + std::to_string(lo) + ".." +
                              std::to_string(hi) + ", got " + py::str(i).cast<std::string>());
    }
    return value;
}

std::uint64_t unsigned_integer(const char* function, const char* name, py::handle v) {
    if (!v || v.is_none() || PyFloat_Check(v.ptr()) || !PyIndex_Check(v.ptr())) {
        wrong_type(function, name, "an integer", v);
    }
    const py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
    if (!i) {
        PyErr_Clear();
        wrong_type(function, name, "an integer", v);
    }
    const unsigned long long value = PyLong_AsUnsignedLongLong(i.ptr());
    if (value == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
        PyErr_Clear();
        throw py::value_error(std::string(function) + ": " + name + " must be in 0.." + std::to_string(ULLONG_MAX) +
                              ", got " + py::str(i).cast<std::string>());
    }
    return value;
}

bool boolean(const char* function, const char* name, py::handle v) {
    if (v && (PyBool_Check(v.ptr()) || is_numpy_bool(v))) return PyObject_IsTrue(v.ptr()) == 1;
    // 0 and 1 as C would write them; any other value (a string, None, 2) is more likely a mistake than a wish.
    if (v && PyLong_CheckExact(v.ptr())) {
        const long value = PyLong_AsLong(v.ptr());
        if (value == 0 || value == 1) return value == 1;
        PyErr_Clear();
    }
    wrong_type(function, name, "True or False", v);
}

std::string text(const char* function, const char* name, py::handle v) {
    if (!v || !PyUnicode_Check(v.ptr())) wrong_type(function, name, "a str", v);
    return v.cast<std::string>();
}

std::filesystem::path path(const char* function, const char* name, py::handle v) {
    py::detail::make_caster<std::filesystem::path> caster;
    if (!v || v.is_none() || !caster.load(v, true)) {
        PyErr_Clear();
        wrong_type(function, name, "a path (str or os.PathLike)", v);
    }
    return py::detail::cast_op<std::filesystem::path>(std::move(caster));
}

Args::Args(const char* function, std::span<const Param> params, const py::args& args, const py::kwargs& kwargs)
    : function_(function), params_(params) {
    const std::size_t n = params.size();
    const auto given = std::size_t(PyTuple_GET_SIZE(args.ptr()));
    if (given > n) {
        throw py::type_error(std::string(function) + " takes at most " + std::to_string(n) + " arguments (" +
                             std::to_string(given) + " given)");
    }
    for (std::size_t i = 0; i < given; ++i) values_[i] = PyTuple_GET_ITEM(args.ptr(), py::ssize_t(i));
    if (kwargs.ptr() != nullptr) {
        PyObject* key = nullptr;
        PyObject* value = nullptr;
        py::ssize_t pos = 0;
        while (PyDict_Next(kwargs.ptr(), &pos, &key, &value)) {
            std::size_t i = 0;
            while (i < n && PyUnicode_CompareWithASCIIString(key, params[i].name) != 0) ++i;
            if (i == n) {
                std::string names;
                for (const Param& p : params) names += (names.empty() ? "" : ", ") + std::string(p.name);
                throw py::type_error(std::string(function) + " got an unexpected keyword argument '" +
                                     py::str(key).cast<std::string>() + "'; its arguments: " + names);
            }
            if (values_[i] != nullptr) {
                throw py::type_error(std::string(function) + " got multiple values for argument '" + params[i].name +
                                     "'");
            }
            values_[i] = value;
        }
    }
    std::string missing;
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (values_[i] == nullptr && params[i].default_text == nullptr) {
            missing += (missing.empty() ? "'" : ", '") + std::string(params[i].name) + "'";
            ++count;
        }
    }
    if (count > 0) {
        throw py::type_error(std::string(function) + " missing " + std::to_string(count) + " required argument" +
                             (count > 1 ? "s: " : ": ") + missing);
    }
}

py::object Args::object(std::size_t i) const {
    return given(i) ? py::reinterpret_borrow<py::object>(values_[i]) : py::object(py::none());
}

int Args::integer(std::size_t i, int otherwise) const {
    return given(i) ? int(python::integer(function_, name(i), values_[i], INT_MIN, INT_MAX)) : otherwise;
}

std::string signature(const char* name, std::span<const Param> params) {
    std::string s = std::string(name) + "(";
    for (std::size_t i = 0; i < params.size(); ++i) {
        s += (i > 0 ? ", " : "") + std::string(params[i].name);
        if (params[i].default_text != nullptr) s += std::string("=") + params[i].default_text;
    }
    return s + ")";
}

bool initialised(py::handle self) {
    // pybind11's own test (its metaclass's, after __init__): the holder is made with the C++ object.
    auto* inst = reinterpret_cast<py::detail::instance*>(self.ptr());
    return inst->get_value_and_holder(nullptr, false).holder_constructed();
}

void refuse_second_init(const py::object& cls, const char* type_name) {
    const py::object init = cls.attr("__init__");
    const std::string doc = py::str(init.attr("__doc__"));
    const std::string message = std::string(type_name) +
                                ".__init__ on an object already initialised: its size and backend cannot change; "
                                "make a new " +
                                type_name;
    py::options options;
    options.disable_function_signatures();
    cls.attr("__init__") = py::cpp_function(
        [init, cls, message](const py::object& self, const py::args& args, const py::kwargs& kwargs) {
            if (py::isinstance(self, cls) && initialised(self)) throw py::type_error(message);
            init(self, *args, **kwargs);
        },
        // Not named __init__: pybind11 takes a function of that name for a constructor, and ignores a second call
        // of a constructor before the function could refuse it.
        py::name("_init_once"), py::is_method(cls), py::doc(doc.c_str()));
}

py::array as_array(const py::object& obj, const std::string& what) {
    if (obj.is_none()) throw py::type_error(what + " must be an array, not None");
    py::array a = py::array::ensure(obj);
    if (a) return a;
    // ensure() clears numpy's exception; numpy.asarray raises it again, with numpy's reason.
    std::string reason = "numpy cannot make one of a " + type_name(obj);
    try {
        a = py::module_::import("numpy").attr("asarray")(obj);
    } catch (const py::error_already_set& e) {
        reason = py::str(e.value()).cast<std::string>();
    }
    throw py::value_error(what + " cannot be made an array: " + reason);
}

}  // namespace pyrseg::python
