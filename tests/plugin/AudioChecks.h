// Measurements on rendered audio shared by the engine and host tests.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace rosin::test {

/// Fundamental (Hz) of x[from, to) by the normalised autocorrelation: the first lag whose
/// correlation is within 10 % of the best in [fs/fMax, fs/fMin] (so a period, not a multiple),
/// refined by a parabola through its neighbours.
inline double pitchHz(const std::vector<float>& x, double fs, std::size_t from, std::size_t to, double fMin = 40.0,
                      double fMax = 2000.0)
{
    const int lo = static_cast<int>(fs / fMax), hi = static_cast<int>(fs / fMin);
    const std::size_t n = to - from - static_cast<std::size_t>(hi) - 2;
    auto corr = [&](int lag) {
        double r = 0.0, e0 = 0.0, e1 = 0.0;
        for (std::size_t i = from; i < from + n; ++i) {
            const double a = x[i], b = x[i + static_cast<std::size_t>(lag)];
            r += a * b;
            e0 += a * a;
            e1 += b * b;
        }
        return r / std::sqrt(e0 * e1 + 1e-30);
    };
    std::vector<double> c(static_cast<std::size_t>(hi + 2), 0.0);
    double best = -1.0;
    for (int lag = lo; lag <= hi + 1; ++lag) {
        c[static_cast<std::size_t>(lag)] = corr(lag);
        if (lag <= hi) best = std::max(best, c[static_cast<std::size_t>(lag)]);
    }
    int pick = lo;
    for (int lag = lo + 1; lag < hi; ++lag) {
        const double v = c[static_cast<std::size_t>(lag)];
        if (v >= 0.9 * best && v >= c[static_cast<std::size_t>(lag - 1)] && v >= c[static_cast<std::size_t>(lag + 1)]) {
            pick = lag;
            break;
        }
    }
    const double r0 = c[static_cast<std::size_t>(pick - 1)], r1 = c[static_cast<std::size_t>(pick)], r2 = c[static_cast<std::size_t>(pick + 1)];
    const double den = r0 - 2.0 * r1 + r2;
    const double period = pick + (den != 0.0 ? 0.5 * (r0 - r2) / den : 0.0);
    return fs / period;
}

inline double cents(double f, double reference) { return 1200.0 * std::log2(f / reference); }

inline double rms(const std::vector<float>& x, std::size_t from, std::size_t to)
{
    double s = 0.0;
    for (std::size_t i = from; i < to; ++i) s += static_cast<double>(x[i]) * x[i];
    return std::sqrt(s / static_cast<double>(std::max<std::size_t>(1, to - from)));
}

inline double peakAbs(const std::vector<float>& x, std::size_t from, std::size_t to)
{
    double p = 0.0;
    for (std::size_t i = from; i < to; ++i) p = std::max(p, std::abs(static_cast<double>(x[i])));
    return p;
}

/// Largest second difference |x[i+1] - 2x[i] + x[i-1]|: a click is a kink the signal's own
/// curvature does not explain.
inline double maxSecondDifference(const std::vector<float>& x, std::size_t from, std::size_t to)
{
    double m = 0.0;
    for (std::size_t i = std::max<std::size_t>(from, 1); i + 1 < to; ++i)
        m = std::max(m, std::abs(static_cast<double>(x[i + 1]) - 2.0 * x[i] + x[i - 1]));
    return m;
}

inline double midiToHz(double note, double a4 = 440.0) { return a4 * std::exp2((note - 69.0) / 12.0); }

} // namespace rosin::test
