// Circular delay lines with an interpolated read. Memory is reserved in prepare() only.
//
// Every sample is written twice, at i and at i + size, so any run of up to `size` recent
// samples sits contiguously in memory: a four-point read is one index computation and four
// neighbouring loads instead of four wrapped ones (reads are most of a voice's memory work).
//
// DelayLines holds several lines of one size that advance together: a string writes all of its
// lines once per sample, so one write index serves them all (one update per sample instead of
// one per line, and a read is the same single add for every line).
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "Config.h"

namespace rosin::dsp {

template <typename T>
class DelayLines {
public:
    /// [setup thread] `lines` lines, each with room for delays up to maxDelaySamples.
    void prepare(int lines, double maxDelaySamples)
    {
        std::size_t size = 8;
        while (static_cast<double>(size) < maxDelaySamples + 8.0) size <<= 1;
        lines_ = std::max(lines, 1);
        buffer_.assign(static_cast<std::size_t>(lines_) * 2 * size, T(0));
        size_ = size;
        mask_ = size - 1;
        writeIndex_ = 0;
    }

    void reset() noexcept { std::fill(buffer_.begin(), buffer_.end(), T(0)); writeIndex_ = 0; }

    /// [audio thread] Silence one line (one that was not written for a while holds stale waves).
    void clear(int line) noexcept
    {
        std::fill_n(buffer_.begin() + static_cast<std::ptrdiff_t>(start(line)), 2 * size_, T(0));
    }

    int lines() const noexcept { return lines_; }

    /// Largest delay (samples) that read() accepts.
    double capacity() const noexcept { return static_cast<double>(size_) - 5.0; }

    /// Read position and interpolation weights for one delay of one line. Computing them is the
    /// costly part of a fractional read, and delays change only when the bow moves, so callers
    /// keep a Tap and refresh it then.
    struct Tap {
        std::size_t base = 1; ///< delay of the first stencil point
        /// Where the stencil starts relative to the write index: the line's start plus its
        /// mirrored half (size - base - 3), so a read is one add, no wrap. Valid for the lines
        /// it was made for.
        std::size_t offset = 0;
        T h0 = T(1), h1 = T(0), h2 = T(0), h3 = T(0);
    };

    /// Tap for `delay` samples on `line`, where delay = 1 is the most recent write (read before
    /// this sample's writes). Third-order Lagrange (exact at integer delays, FIR so it stays
    /// smooth when the delay moves every sample); linear between 1 and 2 samples, where the
    /// Lagrange stencil would need the future.
    Tap tap(int line, double delay) const noexcept
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
        Tap t;
        if (n < 2) {
            t.base = 1; // linear between delays 1 and 2 (n == 1 here)
            t.offset = start(line) + size_ - 4;
            t.h0 = T(1) - frac;
            t.h1 = frac;
            t.h2 = t.h3 = T(0);
            return t;
        }
        // Stencil at delays n-1, n, n+1, n+2, evaluated at x = 1 + frac.
        const T x = T(1) + frac;
        const T x0 = x, x1 = x - T(1), x2 = x - T(2), x3 = x - T(3);
        t.base = n - 1;
        t.offset = start(line) + size_ - (t.base + 3);
        t.h0 = -x1 * x2 * x3 / T(6);
        t.h1 = x0 * x2 * x3 / T(2);
        t.h2 = -x0 * x1 * x3 / T(2);
        t.h3 = x0 * x1 * x2 / T(6);
        return t;
    }

    T read(const Tap& t) const noexcept
    {
        const T* p = stencil(t);
        return t.h0 * p[3] + t.h1 * p[2] + t.h2 * p[1] + t.h3 * p[0];
    }

    /// Weighted sum of samples at delays first, first + 1, ... of `line` (an FIR read of any kernel).
    T readKernel(int line, std::size_t first, const T* weights, int count) const noexcept
    {
        const T* p = run(line, first + static_cast<std::size_t>(count) - 1); // p[count - 1 - k] is delay first + k
        T acc = T(0);
        for (int k = 0; k < count; ++k) acc += weights[k] * p[count - 1 - k];
        return acc;
    }

    /// The four samples a tap weighs, oldest first: p[0] is delay base + 3, p[3] delay base.
    const T* stencil(const Tap& t) const noexcept { return origin() + t.offset; }
    /// Where this sample's taps count from: stencil(t) is origin() + t.offset for every line
    /// (a caller reading several taps in one sample can take it once).
    const T* origin() const noexcept { return buffer_.data() + writeIndex_; }

    /// This sample's value of `line`; advance() once all lines are written.
    void write(int line, T value) noexcept
    {
        T* p = buffer_.data() + start(line) + writeIndex_;
        p[0] = value;
        p[size_] = value;
    }

    /// Ends the sample: what was written becomes delay 1.
    void advance() noexcept { writeIndex_ = (writeIndex_ + 1) & mask_; }

    /// Sum of squares of the most recent `count` samples of `line` (energy bookkeeping in tests).
    double sumOfSquares(int line, std::size_t count) const noexcept
    {
        double s = 0.0;
        for (std::size_t k = 1; k <= count; ++k) {
            const double v = static_cast<double>(buffer_[start(line) + ((writeIndex_ - k) & mask_)]);
            s += v * v;
        }
        return s;
    }

private:
    std::size_t start(int line) const noexcept { return static_cast<std::size_t>(line) * 2 * size_; }
    /// Start of the contiguous run from delay `oldest` up to the newest samples (oldest <= size).
    const T* run(int line, std::size_t oldest) const noexcept
    {
        return buffer_.data() + start(line) + ((writeIndex_ - oldest) & mask_);
    }

    std::vector<T> buffer_; // per line 2 x size_: the second half mirrors the first
    int lines_ = 1;
    std::size_t size_ = 0;
    std::size_t mask_ = 0;
    std::size_t writeIndex_ = 0;
};

/// One line on its own (tests, and any unit with a single delay).
template <typename T>
class DelayLine {
public:
    using Tap = typename DelayLines<T>::Tap;

    /// [setup thread] Reserve room for delays up to maxDelaySamples.
    void prepare(double maxDelaySamples) { lines_.prepare(1, maxDelaySamples); }
    void reset() noexcept { lines_.reset(); }
    double capacity() const noexcept { return lines_.capacity(); }
    Tap tap(double delay) const noexcept { return lines_.tap(0, delay); }
    T read(const Tap& t) const noexcept { return lines_.read(t); }
    /// Convenience for tests and setup code: tap and read in one.
    T read(double delay) const noexcept { return read(tap(delay)); }
    T readKernel(std::size_t first, const T* weights, int count) const noexcept
    {
        return lines_.readKernel(0, first, weights, count);
    }
    const T* stencil(const Tap& t) const noexcept { return lines_.stencil(t); }
    void write(T value) noexcept
    {
        lines_.write(0, value);
        lines_.advance();
    }
    double sumOfSquares(std::size_t count) const noexcept { return lines_.sumOfSquares(0, count); }

private:
    DelayLines<T> lines_;
};

} // namespace rosin::dsp
