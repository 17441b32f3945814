// Circular delay line with an interpolated read. Memory is reserved in prepare() only.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "Config.h"

namespace rosin::dsp {

template <typename T>
class DelayLine {
public:
    /// [setup thread] Reserve room for delays up to maxDelaySamples.
    void prepare(double maxDelaySamples)
    {
        std::size_t size = 8;
        while (static_cast<double>(size) < maxDelaySamples + 8.0) size <<= 1;
        buffer_.assign(size, T(0));
        mask_ = size - 1;
        writeIndex_ = 0;
    }

    void reset() noexcept { std::fill(buffer_.begin(), buffer_.end(), T(0)); writeIndex_ = 0; }

    /// Largest delay (samples) that read() accepts.
    double capacity() const noexcept { return static_cast<double>(buffer_.size()) - 5.0; }

    /// Value written `delay` samples ago, where delay = 1 is the most recent write.
    /// Read before this sample's write. Third-order Lagrange interpolation (exact at
    /// integer delays, FIR so it stays smooth when the delay moves every sample);
    /// linear between 1 and 2 samples where the Lagrange stencil would need the future.
    T read(double delay) const noexcept
    {
        delay = std::clamp(delay, config::minSegmentDelay, capacity());
        double whole = std::floor(delay);
        double fraction = delay - whole;
        // A fraction of a nanosample is rounding in the caller's delay arithmetic, not intent:
        // snap it so integer delays stay exact.
        if (fraction > 1.0 - 1e-9) { whole += 1.0; fraction = 0.0; }
        if (fraction < 1e-9) fraction = 0.0;
        const auto n = static_cast<std::size_t>(whole);
        const T frac = static_cast<T>(fraction);
        if (n < 2) {
            const T a = at(1), b = at(2);
            return a + frac * (b - a);
        }
        // Stencil at delays n-1, n, n+1, n+2, evaluated at x = 1 + frac.
        const T x = T(1) + frac;
        const T x0 = x, x1 = x - T(1), x2 = x - T(2), x3 = x - T(3);
        const T h0 = -x1 * x2 * x3 / T(6);
        const T h1 = x0 * x2 * x3 / T(2);
        const T h2 = -x0 * x1 * x3 / T(2);
        const T h3 = x0 * x1 * x2 / T(6);
        return h0 * at(n - 1) + h1 * at(n) + h2 * at(n + 1) + h3 * at(n + 2);
    }

    void write(T value) noexcept
    {
        buffer_[writeIndex_] = value;
        writeIndex_ = (writeIndex_ + 1) & mask_;
    }

    /// Sum of squares of the most recent `count` samples (energy bookkeeping in tests).
    double sumOfSquares(std::size_t count) const noexcept
    {
        double s = 0.0;
        for (std::size_t k = 1; k <= count; ++k) s += static_cast<double>(at(k)) * static_cast<double>(at(k));
        return s;
    }

private:
    T at(std::size_t delay) const noexcept { return buffer_[(writeIndex_ - delay) & mask_]; }

    std::vector<T> buffer_;
    std::size_t mask_ = 0;
    std::size_t writeIndex_ = 0;
};

} // namespace rosin::dsp
