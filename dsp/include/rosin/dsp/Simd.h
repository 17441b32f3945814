// Four lanes of T as one value (GCC/Clang vector extension): 16 bytes of floats or 32 bytes
// of doubles. The compiler maps them to what the target has (one SSE register for floats, a
// pair for doubles on baseline x86-64), so the code stays portable and plain.
#pragma once

namespace rosin::dsp::simd {

template <typename T>
struct PackOf4;
template <>
struct PackOf4<float> {
    typedef float type __attribute__((vector_size(16)));
};
template <>
struct PackOf4<double> {
    typedef double type __attribute__((vector_size(32)));
};
template <typename T>
using Pack4 = typename PackOf4<T>::type;

/// Four neighbouring values from any address, as one wide load where the compiler can.
template <typename T>
inline Pack4<T> load4(const T* p) noexcept
{
    return Pack4<T>{p[0], p[1], p[2], p[3]};
}

/// The same four values from four narrow loads. For samples written a moment ago: a wide load
/// over several recent one-sample stores cannot take its data from the store queue and waits
/// for them to reach the cache. On a string's shortest line (the torsional bridge side, a few
/// samples long) that wait made the whole voice ~15 % slower (measured, rosin bench).
template <typename T>
inline Pack4<T> load4Narrow(const T* p) noexcept
{
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    // Empty asm statements: the pointer is opaque to the compiler, so it cannot reuse a wide
    // load of the same address, and so are the loaded values, so it cannot merge the four
    // loads back into one.
    asm("" : "+r"(p));
    T a = p[0], b = p[1], c = p[2], d = p[3];
    asm("" : "+x"(a), "+x"(b), "+x"(c), "+x"(d));
    return Pack4<T>{a, b, c, d};
#else
    return load4(p); // elsewhere: the compiler's own choice
#endif
}

/// {sum(a), sum(b), sum(c), sum(d)}: four dot products finished at once (a 4x4 transpose
/// folded into the adds), instead of four separate lane-by-lane sums.
template <typename T>
inline Pack4<T> sumEach(Pack4<T> a, Pack4<T> b, Pack4<T> c, Pack4<T> d) noexcept
{
    const Pack4<T> ab = __builtin_shufflevector(a, b, 0, 4, 1, 5) + __builtin_shufflevector(a, b, 2, 6, 3, 7);
    const Pack4<T> cd = __builtin_shufflevector(c, d, 0, 4, 1, 5) + __builtin_shufflevector(c, d, 2, 6, 3, 7);
    return __builtin_shufflevector(ab, cd, 0, 1, 4, 5) + __builtin_shufflevector(ab, cd, 2, 3, 6, 7);
}

} // namespace rosin::dsp::simd
