// Single-producer single-consumer ring of trivially copyable items: wait-free on both ends,
// no allocation after construction. One of the two cross-thread channels the project allows
// (the other is a pointer hand-off): events, finished objects and requests travel through it.
#pragma once
#include <array>
#include <atomic>
#include <cstddef>

namespace rosin::rt {

template <typename T, std::size_t Capacity>
class SpscQueue {
    static_assert((Capacity & (Capacity - 1)) == 0, "capacity must be a power of two");

public:
    /// [producer] False when full (the item stays with the caller).
    bool push(const T& item) noexcept
    {
        const std::size_t head = head_.load(std::memory_order_relaxed);
        if (head - tail_.load(std::memory_order_acquire) == Capacity) return false;
        items_[head & (Capacity - 1)] = item;
        head_.store(head + 1, std::memory_order_release);
        return true;
    }

    /// [consumer] False when empty.
    bool pop(T& item) noexcept
    {
        const std::size_t tail = tail_.load(std::memory_order_relaxed);
        if (tail == head_.load(std::memory_order_acquire)) return false;
        item = items_[tail & (Capacity - 1)];
        tail_.store(tail + 1, std::memory_order_release);
        return true;
    }

private:
    std::array<T, Capacity> items_{};
    alignas(64) std::atomic<std::size_t> head_{0};
    alignas(64) std::atomic<std::size_t> tail_{0};
};

} // namespace rosin::rt
