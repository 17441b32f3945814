// Reflection-function pieces for one waveguide segment (PHYSICS.md 1.2): a one-pole loss
// filter fitted to the target damping, and an optional chain of first-order allpasses for
// bending-stiffness dispersion. The sign inversion of a rigid end is applied by the caller.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace rosin::dsp {

/// Loss factor eta(f) = 1/Q(f): 1/qLow at and below f0, rising linearly to 1/qHigh at fHigh.
inline double lossFactor(double f, double f0, double qLow, double qHigh, double fHigh) noexcept
{
    const double eLow = 1.0 / qLow, eHigh = 1.0 / qHigh;
    if (fHigh <= f0) return eLow;
    const double s = std::clamp((f - f0) / (fHigh - f0), 0.0, 1.0);
    return eLow + (eHigh - eLow) * s;
}

/// |R(f)| a segment with round-trip time tau must have so that a mode at f decays at its Q.
inline double segmentMagnitude(double f, double tau, double eta) noexcept
{
    return std::exp(-0.5 * 2.0 * std::numbers::pi * f * eta * tau);
}

/// H(z) = g (1 + p) / (1 + p z^-1). DC gain g, low-pass for p < 0.
template <typename T>
struct OnePoleLoss {
    T b0 = T(1);   ///< g (1 + p)
    T a1 = T(0);   ///< p
    T state = T(0);

    /// Fit to magnitudes m1 at w1 and m2 at w2 (rad/sample), closed form. Falls back to a
    /// flat gain when the targets are (numerically) flat or a low-pass cannot reach them.
    void design(double m1, double w1, double m2, double w2) noexcept
    {
        const double rho = (m1 * m1) / (m2 * m2);
        const double c1 = std::cos(w1), c2 = std::cos(w2);
        double p = 0.0;
        if (std::abs(rho - 1.0) > 1e-12) {
            // rho (1 + 2p c1 + p^2) = 1 + 2p c2 + p^2
            const double A = rho - 1.0, B = 2.0 * (rho * c1 - c2), C = rho - 1.0;
            const double disc = B * B - 4.0 * A * C;
            if (disc >= 0.0) {
                const double r1 = (-B + std::sqrt(disc)) / (2.0 * A);
                const double r2 = (-B - std::sqrt(disc)) / (2.0 * A);
                p = (std::abs(r1) < 1.0) ? r1 : r2;
                if (!(std::abs(p) < 0.999)) p = 0.0;
            }
        }
        const double g = m1 * std::sqrt(1.0 + 2.0 * p * c1 + p * p) / (1.0 + p);
        b0 = static_cast<T>(g * (1.0 + p));
        a1 = static_cast<T>(p);
    }

    void setIdentity() noexcept { b0 = T(1); a1 = T(0); }

    /// Phase delay (samples) at w (rad/sample).
    double phaseDelay(double w) const noexcept
    {
        // arg H = -arg(1 + p e^{-iw}) = atan2(p sin w, 1 + p cos w)
        const double p = static_cast<double>(a1);
        return -std::atan2(p * std::sin(w), 1.0 + p * std::cos(w)) / w;
    }

    void reset() noexcept { state = T(0); }

    T process(T x) noexcept
    {
        const T y = b0 * x - a1 * state;
        state = y;
        return y;
    }
};

/// Chain of identical first-order allpasses A(z) = (a + z^-1) / (1 + a z^-1). With a in (-1, 0)
/// the phase delay falls with frequency, so upper partials come round sooner: a stiff string.
template <typename T, int MaxSections = 8>
struct DispersionChain {
    int sections = 0;
    T a = T(0);
    std::array<T, MaxSections> xPrev{}, yPrev{};

    static double sectionPhaseDelay(double a, double w) noexcept
    {
        // arg A = -w + arg(1 + a e^{iw}) - arg(1 + a e^{-iw}) ... written directly:
        const double num = std::atan2(-std::sin(w), a + std::cos(w));
        const double den = std::atan2(-a * std::sin(w), 1.0 + a * std::cos(w));
        double phase = num - den;
        if (phase > 0.0) phase -= 2.0 * std::numbers::pi;
        return -phase / w;
    }

    double phaseDelay(double w) const noexcept
    {
        return sections == 0 ? 0.0 : sections * sectionPhaseDelay(static_cast<double>(a), w);
    }

    void reset() noexcept { xPrev.fill(T(0)); yPrev.fill(T(0)); }

    T process(T x) noexcept
    {
        for (int s = 0; s < sections; ++s) {
            const T y = a * x + xPrev[s] - a * yPrev[s];
            xPrev[s] = x;
            yPrev[s] = y;
            x = y;
        }
        return x;
    }
};

} // namespace rosin::dsp
