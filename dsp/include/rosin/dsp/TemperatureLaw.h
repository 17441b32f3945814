// mu(theta) (thermal model) and y(theta) (enhanced model), built by inverting steady sliding
// (PHYSICS.md 3.5, 4.2): in steady sliding at speed v the contact settles at theta_ss(v), and
// the measured mu_ss(v) is then the friction at that temperature.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "Config.h"
#include "FrictionLaws.h"

namespace rosin::dsp {

/// Steady contact temperature rise at sliding speed v under the reference load (PHYSICS.md 3.3).
inline double steadyTemperature(double v, double mu, const ThermalParams& tp) noexcept
{
    const double a = tp.contactRadiusAtRef;
    const double area = std::numbers::pi * a * a;
    const double advection = tp.rosinHeatCapacity * tp.layerThickness * tp.advectionWidthFactor * a * v;
    const double conduction = area * tp.rodEffusivity * std::sqrt(3.0 * v / (8.0 * a));
    return tp.referenceLoad * mu * v / (advection + conduction);
}

class TemperatureLaw {
public:
    /// [setup thread] Builds the table. With a speed function it tabulates y = mu_ss / h
    /// (enhanced model); without, mu_ss itself (original thermal model).
    void build(SteadyFit fit, std::nullopt_t, const ThermalParams& tp) { build(SteadyCurve::of(fit), std::optional<SpeedLaw>(), tp); }
    void build(const SteadyCurve& fit, std::nullopt_t, const ThermalParams& tp) { build(fit, std::optional<SpeedLaw>(), tp); }

    void build(SteadyFit fit, std::optional<SpeedFunction> speed, const ThermalParams& tp)
    {
        build(SteadyCurve::of(fit), speed ? std::optional<SpeedLaw>(SpeedLaw::of(*speed)) : std::nullopt, tp);
    }

    void build(const SteadyCurve& fit, std::optional<SpeedLaw> speed, const ThermalParams& tp)
    {
        // Dense log grid of speeds; stop at the first maximum of theta_ss (beyond it the
        // inversion is not single-valued: clamp there, PHYSICS.md 3.5 step 3).
        std::vector<double> thetas{0.0}, values;
        values.push_back(valueAt(fit, speed, 0.0));
        const int n = 6000;
        for (int i = 0; i <= n; ++i) {
            const double v = std::pow(10.0, -8.0 + 9.0 * i / n); // 1e-8 .. 10 m/s
            const double th = steadyTemperature(v, fit(v).mu, tp);
            if (th <= thetas.back()) break;
            thetas.push_back(th);
            values.push_back(valueAt(fit, speed, v));
        }
        thetaMax_ = thetas.back();
        const auto m = static_cast<std::size_t>(config::temperatureTableSize);
        table_.assign(m, 0.0);
        step_ = thetaMax_ / static_cast<double>(m - 1);
        std::size_t j = 0;
        for (std::size_t i = 0; i < m; ++i) {
            const double th = static_cast<double>(i) * step_;
            while (j + 2 < thetas.size() && thetas[j + 1] < th) ++j;
            const double t0 = thetas[j], t1 = thetas[j + 1];
            const double s = std::clamp((th - t0) / (t1 - t0), 0.0, 1.0);
            table_[i] = values[j] + s * (values[j + 1] - values[j]);
        }
        shift_ = tp.temperatureShift();
        scale_ = tp.footprintRatio;
        invStep_ = 1.0 / step_;
        lastIndex_ = static_cast<double>(m - 1);
        tableLast_ = table_.back();
        segments_.assign(m - 1, Segment{});
        nonIncreasing_ = true;
        for (std::size_t i = 0; i + 1 < m; ++i) {
            segments_[i] = {table_[i], table_[i + 1] - table_[i]};
            nonIncreasing_ = nonIncreasing_ && segments_[i].rise <= 0.0;
        }
        built_ = true;
    }

    /// Friction coefficient (or y) at contact rise theta above ambient, with the rosin and
    /// ambient shift and the footprint ratio applied. Clamped at both ends of the table.
    double operator()(double theta) const noexcept { return at(theta).mu; }

    /// Both at once, from one index computation (the junction needs both every slipping sample).
    MuSlope at(double theta) const noexcept
    {
        const double x = (theta + shift_) * invStep_;
        if (!(x >= 0.0)) return {scale_ * table_[0], 0.0};
        if (x >= lastIndex_) return {scale_ * tableLast_, 0.0};
        const auto i = static_cast<std::size_t>(x);
        const double s = x - static_cast<double>(i);
        const Segment& g = segments_[i]; // one read: a slipping sample's next temperature waits for it
        return {scale_ * (g.start + s * g.rise), scale_ * g.rise * invStep_};
    }

    /// d/d(theta) of operator(), one-sided on the table grid (0 where the law is clamped).
    double slope(double theta) const noexcept { return at(theta).slope; }

    /// Unshifted, unscaled table value at theta (what the inversion itself produced).
    double raw(double theta) const noexcept
    {
        const double x = std::clamp(theta / step_, 0.0, static_cast<double>(table_.size() - 1));
        const auto i = std::min(static_cast<std::size_t>(x), table_.size() - 2);
        const double s = x - static_cast<double>(i);
        return table_[i] + s * (table_[i + 1] - table_[i]);
    }

    /// [audio thread] Ambient and rosin shift without rebuilding the table.
    void setShift(double kelvin) noexcept { shift_ = kelvin; }
    /// [audio thread] Footprint ratio r_A without rebuilding the table.
    void setScale(double ratio) noexcept { scale_ = ratio; }
    /// True once build() has run (a default law is flat at 1).
    bool built() const noexcept { return built_; }
    /// True when the law never rises with temperature (friction falls as the contact warms),
    /// so its value at a temperature bounds it from below at every cooler one.
    bool nonIncreasing() const noexcept { return nonIncreasing_ && scale_ >= 0.0; }

    /// Largest temperature rise the steady-sliding data reaches (K); the law is flat above.
    double thetaMax() const noexcept { return thetaMax_; }

private:
    static double valueAt(const SteadyCurve& fit, const std::optional<SpeedLaw>& speed, double v) noexcept
    {
        const double mu = fit(v).mu;
        return speed ? mu / (*speed)(v).mu : mu;
    }

    struct Segment {
        double start, rise; // table_[i] and table_[i + 1] - table_[i]
    };
    std::vector<double> table_{1.0, 1.0};
    std::vector<Segment> segments_{{1.0, 0.0}};
    bool built_ = false, nonIncreasing_ = true; // the default law is flat
    double step_ = 1.0, invStep_ = 1.0, thetaMax_ = 1.0, shift_ = 0.0, scale_ = 1.0;
    double lastIndex_ = 1.0, tableLast_ = 1.0; // the clamp at() tests every sample, kept at hand
};

} // namespace rosin::dsp
