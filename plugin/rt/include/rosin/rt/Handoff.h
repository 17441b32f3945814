// The pointer hand-off: the second of the two cross-thread channels the project allows. A setup
// thread builds an object and publishes it; the audio thread takes it at a block boundary and,
// when it is done with the object it replaced, retires that one into a queue that a
// housekeeping thread empties. Nothing is freed on the audio thread and nothing waits.
//
// Rules: publish() from any non-audio thread (a pointer is owned by exactly one side at any
// time: exchange hands it over); takePending() and retire() from the audio thread only;
// collect() from one housekeeping thread only (the retire queue has a single consumer).
#pragma once
#include <atomic>
#include <memory>

#include "rosin/rt/SpscQueue.h"

namespace rosin::rt {

template <typename T, std::size_t RetireCapacity = 16>
class Handoff {
public:
    Handoff() = default;
    Handoff(const Handoff&) = delete;
    Handoff& operator=(const Handoff&) = delete;
    ~Handoff()
    {
        delete pending_.exchange(nullptr);
        collect();
    }

    /// [setup thread] Offers `next`; one offered earlier and not yet taken never played and is
    /// freed here. `tag` travels with it (readable without touching the object).
    void publish(std::unique_ptr<T> next, int tag = 0)
    {
        pendingTag_.store(tag, std::memory_order_relaxed);
        delete pending_.exchange(next.release(), std::memory_order_acq_rel);
    }

    /// [audio thread] The newest published object, now owned by the caller, or nullptr.
    T* takePending() noexcept { return pending_.exchange(nullptr, std::memory_order_acq_rel); }
    bool hasPending() const noexcept { return pending_.load(std::memory_order_acquire) != nullptr; }
    /// The tag of the last publish (the audio thread may wait for a tag offline).
    int pendingTag() const noexcept { return pendingTag_.load(std::memory_order_relaxed); }

    /// [audio thread] Hands an object back to be freed elsewhere. False when the queue is full
    /// (the housekeeping thread has fallen behind): keep it and try again next block.
    bool retire(T* old) noexcept { return old == nullptr || retired_.push(old); }

    /// [housekeeping thread] Frees what the audio thread retired.
    void collect()
    {
        T* old = nullptr;
        while (retired_.pop(old)) delete old;
    }

private:
    std::atomic<T*> pending_{nullptr};
    std::atomic<int> pendingTag_{0};
    SpscQueue<T*, RetireCapacity> retired_;
};

} // namespace rosin::rt
