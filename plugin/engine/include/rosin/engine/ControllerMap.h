// MIDI-learn table: which controller drives which parameter, over what range. Written by the
// audio thread (a learn completes when the armed controller moves) and by the message thread
// (state restore, mapping presets); every field is a single-word atomic, so neither side waits.
#pragma once
#include <array>
#include <atomic>
#include <vector>

#include "rosin/engine/Presets.h"

namespace rosin::engine {

class ControllerMap {
public:
    static constexpr int numControllers = 120; // 120-127 are channel-mode messages

    ControllerMap() { clear(); }

    void clear() noexcept
    {
        for (auto& s : slots_) {
            s.param.store(-1, std::memory_order_relaxed);
            s.min.store(0.0f, std::memory_order_relaxed);
            s.max.store(1.0f, std::memory_order_relaxed);
            s.invert.store(false, std::memory_order_relaxed);
        }
        learnParam_.store(-1, std::memory_order_release);
    }

    /// Assign a controller; param -1 clears it. min/max in the parameter's own units.
    void set(int cc, int param, float min, float max, bool invert) noexcept
    {
        if (cc < 0 || cc >= numControllers) return;
        Slot& s = slots_[static_cast<std::size_t>(cc)];
        s.min.store(min, std::memory_order_relaxed);
        s.max.store(max, std::memory_order_relaxed);
        s.invert.store(invert, std::memory_order_relaxed);
        s.param.store(param, std::memory_order_release);
    }

    MappingEntry get(int cc) const noexcept
    {
        if (cc < 0 || cc >= numControllers) return {};
        const Slot& s = slots_[static_cast<std::size_t>(cc)];
        MappingEntry e;
        e.cc = cc;
        e.param = s.param.load(std::memory_order_acquire);
        e.min = s.min.load(std::memory_order_relaxed);
        e.max = s.max.load(std::memory_order_relaxed);
        e.invert = s.invert.load(std::memory_order_relaxed);
        return e;
    }

    /// [any thread] The next controller that moves is assigned to `param` over its full range.
    void armLearn(int param) noexcept { learnParam_.store(param, std::memory_order_release); }
    int learning() const noexcept { return learnParam_.load(std::memory_order_acquire); }

    /// [audio thread] Called for every controller; completes a pending learn. Returns true
    /// when it did (the controller's value then applies to the new target at once).
    bool offerForLearn(int cc, float fullMin, float fullMax) noexcept
    {
        int armed = learnParam_.load(std::memory_order_acquire);
        if (armed < 0 || cc < 0 || cc >= numControllers) return false;
        if (!learnParam_.compare_exchange_strong(armed, -1, std::memory_order_acq_rel)) return false;
        // One controller drives one parameter: a controller already mapped elsewhere moves.
        set(cc, armed, fullMin, fullMax, false);
        return true;
    }

    std::vector<MappingEntry> entries() const
    {
        std::vector<MappingEntry> out;
        for (int cc = 0; cc < numControllers; ++cc)
            if (const MappingEntry e = get(cc); e.param >= 0) out.push_back(e);
        return out;
    }

    void assign(const std::vector<MappingEntry>& list) noexcept
    {
        for (int cc = 0; cc < numControllers; ++cc) set(cc, -1, 0.0f, 1.0f, false);
        for (const auto& e : list) set(e.cc, e.param, e.min, e.max, e.invert);
    }

private:
    struct Slot {
        std::atomic<int> param{-1};
        std::atomic<float> min{0.0f}, max{1.0f};
        std::atomic<bool> invert{false};
    };
    std::array<Slot, numControllers> slots_;
    std::atomic<int> learnParam_{-1};
};

} // namespace rosin::engine
