// Reflection-function pieces for one waveguide segment (PHYSICS.md 1.2): a one-pole loss
// filter fitted to the target damping (optionally with its DC restored by a low shelf), and an
// optional chain of first-order allpasses for bending-stiffness dispersion. The sign inversion of
// a rigid end is applied by the caller.
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

/// One reflection's loss: a one-pole low-pass g (1 + p) / (1 + p z^-1) fitted to the target
/// magnitudes at two frequencies, optionally times a first-order low shelf S(z) = K (1 - zeta z^-1) / (1 -
/// rho z^-1) that gives back at DC what the low-pass loses there. A real string's damping vanishes
/// at zero frequency (a held deflection does not relax); the low-pass alone lost about as much at
/// DC as at f0, so a sticking bow's displacement crept back (the cello D's pre-slip ramp 4.5 %
/// soft after 0.2 s, with torsion 9 %; docs/model.md). The shelf's corner sits below f0, so it
/// barely touches the harmonics; the low-pass is refitted so that the pair hits the targets.
template <typename T>
struct OnePoleLoss {
    T b0 = T(1);   ///< g (1 + p)
    T a1 = T(0);   ///< p
    T state = T(0);
    /// The shelf as 1 + (top0 + top1 z^-1) / (1 - rho z^-1): the low-pass output plus a small
    /// top-up, so that rounding (in float) is relative to the top-up, not to the wave.
    T top0 = T(0), top1 = T(0), shelfPole = T(0); ///< K - 1, rho - K zeta, rho
    T topState = T(0);

    /// DC gain the pair aims at: a hair under 1, so that rounding can never make a reflection
    /// gain at DC (a held deflection then relaxes over about 1e6 reflections, minutes).
    static constexpr double kDcGain = 1.0 - 1e-6;

    /// Fit to magnitudes m1 at w1 and m2 at w2 (rad/sample), closed form, with the DC restored
    /// by a shelf whose corner is wRestore (rad/sample; 0 = no shelf, the low-pass alone). The
    /// low-pass falls back to a flat gain when the targets are (numerically) flat or a low-pass
    /// cannot reach them.
    void design(double m1, double w1, double m2, double w2, double wRestore = 0.0) noexcept
    {
        setShelf(1.0, 0.0, 0.0);
        double t1 = m1, t2 = m2;
        for (int pass = 0; pass < (wRestore > 0.0 ? 4 : 1); ++pass) {
            designLowPass(t1, w1, t2, w2);
            if (!(wRestore > 0.0)) break;
            const double g = static_cast<double>(b0) / (1.0 + static_cast<double>(a1));
            if (!(g > 0.0 && g < kDcGain)) break;
            // S(1) = K (1 - zeta) / (1 - rho) = kDcGain / g and S(-1) = K (1 + zeta) / (1 + rho) = 1.
            const double rho = std::exp(-wRestore);
            const double q = (1.0 - rho) / (1.0 + rho) * kDcGain / g;
            const double zeta = (1.0 - q) / (1.0 + q);
            setShelf((1.0 + rho) / (1.0 + zeta), zeta, rho);
            t1 = m1 / shelfMagnitude(w1);
            t2 = m2 / shelfMagnitude(w2);
        }
        // Coefficients rounded to T could leave the DC gain a hair above kDcGain: scale the top-up.
        const double g = static_cast<double>(b0) / (1.0 + static_cast<double>(a1));
        const double r = static_cast<double>(shelfPole), sum = static_cast<double>(top0) + static_cast<double>(top1);
        if (dcGain() > kDcGain && sum > 0.0) {
            const double scale = (kDcGain / g - 1.0) * (1.0 - r) / sum * (1.0 - 1e-7);
            top0 = static_cast<T>(static_cast<double>(top0) * scale);
            top1 = static_cast<T>(static_cast<double>(top1) * scale);
        }
    }

    void setIdentity() noexcept
    {
        b0 = T(1);
        a1 = T(0);
        setShelf(1.0, 0.0, 0.0);
    }

    /// Gain at DC of the pair, from the coefficients as stored.
    double dcGain() const noexcept
    {
        const double r = static_cast<double>(shelfPole), sum = static_cast<double>(top0) + static_cast<double>(top1);
        return static_cast<double>(b0) / (1.0 + static_cast<double>(a1)) * (1.0 + sum / (1.0 - r));
    }

    /// |H| at w (rad/sample).
    double magnitude(double w) const noexcept
    {
        const double p = static_cast<double>(a1);
        return static_cast<double>(b0) / std::sqrt(1.0 + 2.0 * p * std::cos(w) + p * p) * shelfMagnitude(w);
    }

