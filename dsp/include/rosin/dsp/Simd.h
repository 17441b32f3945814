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

/// Four neighbouring values from any address (built lane by lane: delay lines are written one
/// sample at a time, and a lane-wise build makes no alignment or aliasing assumption).
template <typename T>
inline Pack4<T> load4(const T* p) noexcept
{
    return Pack4<T>{p[0], p[1], p[2], p[3]};
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
