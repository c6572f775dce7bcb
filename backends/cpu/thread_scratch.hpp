#pragma once
// Scratch for the chunks of a parallel loop (ThreadPool::parallel_for) that carry rows from chunk to chunk: one per
// thread that can run at once, made on the first frame (or when a caller's arena has more threads than before). A
// chunk takes the scratch its thread had last when it is free, so that a thread that runs the chunks of a band in
// order (oneTBB's do, unless another thread steals some) finds the rows its last chunk left.
#include <cstddef>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace pyrseg::cpu {

template <class T>
class ThreadScratch {
public:
    // At least `count` of them, each made by make(T&). Made whole before they are kept: an allocation failing half-way
    // (out_of_memory) must not leave a scratch half made for the next frame to use.
    template <class Make>
    void reserve(std::size_t count, const Make& make) {
        if (items_.size() >= count) return;
        std::vector<Item> items(count);
        for (Item& item : items) make(item.value);
        items_ = std::move(items);
    }

    template <class Fn>
    void for_each(const Fn& fn) {
        for (Item& item : items_) fn(item.value);
    }

    // A scratch for the chunk that runs fn(T&): the one this thread took last when it is free, else the first free
    // one (one is: no more chunks run at once than reserve made scratches).
    template <class Fn>
    void with(const Fn& fn) {
        const std::size_t slot = acquire();
        fn(items_[slot].value);
        const std::lock_guard<std::mutex> lock(mutex_);
        items_[slot].busy = false;
    }

private:
    struct Item {
        T value{};
        std::thread::id owner;
        bool busy = false;
    };

    std::size_t acquire() {
        const std::lock_guard<std::mutex> lock(mutex_);
        const std::thread::id self = std::this_thread::get_id();
        std::size_t slot = items_.size();
        for (std::size_t i = 0; i < items_.size(); ++i) {
            if (items_[i].busy) continue;
            if (slot == items_.size()) slot = i;
            if (items_[i].owner == self) {
                slot = i;
                break;
            }
        }
        items_[slot].busy = true;
        items_[slot].owner = self;
        return slot;
    }

    std::vector<Item> items_;
    std::mutex mutex_;
};

}  // namespace pyrseg::cpu
