#pragma once
// Host staging memory a GPU backend copies frames through (mapped memory on Vulkan, pinned memory on CUDA): between
// two finish() calls, uploads and downloads are packed from offset 0 of their areas, and each download reaches its
// destination once the device's copies are done.
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "core/gpu/device.hpp"
#include "core/gpu/host_frame.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::gpu {

// The staging areas a device needs for the executor's transfers between two waits: in, the points, normals and colour;
// out, the results (StagedResults), the segment count and the statistics words (within the lut buffer's size); each
// with room for the arena's alignment.
struct StagingBytes {
    std::size_t upload;
    std::size_t download;
};
inline StagingBytes staging_bytes(const BufferSizes& sizes) {
    constexpr std::size_t kAlignmentRoom = 256;
    const std::size_t pixels = sizes[std::size_t(Buffer::out)] / 4;
    return {sizes[std::size_t(Buffer::points)] + sizes[std::size_t(Buffer::normals)] +
                sizes[std::size_t(Buffer::color)] + 2 * kAlignmentRoom,
            StagedResults::kBytesPerPixel * pixels + sizes[std::size_t(Buffer::lut)] + kAlignmentRoom};
}

class StagingArena {
public:
    StagingArena() { downloads_.reserve(16); }

    // The areas (owned by the backend, alive as long as the arena is used).
    void reset(unsigned char* up, std::size_t up_bytes, unsigned char* down, std::size_t down_bytes) {
        up_ = up;
        up_capacity_ = up_bytes;
        down_ = down;
        down_capacity_ = down_bytes;
        up_used_ = 0;
        down_used_ = 0;
        downloads_.clear();
    }

    // Copies `src` into the upload area; returns its offset there, for the device's copy to the buffer.
    std::size_t stage_upload(const void* src, std::size_t bytes) {
        const std::size_t at = take(up_used_, up_capacity_, bytes, "upload");
        std::memcpy(up_ + at, src, bytes);
        return at;
    }

    // Room in the download area for `bytes` that go to `dst` once complete() is called; returns the offset.
    std::size_t stage_download(void* dst, std::size_t bytes) {
        const std::size_t at = take(down_used_, down_capacity_, bytes, "download");
        downloads_.push_back({dst, at, bytes});
        return at;
    }

    // After the device's copies into the download area: every download to its destination; both areas start over.
    void complete() {
        for (const Download& d : downloads_) std::memcpy(d.dst, down_ + d.at, d.bytes);
        restart();
    }

    // Both areas start over, and pending downloads are dropped (a frame abandoned by an error).
    void restart() {
        downloads_.clear();
        up_used_ = 0;
        down_used_ = 0;
    }

private:
    struct Download {
        void* dst;
        std::size_t at;
        std::size_t bytes;
    };

    // `bytes` from where the last take ended (16-byte aligned).
    static std::size_t take(std::size_t& used, std::size_t capacity, std::size_t bytes, const char* what) {
        const std::size_t at = used;
        if (at + bytes > capacity) {
            throw Error(ErrorCode::internal, std::string("the ") + what + " staging memory is too small");
        }
        used = (at + bytes + 15) / 16 * 16;
        return at;
    }

    unsigned char* up_ = nullptr;
    unsigned char* down_ = nullptr;
    std::size_t up_capacity_ = 0;
    std::size_t down_capacity_ = 0;
    std::size_t up_used_ = 0;
    std::size_t down_used_ = 0;
    std::vector<Download> downloads_;
};

}  // namespace pyrseg::gpu
