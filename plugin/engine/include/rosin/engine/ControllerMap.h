// MIDI-learn: which controller drives which parameter, over what range. The table is a value:
// the message side (the editor, a mapping preset, a restored session, a learn that the audio
// thread reported) builds a new one and hands it over whole; the audio thread reads the table it
// took at the top of its block and never sees a half-written one. Old tables are freed by the
// housekeeping thread (rt::Handoff).
#pragma once
#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "rosin/engine/Presets.h"
#include "rosin/rt/Handoff.h"

namespace rosin::engine {

struct ControllerTable {
    static constexpr int numControllers = 120; // 120-127 are channel-mode messages
    std::array<MappingEntry, numControllers> slots{};

    ControllerTable()
    {
        for (int cc = 0; cc < numControllers; ++cc) slots[static_cast<std::size_t>(cc)].cc = cc;
    }
    const MappingEntry& get(int cc) const noexcept
    {
        static const MappingEntry none{};
        return cc >= 0 && cc < numControllers ? slots[static_cast<std::size_t>(cc)] : none;
    }
};

class ControllerMap {
public:
    static constexpr int numControllers = ControllerTable::numControllers;

    ControllerMap();
    ~ControllerMap() { delete retiring_; }
    ControllerMap(const ControllerMap&) = delete;
    ControllerMap& operator=(const ControllerMap&) = delete;

    // [message side: any thread but audio; serialised inside]
    /// Assign a controller; param -1 clears it. min/max in the parameter's own units. One
    /// controller drives one parameter.
    void set(int cc, int param, float min, float max, bool invert);
    /// Replace the whole table.
    void assign(const std::vector<MappingEntry>& list);
    void clear() { assign({}); }
    MappingEntry get(int cc) const;
    std::vector<MappingEntry> entries() const;

    /// [any thread] The next controller that moves is assigned to `param` over its full range.
    void armLearn(int param) noexcept { learnParam_.store(param, std::memory_order_release); }
    int learning() const noexcept { return learnParam_.load(std::memory_order_acquire); }
    /// [audio thread] Claims the armed learn (once): the parameter, or -1.
    int claimLearn() noexcept { return learnParam_.exchange(-1, std::memory_order_acq_rel); }

    /// [audio thread] The newest table, taken at the top of a block (the one it replaces is
    /// retired). Never null.
    const ControllerTable& acquire() noexcept;
    /// [housekeeping thread] Frees retired tables.
    void collect() { handoff_.collect(); }

private:
    void publishLocked();

    mutable std::mutex mutex_; ///< message-side writers only; never taken on the audio thread
    ControllerTable edited_;   ///< the message side's copy
    rt::Handoff<ControllerTable, 64> handoff_;
    std::unique_ptr<ControllerTable> active_; ///< [audio thread] the table in use
    ControllerTable* retiring_ = nullptr;     ///< [audio thread] replaced, waiting for room in the retire queue
    std::atomic<int> learnParam_{-1};
};

} // namespace rosin::engine
