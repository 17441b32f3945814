// What the editor's live views need from the audio thread: one frame per sample of the voice
// being watched, through a single-producer single-consumer ring. The audio thread writes whole
// chunks and never waits; when the reader falls behind (or no editor is open) frames are dropped.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rosin::engine {

struct ViewFrame {
    float bridgeForce = 0;  ///< N, the string's force on the bridge (before the body)
    float velocity = 0;     ///< string velocity at the bow (m/s)
    float bowSpeed = 0;     ///< signed bow speed (m/s)
    float friction = 0;     ///< friction force on the string (N)
    float force = 0;        ///< bow force (N)
    float temperature = 0;  ///< contact temperature rise above ambient (K)
    float beta = 0;         ///< bow position (fraction of the vibrating length)
    float frequency = 0;    ///< the note's stopped-string fundamental (Hz)
    std::uint8_t stick = 1;
    std::uint8_t string = 0;    ///< which string of the instrument (0 = lowest)
    std::uint8_t noteStart = 0; ///< 1 on the first frame of a new note
    std::uint8_t bowed = 1;     ///< 0 while a finger or stick excites the string (pizzicato, col legno)
};

class ViewRing {
public:
    /// [setup] capacity is rounded up to a power of two; the only allocation.
    explicit ViewRing(std::size_t capacity = 1u << 15)
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
    std::size_t write(const ViewFrame* frames, std::size_t n) noexcept
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
    std::size_t read(ViewFrame* out, std::size_t max) noexcept
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
    std::vector<ViewFrame> frames_;
    std::size_t mask_ = 0;
    std::atomic<bool> listening_{false};
    std::atomic<std::size_t> dropped_{0};
    alignas(64) std::atomic<std::size_t> head_{0};
    alignas(64) std::atomic<std::size_t> tail_{0};
};

} // namespace rosin::engine
