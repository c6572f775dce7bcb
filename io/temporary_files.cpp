#include "temporary_files.hpp"

#include <unistd.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstring>

namespace pyrseg::io::detail {
namespace {

// A slot's state: free, being filled or emptied (its path not to be read), or holding a registered path.
enum : int { kFree = 0, kBusy = 1, kRegistered = 2 };
constexpr int kSlots = 64;
constexpr std::size_t kMaxPath = 4096;

struct Slot {
    std::atomic<int> state{kFree};
    std::array<char, kMaxPath> path{};
};
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler reads the slots' states");

std::array<Slot, kSlots>& slots() {
    static std::array<Slot, kSlots> table;
    return table;
}

void on_termination_signal(int signal_number) {
    remove_registered_temporaries();
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
}

}  // namespace

RegisteredTemporary::RegisteredTemporary(const std::filesystem::path& path) noexcept {
    const std::string& text = path.native();
    if (text.size() >= kMaxPath) return;
    for (int i = 0; i < kSlots; ++i) {
        Slot& s = slots()[std::size_t(i)];
        int expected = kFree;
        if (!s.state.compare_exchange_strong(expected, kBusy, std::memory_order_acquire)) continue;
        std::memcpy(s.path.data(), text.c_str(), text.size() + 1);
        s.state.store(kRegistered, std::memory_order_release);
        slot_ = i;
        return;
    }
}

RegisteredTemporary::~RegisteredTemporary() {
    if (slot_ >= 0) slots()[std::size_t(slot_)].state.store(kFree, std::memory_order_release);
}

RegisteredTemporary::RegisteredTemporary(RegisteredTemporary&& other) noexcept : slot_(other.slot_) {
    other.slot_ = -1;
}

RegisteredTemporary& RegisteredTemporary::operator=(RegisteredTemporary&& other) noexcept {
    if (this != &other) {
        if (slot_ >= 0) slots()[std::size_t(slot_)].state.store(kFree, std::memory_order_release);
        slot_ = other.slot_;
        other.slot_ = -1;
    }
    return *this;
}

void remove_registered_temporaries() noexcept {
    for (Slot& s : slots()) {
        if (s.state.load(std::memory_order_acquire) == kRegistered) ::unlink(s.path.data());
    }
}

void remove_temporaries_on_termination_signals() {
    (void)slots();  // made before any handler can run: a function-local static is not for a signal handler to make
    struct sigaction action {};
    action.sa_handler = on_termination_signal;
    sigemptyset(&action.sa_mask);
    for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
        // One ignored from the start stays ignored (nohup's SIGHUP, a background job's SIGINT).
        struct sigaction before {};
        if (sigaction(signal_number, nullptr, &before) == 0 && before.sa_handler == SIG_IGN) continue;
        sigaction(signal_number, &action, nullptr);
    }
}

}  // namespace pyrseg::io::detail