    /// Phase delay (samples) at w (rad/sample).
    double phaseDelay(double w) const noexcept
    {
        // arg H = -arg(1 + p e^{-iw}) + arg(S(e^{iw}))
        const double p = static_cast<double>(a1);
        const double lowPass = -std::atan2(-p * std::sin(w), 1.0 + p * std::cos(w));
        const std::array<double, 2> s = shelfResponse(w);
        return -(lowPass + std::atan2(s[1], s[0])) / w;
    }

    void reset() noexcept { state = T(0); topState = T(0); }

    T process(T x) noexcept
    {
        const T y = b0 * x - a1 * state;
        const T top = top0 * y + top1 * state + shelfPole * topState;
        state = y;
        topState = top;
        return y + top;
    }

private:
    void designLowPass(double m1, double w1, double m2, double w2) noexcept
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

    void setShelf(double k, double zeta, double rho) noexcept
    {
        top0 = static_cast<T>(k - 1.0);
        top1 = static_cast<T>(rho - k * zeta);
        shelfPole = static_cast<T>(rho);
    }

    /// S(e^{iw}) = 1 + (top0 + top1 e^{-iw}) / (1 - rho e^{-iw}), as (re, im).
    std::array<double, 2> shelfResponse(double w) const noexcept
    {
        const double t0 = static_cast<double>(top0), t1 = static_cast<double>(top1), r = static_cast<double>(shelfPole);
        const double nr = t0 + t1 * std::cos(w), ni = -t1 * std::sin(w);
        const double dr = 1.0 - r * std::cos(w), di = r * std::sin(w);
        const double d2 = dr * dr + di * di;
        return {1.0 + (nr * dr + ni * di) / d2, (ni * dr - nr * di) / d2};
    }

    double shelfMagnitude(double w) const noexcept
    {
        const std::array<double, 2> s = shelfResponse(w);
        return std::hypot(s[0], s[1]);
    }
};

/// Chain of identical first-order allpasses A(z) = (a + z^-1) / (1 + a z^-1). With a in (-1, 0)
/// the phase delay falls with frequency, so upper partials come round sooner: a stiff string.
template <typename T, int MaxSections = 8>
struct DispersionChain {
    int sections = 0;
    T a = T(0);
    std::array<T, static_cast<std::size_t>(MaxSections)> xPrev{}, yPrev{};

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

/// MSW83-style reflection (PHYSICS.md 1.2): a delayed Gaussian pulse of width sigma and area
/// 1 - eps, |R| = (1 - eps) exp(-w^2 sigma^2 / 2). Realised as an FIR read around the delay,
/// so it also does the fractional delay. Fitted to the same two target magnitudes as the
/// one-pole design; the pulse is symmetric, so it adds no phase delay.
template <typename T>
struct GaussianReflection {
    static constexpr int kMaxTaps = 24;
    std::size_t first = 1; ///< delay of the first tap
    int taps = 1;
    T weights[kMaxTaps]{T(1)};

    /// delay (samples, >= 1), magnitudes m1 at w1 and m2 at w2 (rad/sample), m2 < m1.
    void design(double delay, double m1, double w1, double m2, double w2) noexcept
    {
        double sigma2 = 0.0;
        if (m2 < m1 && w2 > w1) sigma2 = 2.0 * std::log(m1 / m2) / (w2 * w2 - w1 * w1);
        const double sigma = std::sqrt(std::max(sigma2, 0.09)); // at least 0.3 samples: a smooth kernel
        const double area = m1 * std::exp(0.5 * w1 * w1 * sigma * sigma);
        const int reach = std::min(kMaxTaps / 2 - 1, static_cast<int>(std::ceil(4.0 * sigma)) + 1);
        const double lo = std::max(1.0, std::floor(delay) - reach);
        first = static_cast<std::size_t>(lo);
        taps = std::min(kMaxTaps, static_cast<int>(std::floor(delay) + reach + 1 - lo + 1));
        double sum = 0.0;
        for (int k = 0; k < taps; ++k) {
            const double d = (lo + k - delay) / sigma;
            weights[k] = static_cast<T>(std::exp(-0.5 * d * d));
            sum += static_cast<double>(weights[k]);
        }
        for (int k = 0; k < taps; ++k) weights[k] = static_cast<T>(static_cast<double>(weights[k]) * area / sum);
    }
};

} // namespace rosin::dsp
