#pragma once
// Triple buffer: one writer publishes whole values, one reader takes the newest.
// Neither ever waits for the other and the reader never sees a half-written
// value. Used for simulation → render (the two latest states) and for handing
// a new configuration to the simulation.
#include <array>
#include <atomic>
#include <cstdint>

namespace marionette {

template <typename T>
class LatestValue {
public:
    // Writer: fill the back buffer in place, then publish() it.
    T& back() { return slots_[back_]; }
    void publish() {
        // Swap our back slot into the middle, marking it fresh; take the old middle.
        const std::uint8_t old = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
        back_ = static_cast<std::uint8_t>(old & kIndexMask);
        ++published_;
    }

    // Reader: true when a value newer than the last one read was taken; front()
    // then holds it. front() stays valid (and unchanged) until the next take().
    bool take() {
        if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
        const std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
        front_ = static_cast<std::uint8_t>(old & kIndexMask);
        return true;
    }
    const T& front() const { return slots_[front_]; }

    std::uint64_t published_count() const { return published_; }  // writer side only

private:
    static constexpr std::uint8_t kFresh = 0x4;
    static constexpr std::uint8_t kIndexMask = 0x3;
    std::array<T, 3> slots_{};
    std::uint8_t back_ = 0;   // writer's
    std::uint8_t front_ = 1;  // reader's
    alignas(64) std::atomic<std::uint8_t> middle_{2};
    std::uint64_t published_ = 0;
};

}  // namespace marionette
