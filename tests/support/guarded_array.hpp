#pragma once
// Values at the very end of a readable and writable mapping whose next page is not accessible: a kernel that reads
// or writes one element past the last (a whole-vector load or store at a row's end) faults instead of passing by.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace pyrseg::test {

template <class T>
class GuardedArray {
    static_assert(std::is_trivially_copyable_v<T>);

public:
    explicit GuardedArray(const std::vector<T>& values) : count_(values.size()) {
        const auto page = std::size_t(sysconf(_SC_PAGESIZE));
        const std::size_t bytes = values.size() * sizeof(T);
        size_ = (bytes + page - 1) / page * page + page;
        void* map = mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (map == MAP_FAILED) throw std::runtime_error("mmap failed");
        base_ = static_cast<unsigned char*>(map);
        unsigned char* guard = base_ + size_ - page;
        if (mprotect(guard, page, PROT_NONE) != 0) throw std::runtime_error("mprotect failed");
        data_ = reinterpret_cast<T*>(guard - bytes);
        std::memcpy(data_, values.data(), bytes);
    }
    ~GuardedArray() { munmap(base_, size_); }
    GuardedArray(const GuardedArray&) = delete;
    GuardedArray& operator=(const GuardedArray&) = delete;
    GuardedArray(GuardedArray&&) = delete;
    GuardedArray& operator=(GuardedArray&&) = delete;

    [[nodiscard]] T* data() { return data_; }
    [[nodiscard]] const T* data() const { return data_; }
    [[nodiscard]] std::vector<T> values() const { return {data_, data_ + count_}; }

private:
    unsigned char* base_ = nullptr;
    std::size_t size_ = 0;
    T* data_ = nullptr;
    std::size_t count_ = 0;
};

}  // namespace pyrseg::test
