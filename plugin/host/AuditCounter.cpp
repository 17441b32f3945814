// Counts heap allocations and mutex locks on the thread that is inside an audited scope. The
// definitions interpose the C library's (the executable exports them with -rdynamic, so the
// dlopen'ed plugin binds to them too) and forward to glibc's own entry points.
#include <dlfcn.h>
#include <pthread.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "AuditCounter.h"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {
thread_local int pluginDepth = 0;  // inside Rosin's processBlock (reported by the plugin)
thread_local int callDepth = 0;    // inside the host's call into the plugin
std::uint64_t allocPlugin = 0, lockPlugin = 0, allocCall = 0, lockCall = 0;
bool scopeSeen = false;

inline void countAllocation()
{
    if (pluginDepth > 0) ++allocPlugin;
    if (callDepth > 0) ++allocCall;
}
inline void countLock()
{
    if (pluginDepth > 0) ++lockPlugin;
    if (callDepth > 0) ++lockCall;
}

using LockFn = int (*)(pthread_mutex_t*);
LockFn realLock()
{
    static LockFn fn = reinterpret_cast<LockFn>(dlsym(RTLD_NEXT, "pthread_mutex_lock"));
    return fn;
}
LockFn realTryLock()
{
    static LockFn fn = reinterpret_cast<LockFn>(dlsym(RTLD_NEXT, "pthread_mutex_trylock"));
    return fn;
}
} // namespace

extern "C" {
__attribute__((visibility("default"))) void* malloc(std::size_t n)
{
    countAllocation();
    return __libc_malloc(n);
}
__attribute__((visibility("default"))) void* calloc(std::size_t a, std::size_t b)
{
    countAllocation();
    return __libc_calloc(a, b);
}
__attribute__((visibility("default"))) void* realloc(void* p, std::size_t n)
{
    countAllocation();
    return __libc_realloc(p, n);
}
__attribute__((visibility("default"))) void free(void* p) { __libc_free(p); }
__attribute__((visibility("default"))) int posix_memalign(void** out, std::size_t align, std::size_t n)
{
    countAllocation();
    void* p = __libc_memalign(align, n);
    if (!p) return 12; // ENOMEM
    *out = p;
    return 0;
}
__attribute__((visibility("default"))) void* aligned_alloc(std::size_t align, std::size_t n)
{
    countAllocation();
    return __libc_memalign(align, n);
}
__attribute__((visibility("default"))) void* memalign(std::size_t align, std::size_t n)
{
    countAllocation();
    return __libc_memalign(align, n);
}
__attribute__((visibility("default"))) int pthread_mutex_lock(pthread_mutex_t* m)
{
    countLock();
    return realLock()(m);
}
__attribute__((visibility("default"))) int pthread_mutex_trylock(pthread_mutex_t* m)
{
    countLock();
    return realTryLock()(m);
}
/// The plugin calls this (weak reference) at the top and bottom of its processBlock.
__attribute__((visibility("default"))) void rosin_audit_scope(int entering)
{
    scopeSeen = true;
    pluginDepth += entering ? 1 : -1;
}
}

namespace rosin::host::audit {
void enterCall() noexcept { ++callDepth; }
void exitCall() noexcept { --callDepth; }
void reset() noexcept { allocPlugin = lockPlugin = allocCall = lockCall = 0; scopeSeen = false; }
Counts read() noexcept { return {allocPlugin, lockPlugin, allocCall, lockCall, scopeSeen}; }
bool linked() noexcept { return true; }
/// Proves the counter is live: an allocation and a lock inside a fake plugin scope must count.
bool selfTest() noexcept
{
    const Counts before = read();
    rosin_audit_scope(1);
    void* volatile p = std::malloc(64);
    std::free(p);
    pthread_mutex_t m = PTHREAD_MUTEX_INITIALIZER;
    pthread_mutex_lock(&m);
    pthread_mutex_unlock(&m);
    rosin_audit_scope(0);
    const Counts after = read();
    allocPlugin = before.allocationsInPlugin;
    lockPlugin = before.locksInPlugin;
    scopeSeen = before.scopeSeen;
    return after.allocationsInPlugin == before.allocationsInPlugin + 1 && after.locksInPlugin == before.locksInPlugin + 1;
}
} // namespace rosin::host::audit
