#pragma once
// Arguments as a hostile caller passes them (issue 32): every parameter is taken as a Python object and converted
// here, so that a wrong type is a TypeError naming the function, the parameter and what it wants, and a missing or
// unknown argument is a short TypeError naming it. pybind11's own messages for both ("Unable to cast Python
// instance..." and "incompatible function arguments ... Invoked with: <every argument's repr>") name no parameter
// and print whole arrays.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "bindings.hpp"

namespace pyrseg::python {

// Each raises TypeError for a value of another type and ValueError for one out of range; `function` and `name`
// say whose parameter it is ("segment_depth()", "fx").
double number(const char* function, const char* name, py::handle v);
long long integer(const char* function, const char* name, py::handle v, long long lo, long long hi);
std::uint64_t unsigned_integer(const char* function, const char* name, py::handle v);
bool boolean(const char* function, const char* name, py::handle v);
std::string text(const char* function, const char* name, py::handle v);
std::filesystem::path path(const char* function, const char* name, py::handle v);

struct Param {
    const char* name;
    const char* default_text = nullptr;  // as the signature shows the default; nullptr: required
};

// One call's arguments bound to the parameters as Python binds them: positional first, then by keyword. Raises
// TypeError as Python does for too many, unknown, repeated or missing arguments, naming them and never printing a
// value. Allocates nothing unless it raises (a frame's call goes through it).
class Args {
public:
    static constexpr std::size_t kMax = 12;
    Args(const char* function, std::span<const Param> params, const py::args& args, const py::kwargs& kwargs);

    [[nodiscard]] bool given(std::size_t i) const { return values_[i] != nullptr; }
    // The argument, or None when not given.
    [[nodiscard]] py::object object(std::size_t i) const;
    [[nodiscard]] double number(std::size_t i) const { return python::number(function_, name(i), values_[i]); }
    [[nodiscard]] double number(std::size_t i, double otherwise) const { return given(i) ? number(i) : otherwise; }
    [[nodiscard]] int integer(std::size_t i, int otherwise) const;
    [[nodiscard]] bool boolean(std::size_t i, bool otherwise) const {
        return given(i) ? python::boolean(function_, name(i), values_[i]) : otherwise;
    }
    [[nodiscard]] std::string text(std::size_t i, const char* otherwise) const {
        return given(i) ? python::text(function_, name(i), values_[i]) : std::string(otherwise);
    }
    [[nodiscard]] std::filesystem::path path(std::size_t i) const {
        return python::path(function_, name(i), values_[i]);
    }
    [[nodiscard]] const char* function() const { return function_; }
    [[nodiscard]] const char* name(std::size_t i) const { return params_[i].name; }

private:
    const char* function_;
    std::span<const Param> params_;
    std::array<PyObject*, kMax> values_{};
};

// "name(a, b, c=None)": the first line of a docstring, as pybind11 would write it for named arguments.
std::string signature(const char* name, std::span<const Param> params);

// Defines scope.name as f (which takes the call's py::args and py::kwargs, after self for a method) with a
// docstring that starts with the parameters' signature.
template <class Scope, class F>
void def_args(Scope& scope, const char* name, std::span<const Param> params, const std::string& doc, F&& f) {
    py::options options;
    options.disable_function_signatures();
    const std::string text = signature(name, params) + "\n\n" + doc;
    scope.def(name, std::forward<F>(f), text.c_str());
}

std::string type_name(py::handle v);

// `obj` as a numpy array, viewed where numpy can (arrays, buffers, CPU tensors) and made otherwise (lists).
// TypeError "<what> must be an array, not None" for None; ValueError naming `what` with numpy's own reason where
// numpy cannot make an array of it (a ragged list).
py::array as_array(const py::object& obj, const std::string& what);

// Whether a pybind11 instance has had its C++ object made: T.__new__(T) makes the Python object alone, and
// pybind11 would hand its methods uninitialised memory.
[[nodiscard]] bool initialised(py::handle self);
// self's C++ object, or TypeError `message` when it was never made.
template <class T>
T& live(py::handle self, const char* type, const char* message) {
    // self is any object when a method is called through the class (Segmenter.segment(5, ...)).
    if (!py::isinstance<T>(self))
        throw py::type_error(std::string("self must be a ") + type + ", got " + type_name(self));
    if (!initialised(self)) throw py::type_error(message);
    return self.cast<T&>();
}
// Replaces cls.__init__ by one that refuses an object already initialised: pybind11 silently ignores a second
// __init__ (its C++ object cannot be made twice), leaving the caller to think it took the new arguments.
void refuse_second_init(const py::object& cls, const char* type_name);

}  // namespace pyrseg::python
