#pragma once
// What a GPU API implements for pyrseg: buffers, transfers, dispatches of the kernel table's entry points,
// timestamps, submit-and-wait. Everything else of a GPU backend (the passes, the buffer table, the memory checks,
// the fills' convergence, compaction, statistics, read-back) is core/gpu/gpu_executor.cpp, once for all of them.
// OpenMM's ComputeContext is the model: the backends differ only where their APIs do.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/device_frame.hpp"
#include "pyrseg/segmenter.hpp"
#include "shaders/pyr_kernels.h"

namespace pyrseg::gpu {

// The kernel table (shaders/pyr_kernels.h) as host ids.
enum class Kernel : std::uint32_t {
#define PYR_HOST_KERNEL_ID(name, NAME, dims) name,
    PYR_KERNEL_TABLE(PYR_HOST_KERNEL_ID)
#undef PYR_HOST_KERNEL_ID
        count
};
inline constexpr std::size_t kKernelCount = std::size_t(Kernel::count);
// pyr_k_<name>, PYR_ENTRY_<NAME>, and the kernel's grid: 1 (a count), 2 (width x height) or 3 (workgroups).
[[nodiscard]] const char* kernel_entry_name(Kernel k);  // "pyr_k_normals"
[[nodiscard]] const char* kernel_glsl_name(Kernel k);   // "NORMALS" (PYR_ENTRY_NORMALS)
[[nodiscard]] int kernel_dims(Kernel k);

// A dispatch's argument words (shaders/pyr_entries.h lists each kernel's).
struct Args {
    std::array<std::uint32_t, PYR_ARG_WORDS> words{};
};

// The buffer table (shaders/pyr_buffers.h) as host ids, in binding order. Sizes come from the plan
// (gpu::buffer_sizes); the mask holds mask_texel_bytes per texel.
enum class Buffer : std::uint32_t {
#define PYR_HOST_BUFFER_ID(name, index, TYPE, QUAL) name,
    PYR_BUFFER_TABLE(PYR_HOST_BUFFER_ID)
#undef PYR_HOST_BUFFER_ID
        count
};
inline constexpr std::size_t kBufferCount = std::size_t(Buffer::count);
#define PYR_HOST_BUFFER_INDEX(name, index, TYPE, QUAL) \
    static_assert(std::uint32_t(Buffer::name) == (index), "shaders/pyr_buffers.h: " #name "'s index");
PYR_BUFFER_TABLE(PYR_HOST_BUFFER_INDEX)
#undef PYR_HOST_BUFFER_INDEX
static_assert(kBufferCount == PYR_BUFFER_COUNT, "shaders/pyr_buffers.h: PYR_BUFFER_COUNT");
[[nodiscard]] const char* buffer_name(Buffer b);
using BufferSizes = std::array<std::size_t, kBufferCount>;  // bytes

// What a device can fail with mid-frame, in API-neutral terms: each backend's Device::fail_like turns one into its
// API's own error (the fault hook of core/gpu/device_fault.hpp fails a device through it).
enum class Fault : std::uint8_t {
    out_of_memory,  // VK_ERROR_OUT_OF_DEVICE_MEMORY, CL_MEM_OBJECT_ALLOCATION_FAILURE, cudaErrorMemoryAllocation
    device_lost,    // VK_ERROR_DEVICE_LOST, CL_OUT_OF_RESOURCES (a faulted context), cudaErrorLaunchFailure
};
[[nodiscard]] const char* fault_name(Fault f);

struct DeviceLimits {
    BufferSizes max_buffer_bytes{};    // per buffer, the largest one the device can allocate and its kernels bind
    std::string max_buffer_what;       // where those limits come from, for errors: "maxStorageBufferRange"
    std::size_t memory_bytes = 0;      // what all buffers of a Segmenter may take together
    std::string memory_what;           // "the largest heap", "free memory"
    std::size_t mask_texel_bytes = 1;  // 1, or 4 where the shading language has no byte access (GLSL)
};

class Device {
public:
    virtual ~Device() = default;
    Device() = default;
    Device(const Device&) = delete;
    Device& operator=(const Device&) = delete;

    [[nodiscard]] virtual std::string description() const = 0;
    [[nodiscard]] virtual DeviceLimits limits() const = 0;
    // Once, before anything else; the executor has checked the sizes against limits(). The image width is part of
    // every kernel's context (PYR_W).
    virtual void allocate(const BufferSizes& sizes, std::uint32_t image_width) = 0;

    // Queued in order with the dispatches. upload reads `src` before it returns or before finish() returns (the
    // caller keeps it until then); download's `dst` is written by the time finish() returns.
    virtual void upload(Buffer b, std::size_t offset, const void* src, std::size_t bytes) = 0;
    virtual void download(Buffer b, std::size_t offset, void* dst, std::size_t bytes) = 0;
    virtual void zero(Buffer b, std::size_t offset, std::size_t bytes) = 0;
    // A 1D kernel over `nx` invocations (ny = 1), or a 2D kernel over nx x ny texels; nothing when either is 0.
    virtual void dispatch(Kernel k, std::uint32_t nx, std::uint32_t ny, const Args& args) = 0;

    // A timestamp: the pass `pass` starts here (nullptr: the frame ends here).
    virtual void mark(const char* pass) = 0;
    // Submits what is queued and waits for it.
    virtual void finish() = 0;
    // After finish(): overwrites `timings` (the pipeline's host times, same pass names) with the device's times
    // between marks of the frame, and returns true; false when the device keeps none.
    virtual bool pass_times(std::vector<PassTiming>& timings) = 0;
    // A new frame starts: forget the last frame's marks.
    virtual void begin_frame() = 0;

    // Device-resident frames (core/device_frame.hpp), on a device made on the caller's context. The defaults throw
    // pyrseg::Error: the device has no caller's buffers.
    //
    // `rows` rows of `row_bytes` bytes between one of the caller's buffers, rows `pitch` bytes apart from its
    // offset on, and one of pyrseg's, packed from `offset` on; queued in order with the dispatches.
    virtual void copy_in(Buffer dst, std::size_t offset, const core::ExternalBuffer& src, std::size_t pitch,
                         std::size_t row_bytes, std::size_t rows);
    virtual void copy_out(const core::ExternalBuffer& dst, std::size_t pitch, Buffer src, std::size_t offset,
                          std::size_t row_bytes, std::size_t rows);
    // A small upload (at most 64 KiB at a time: the device's constant tables) queued in order with the
    // dispatches of a device-resident frame, `src` read before it returns: the frame may run long after.
    virtual void upload_inline(Buffer b, std::size_t offset, const void* src, std::size_t bytes);
    // Ends a device-resident frame: what is queued goes to the device in the API's own order (the caller's queue,
    // stream, command buffer or semaphores), with no host wait.
    virtual void submit();

    // Throws exactly what this API's error path throws when `what` fails with the API's code for `fault`, so that
    // an injected fault reads like a real one. The default (a device without it) throws ErrorCode::internal.
    [[noreturn]] virtual void fail_like(Fault fault, const char* what) const;
};

}  // namespace pyrseg::gpu
