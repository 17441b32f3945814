// Real-time audit for the headless host (see AuditCounter.cpp): what happens on the thread that
// is inside the plugin's processBlock. An executable that links AuditCounter.cpp gets the
// counting; PluginHost calls enterCall/exitCall around its call, Rosin reports its own scope.
#pragma once
#include <cstdint>

namespace rosin::host::audit {

/// What was counted in one scope.
struct Tally {
    std::uint64_t allocations = 0; ///< malloc, calloc, realloc, memalign and friends (operator new too)
    std::uint64_t frees = 0;       ///< free (operator delete too)
    std::uint64_t locks = 0;       ///< pthread_mutex_lock / trylock, rwlocks
    std::uint64_t waits = 0;       ///< condition variables and semaphores: wait, signal, broadcast, post
    std::uint64_t blocking = 0;    ///< sleeps, joins, poll/select, read/write on file descriptors
    std::uint64_t total() const noexcept { return allocations + frees + locks + waits + blocking; }
};

struct Counts {
    Tally plugin; ///< inside Rosin's processBlock (the plugin reported its scope)
    Tally call;   ///< the whole host -> plugin call (the format wrapper too)
    bool scopeSeen = false;
};

void enterCall() noexcept;
void exitCall() noexcept;
void reset() noexcept;
Counts read() noexcept;
/// Proves every counter is live: each kind of call made inside a fake plugin scope must count.
bool selfTest() noexcept;

} // namespace rosin::host::audit
