#pragma once
// Single-producer/single-consumer ring of fixed power-of-two capacity, the only
// kind of queue between marionette's threads. Acquire/release atomics only; the
// two indices live on separate cache lines, and each side caches the other's
// index so the common case touches one shared line per operation. Never blocks,
// never allocates after construction.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace marionette {

inline constexpr std::size_t kCacheLine = 64;

template <typename T, std::size_t Capacity>
class SpscRing {
    static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "capacity must be a power of two");
    static_assert(std::is_trivially_copyable_v<T>, "ring items are copied as plain data");

public:
    static constexpr std::size_t capacity() { return Capacity; }

    // Producer side. False when full (the caller decides what that means).
    bool try_push(const T& item) {
        const std::uint64_t head = head_.load(std::memory_order_relaxed);
        if (head - producer_cached_tail_ >= Capacity) {
            producer_cached_tail_ = tail_.load(std::memory_order_acquire);
            if (head - producer_cached_tail_ >= Capacity) return false;
        }
        slots_[head & (Capacity - 1)] = item;
        head_.store(head + 1, std::memory_order_release);
        return true;
    }

    // Consumer side. False when empty.
    bool try_pop(T& out) {
        const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
        if (tail == consumer_cached_head_) {
            consumer_cached_head_ = head_.load(std::memory_order_acquire);
            if (tail == consumer_cached_head_) return false;
        }
        out = slots_[tail & (Capacity - 1)];
        tail_.store(tail + 1, std::memory_order_release);
        return true;
    }

    // Consumer side: the oldest item without removing it.
    const T* peek() {
        const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
        if (tail == consumer_cached_head_) {
            consumer_cached_head_ = head_.load(std::memory_order_acquire);
            if (tail == consumer_cached_head_) return nullptr;
        }
        return &slots_[tail & (Capacity - 1)];
    }

    // Either side; exact only when the other side is idle.
    std::size_t size_approx() const {
        return static_cast<std::size_t>(head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire));
    }

private:
    // 64-bit indices never wrap in practice (2^64 items), so full/empty need no spare slot.
    alignas(kCacheLine) std::atomic<std::uint64_t> head_{0};
    std::uint64_t producer_cached_tail_ = 0;
    alignas(kCacheLine) std::atomic<std::uint64_t> tail_{0};
    std::uint64_t consumer_cached_head_ = 0;
    alignas(kCacheLine) std::array<T, Capacity> slots_{};
};

}  // namespace marionette
