#pragma once
// The CUDA backend's gpu::Device as the interop functions (cuda_interop.cpp, pyrseg/cuda.hpp) reach it: on a
// non-blocking stream of pyrseg's own, or on the caller's stream. Plain C++ over the CUDA runtime's header; the
// implementation (and the kernels) is cuda_backend.cu.
#include <cuda_runtime_api.h>

#include <memory>

#include "core/gpu/device.hpp"

namespace pyrseg::cuda {

class CudaDevice : public gpu::Device {
public:
    // The CUDA device's ordinal, and the stream every command of the Segmenter goes on.
    [[nodiscard]] virtual int ordinal() const = 0;
    [[nodiscard]] virtual cudaStream_t stream() const = 0;
    // true: the stream is the caller's (pyrseg/cuda.hpp), and the device takes device-resident frames.
    [[nodiscard]] virtual bool callers_stream() const = 0;
};

// On a non-blocking stream of pyrseg's own, on CUDA device `device`.
[[nodiscard]] std::unique_ptr<CudaDevice> make_device(int device);

// On the caller's `stream` of CUDA device `device` (not owned: it must outlive the device). Commands go on that
// stream only; device frames are queued at submit() without a host wait, host frames wait for the stream.
[[nodiscard]] std::unique_ptr<CudaDevice> make_device(int device, cudaStream_t stream);

// Makes `device` the calling thread's current CUDA device for the guard's life, then makes the one that was current
// again; calls nothing more when it already is. Throws pyrseg::Error when CUDA refuses.
class CurrentDevice {
public:
    explicit CurrentDevice(int device);
    ~CurrentDevice();
    CurrentDevice(const CurrentDevice&) = delete;
    CurrentDevice& operator=(const CurrentDevice&) = delete;

private:
    int previous_ = -1;  // -1: nothing to restore
};

}  // namespace pyrseg::cuda
