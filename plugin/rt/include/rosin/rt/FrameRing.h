// A single-producer single-consumer ring of frames sized at construction: the writer (the audio
// thread) copies whole chunks and never waits; when the reader falls behind, or nobody reads,
// frames are dropped and counted. Used for the editor's live views.
#pragma once
#include <atomic>
#include <cstddef>
#include <vector>

namespace rosin::rt {

template <typename Frame>
class FrameRing {
public:
    /// [setup] capacity is rounded up to a power of two; the only allocation.
    explicit FrameRing(std::size_t capacity = 1u << 15)
    {
        std::size_t c = 1;
        while (c < capacity) c <<= 1;
        frames_.resize(c);
        mask_ = c - 1;
    }

    /// [reader] Whether anyone is reading: the writer skips the work when not.
    void setListening(bool on) noexcept { listening_.store(on, std::memory_order_relaxed); }
    bool listening() const noexcept { return listening_.load(std::memory_order_relaxed); }

    /// [writer] Copies what fits; returns how many frames were taken.
    std::size_t write(const Frame* frames, std::size_t n) noexcept
    {
        const std::size_t head = head_.load(std::memory_order_relaxed);
        const std::size_t free = frames_.size() - (head - tail_.load(std::memory_order_acquire));
        const std::size_t take = n < free ? n : free;
        for (std::size_t i = 0; i < take; ++i) frames_[(head + i) & mask_] = frames[i];
        head_.store(head + take, std::memory_order_release);
        if (take < n) dropped_.fetch_add(n - take, std::memory_order_relaxed);
        return take;
    }

    /// [reader] Moves up to `max` frames out; returns how many.
    std::size_t read(Frame* out, std::size_t max) noexcept
    {
        const std::size_t tail = tail_.load(std::memory_order_relaxed);
        const std::size_t available = head_.load(std::memory_order_acquire) - tail;
        const std::size_t take = available < max ? available : max;
        for (std::size_t i = 0; i < take; ++i) out[i] = frames_[(tail + i) & mask_];
        tail_.store(tail + take, std::memory_order_release);
        return take;
    }

    std::size_t capacity() const noexcept { return frames_.size(); }
    std::size_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

private:
    std::vector<Frame> frames_;
    std::size_t mask_ = 0;
    std::atomic<bool> listening_{false};
    std::atomic<std::size_t> dropped_{0};
    alignas(64) std::atomic<std::size_t> head_{0};
    alignas(64) std::atomic<std::size_t> tail_{0};
};

} // namespace rosin::rt
