// Allocation and lock counting for real-time audits (see AuditCounter.cpp). An executable
// that links AuditCounter.cpp gets the counting; PluginHost calls these around processBlock.
#pragma once
#include <cstdint>

namespace rosin::host::audit {
struct Counts {
    std::uint64_t allocationsInPlugin, locksInPlugin, allocationsInCall, locksInCall;
    bool scopeSeen;
};
void enterCall() noexcept;
void exitCall() noexcept;
void reset() noexcept;
Counts read() noexcept;
bool selfTest() noexcept;
} // namespace rosin::host::audit
