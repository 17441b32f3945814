#include "rosin/reference/Friction.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

namespace rosin::reference {

double SteadySliding::mu(double speed) const
{
    const double v = std::abs(speed);
    if (shape == Shape::Exponentials) return level * (a1 * std::exp(-v / v1) + a2 * std::exp(-v / v2) + a3);
    return level * c * std::pow(v + v0, -p);
}

double SteadySliding::slope(double speed) const
{
    const double v = std::abs(speed);
    if (shape == Shape::Exponentials) return -level * (a1 / v1 * std::exp(-v / v1) + a2 / v2 * std::exp(-v / v2));
    return -level * p * c * std::pow(v + v0, -p - 1.0);
}

double SpeedFunction::at(double speed) const { return h0 * std::pow((std::abs(speed) + v0) / v0, -p); }

double steadyRise(double speed, const Friction& f)
{
    const ContactConstants& k = f.contact;
    const double a = k.radiusAtReference, area = std::numbers::pi * a * a, v = std::abs(speed);
    if (v <= 0.0) return 0.0;
    // Generated heat F mu v leaves by advection (rho c delta w v theta) and into the renewed
    // rod (A e_r sqrt(3 v / 8 a) theta); the stationary string's flux has died away.
    const double advection = k.rosinVolumetricHeat * k.layerThickness * k.advectionWidthFactor * a * v;
    const double conduction = area * k.rodEffusivity * std::sqrt(3.0 * v / (8.0 * a));
    return k.referenceLoad * f.steady.mu(v) * v / (advection + conduction);
}

void TemperatureTable::build(const Friction& f, int points)
{
    // The monotonic part of theta_ss(v): scan a log grid of speeds up to its first maximum.
    double vPeak = 1e-9, thetaPeak = 0.0;
    for (int i = 0; i <= 4000; ++i) {
        const double v = std::pow(10.0, -9.0 + 10.0 * i / 4000.0);
        const double th = steadyRise(v, f);
        if (th <= thetaPeak) break;
        vPeak = v;
        thetaPeak = th;
    }
    thetaMax_ = thetaPeak;
    const bool enhanced = f.law == FrictionLaw::Enhanced;
    auto value = [&](double v) { return enhanced ? f.steady.mu(v) / f.speed.at(v) : f.steady.mu(v); };
    values_.assign(static_cast<std::size_t>(points), 0.0);
    step_ = thetaMax_ / (points - 1);
    values_[0] = value(0.0);
    for (int i = 1; i < points; ++i) {
        const double target = i * step_;
        double lo = 0.0, hi = vPeak; // theta_ss rises on [0, vPeak]: bisect in log speed
        for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
            const double mid = lo > 0.0 ? std::sqrt(lo * hi) : 0.5 * hi;
            (steadyRise(mid, f) < target ? lo : hi) = mid;
        }
        values_[static_cast<std::size_t>(i)] = value(0.5 * (lo + hi));
    }
}

double TemperatureTable::at(double theta) const
{
    if (values_.empty()) return 1.0;
    if (!(theta > 0.0)) return values_.front();
    const double x = theta / step_;
    if (x >= static_cast<double>(values_.size() - 1)) return values_.back();
    const auto i = static_cast<std::size_t>(x);
    const double s = x - static_cast<double>(i);
    return values_[i] + s * (values_[i + 1] - values_[i]);
}

namespace {

/// The outermost (largest) root of g(x) = twoZ (d - x) - limit(x) on (0, d], if any. g(d) <= 0;
/// g is concave when limit is convex, so scanning down from d finds the outer sign change.
std::optional<double> outerRoot(double d, double twoZ, const std::function<double(double)>& limit)
{
    if (d <= 0.0) return std::nullopt;
    auto g = [&](double x) { return twoZ * (d - x) - limit(x); };
    double hi = d, lo = -1.0;
    if (g(d) >= 0.0) return d;
    double best = -1e300, bestX = d;
    for (int i = 1; i <= 80; ++i) {
        const double x = d * std::pow(0.8, i);
        const double gx = g(x);
        if (gx >= 0.0) {
            lo = x;
            break;
        }
        if (gx > best) { best = gx; bestX = x; }
        hi = x;
    }
    if (lo < 0.0) {
        if (g(0.0) >= 0.0) {
            lo = 0.0;
        } else {
            // A root may hide near g's maximum between two scan points: search for it.
            double a = bestX * 0.8, b = std::min(d, bestX / 0.8);
            for (int it = 0; it < 100; ++it) {
                const double m1 = a + (b - a) * 0.381966, m2 = a + (b - a) * 0.618034;
                (g(m1) < g(m2) ? a : b) = g(m1) < g(m2) ? m1 : m2;
            }
            const double top = 0.5 * (a + b);
            if (g(top) < 0.0) return std::nullopt;
            lo = top;
            hi = std::min(d, bestX / 0.8);
            while (g(hi) >= 0.0 && hi < d) hi = std::min(d, hi / 0.8);
        }
    }
    for (int it = 0; it < 200 && hi - lo > 1e-14 * d; ++it) {
        const double mid = 0.5 * (lo + hi);
        (g(mid) >= 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

} // namespace

ContactSolver::Result ContactSolver::solve(double vFree, double bowSpeed, double twoZ, const std::function<double(double)>& limit,
                                           bool flat)
{
    const double d = bowSpeed - vFree; // the bow leads the free string by d
    const double stickForce = twoZ * d;
    const bool canStick = std::abs(stickForce) <= limit(0.0);
    auto slipOn = [&](double side) -> std::optional<double> {
        const double ds = side * d;
        if (flat) {
            const double x = ds - limit(0.0) / twoZ;
            if (x > 0.0) return x;
            return std::nullopt;
        }
        return outerRoot(ds, twoZ, limit);
    };
    auto slipResult = [&](double side, double x) {
        state_ = side > 0 ? ContactState::SlipForward : ContactState::SlipBackward;
        const double force = side * limit(x);
        return Result{force, vFree + force / twoZ, false};
    };
    // Hysteresis (PHYSICS.md 2.3): a sticking contact stays stuck while it can; a slipping one
    // follows its branch while the branch exists, then sticks, or else slips the other way.
    if (state_ == ContactState::Stick) {
        if (canStick) return {stickForce, bowSpeed, true};
        const double side = d > 0 ? 1.0 : -1.0;
        if (auto x = slipOn(side)) return slipResult(side, *x);
        return {stickForce, bowSpeed, true}; // no slip root at all: only sticking is consistent
    }
    const double side = state_ == ContactState::SlipForward ? 1.0 : -1.0;
    if (auto x = slipOn(side)) return slipResult(side, *x);
    if (canStick) {
        state_ = ContactState::Stick;
        return {stickForce, bowSpeed, true};
    }
    if (auto x = slipOn(-side)) return slipResult(-side, *x);
    state_ = ContactState::Stick;
    return {stickForce, bowSpeed, true};
}

} // namespace rosin::reference
