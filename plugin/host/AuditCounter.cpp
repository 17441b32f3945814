// Counts heap traffic, locks, condition variables and blocking calls on the thread that is inside
// an audited scope. The definitions interpose the C library's (the executable exports them with
// -rdynamic, so the dlopen'ed plugin binds to them too) and forward to the real entry points.
#include <dlfcn.h>
#include <poll.h>
#include <pthread.h>
#include <semaphore.h>
#include <sys/select.h>
#include <time.h>
#include <unistd.h>

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
using rosin::host::audit::Tally;
thread_local int pluginDepth = 0; // inside Rosin's processBlock (reported by the plugin)
thread_local int callDepth = 0;   // inside the host's call into the plugin
Tally inPlugin, inCall;
bool scopeSeen = false;

template <std::uint64_t Tally::*Field>
inline void count()
{
    if (pluginDepth > 0) ++(inPlugin.*Field);
    if (callDepth > 0) ++(inCall.*Field);
}

/// The next definition of a C function (glibc's), looked up once.
template <typename Fn>
Fn real(const char* name)
{
    return reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name));
}
} // namespace

#define ROSIN_FORWARD(ret, name, field, params, args)                                  \
    __attribute__((visibility("default"))) ret name params                             \
    {                                                                                   \
        count<&Tally::field>();                                                         \
        static auto fn = real<ret(*) params>(#name);                                    \
        return fn args;                                                                 \
    }

extern "C" {
__attribute__((visibility("default"))) void* malloc(std::size_t n)
{
    count<&Tally::allocations>();
    return __libc_malloc(n);
}
__attribute__((visibility("default"))) void* calloc(std::size_t a, std::size_t b)
{
    count<&Tally::allocations>();
    return __libc_calloc(a, b);
}
__attribute__((visibility("default"))) void* realloc(void* p, std::size_t n)
{
    count<&Tally::allocations>();
    return __libc_realloc(p, n);
}
__attribute__((visibility("default"))) void free(void* p)
{
    if (p) count<&Tally::frees>();
    __libc_free(p);
}
__attribute__((visibility("default"))) int posix_memalign(void** out, std::size_t align, std::size_t n)
{
    count<&Tally::allocations>();
    void* p = __libc_memalign(align, n);
    if (!p) return 12; // ENOMEM
    *out = p;
    return 0;
}
__attribute__((visibility("default"))) void* aligned_alloc(std::size_t align, std::size_t n)
{
    count<&Tally::allocations>();
    return __libc_memalign(align, n);
}
__attribute__((visibility("default"))) void* memalign(std::size_t align, std::size_t n)
{
    count<&Tally::allocations>();
    return __libc_memalign(align, n);
}
ROSIN_FORWARD(int, pthread_mutex_lock, locks, (pthread_mutex_t * m), (m))
ROSIN_FORWARD(int, pthread_mutex_trylock, locks, (pthread_mutex_t * m), (m))
ROSIN_FORWARD(int, pthread_rwlock_rdlock, locks, (pthread_rwlock_t * l), (l))
ROSIN_FORWARD(int, pthread_rwlock_wrlock, locks, (pthread_rwlock_t * l), (l))
ROSIN_FORWARD(int, pthread_cond_wait, waits, (pthread_cond_t * c, pthread_mutex_t* m), (c, m))
ROSIN_FORWARD(int, pthread_cond_timedwait, waits, (pthread_cond_t * c, pthread_mutex_t* m, const struct timespec* t), (c, m, t))
ROSIN_FORWARD(int, pthread_cond_signal, waits, (pthread_cond_t * c), (c))
ROSIN_FORWARD(int, pthread_cond_broadcast, waits, (pthread_cond_t * c), (c))
ROSIN_FORWARD(int, sem_wait, waits, (sem_t * s), (s))
ROSIN_FORWARD(int, sem_timedwait, waits, (sem_t * s, const struct timespec* t), (s, t))
ROSIN_FORWARD(int, sem_post, waits, (sem_t * s), (s))
ROSIN_FORWARD(int, nanosleep, blocking, (const struct timespec* a, struct timespec* b), (a, b))
ROSIN_FORWARD(int, clock_nanosleep, blocking, (clockid_t c, int f, const struct timespec* a, struct timespec* b), (c, f, a, b))
ROSIN_FORWARD(int, usleep, blocking, (useconds_t u), (u))
ROSIN_FORWARD(unsigned int, sleep, blocking, (unsigned int s), (s))
ROSIN_FORWARD(int, pthread_join, blocking, (pthread_t t, void** r), (t, r))
ROSIN_FORWARD(int, poll, blocking, (struct pollfd * f, nfds_t n, int t), (f, n, t))
ROSIN_FORWARD(int, select, blocking, (int n, fd_set* r, fd_set* w, fd_set* e, struct timeval* t), (n, r, w, e, t))
ROSIN_FORWARD(ssize_t, read, blocking, (int fd, void* b, size_t n), (fd, b, n))
ROSIN_FORWARD(ssize_t, write, blocking, (int fd, const void* b, size_t n), (fd, b, n))

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
void reset() noexcept
{
    inPlugin = {};
    inCall = {};
    scopeSeen = false;
}
Counts read() noexcept { return {inPlugin, inCall, scopeSeen}; }

bool selfTest() noexcept
{
    const Counts before = read();
    rosin_audit_scope(1);
    void* volatile p = std::malloc(64);
    std::free(p);
    // Set up before the counted calls (glibc's PTHREAD_MUTEX_INITIALIZER spells a null as 0).
    pthread_mutex_t m;
    pthread_mutex_init(&m, nullptr);
    pthread_mutex_lock(&m);
    pthread_mutex_unlock(&m);
    pthread_mutex_destroy(&m);
    pthread_cond_t c = PTHREAD_COND_INITIALIZER;
    pthread_cond_signal(&c);
    const struct timespec zero{0, 0};
    nanosleep(&zero, nullptr);
    rosin_audit_scope(0);
    const Counts after = read();
    inPlugin = before.plugin;
    scopeSeen = before.scopeSeen;
    return after.plugin.allocations == before.plugin.allocations + 1 && after.plugin.frees == before.plugin.frees + 1 &&
           after.plugin.locks == before.plugin.locks + 1 && after.plugin.waits == before.plugin.waits + 1 &&
           after.plugin.blocking == before.plugin.blocking + 1;
}
} // namespace rosin::host::audit
