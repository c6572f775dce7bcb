#pragma once
// CUDA device arrays (__cuda_array_interface__: cupy, torch, numba) as frames of a CUDA Segmenter, through
// pyrseg/cuda.hpp: read and written in device memory, queued on the Segmenter's stream, never copied to the host.
#include <cstdint>

#include "bindings.hpp"
#include "pyrseg/depth.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::python {

[[nodiscard]] bool is_device_array(const py::handle& obj);

class DeviceFrames {
public:
    // True when the module was built with pyrseg's CUDA backend.
    [[nodiscard]] static bool built();
    // A Segmenter whose work goes on `stream` (cuda_stream=: None or 0 for the legacy default stream, an int
    // cudaStream_t, or a stream object with .ptr (cupy) or .cuda_stream (torch)).
    DeviceFrames(const py::object& stream);
    DeviceFrames(const DeviceFrames&) = delete;
    DeviceFrames& operator=(const DeviceFrames&) = delete;
    ~DeviceFrames();
    [[nodiscard]] Segmenter make_segmenter(int width, int height, const Params& params, const Outputs& outputs) const;

    // Queue one frame (no wait). out: H x W uint32 device array; count: None or a device uint32 array.
    void segment_cloud(Segmenter& segmenter, const py::object& points, const py::object& normals, const py::object& out,
                       const py::object& count);
    // camera: the DepthView's metres per unit and intrinsics; the rest comes from the array.
    void segment_depth(Segmenter& segmenter, const py::object& depth, const DepthView& camera, const py::object& out,
                       const py::object& count);

private:
    std::uintptr_t stream_ = 0;
    void* event_ = nullptr;  // cudaEvent_t: the producers' streams are made to precede the frame through it
};

}  // namespace pyrseg::python
