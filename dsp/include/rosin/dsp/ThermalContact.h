// Heat balance of the rosin contact (PHYSICS.md 3.3-3.4).
//
// Conduction into a half-space is sqrt(s) in the Laplace domain (sqrt(s + kappa) when the
// surface moves through the contact and is renewed). Both are written as a sum of one-pole
// states on a logarithmic grid of rates xi_k, so the history costs O(M) per sample instead of
// a growing convolution. Conduction is stiff at audio rates, so the temperature is updated
// implicitly with the pole states integrated exactly over the step.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "Config.h"
#include "FrictionLaws.h"

namespace rosin::dsp {

/// Bank of one-pole states approximating sqrt(s + kappa) for one side of the contact.
/// Flux per unit area and effusivity, with theta held over the step: Gamma*theta - H.
template <typename T>
class ConductionBank {
public:
    /// [setup thread] Log grid xi_min..xi_max, `perDecade` poles per decade. Weights from the
    /// trapezoid rule on sqrt(s) = (1/pi) int s/(s+xi) xi^{-1/2} dxi, plus the two ends of the
    /// integral the grid leaves out: below it, one pole at xi_lo/3 (matters for t ~ 1/xi_min);
    /// above it, s/(s+xi) ~ s/xi, i.e. an extra heat capacity 2/(pi sqrt(xi_hi)) (matters once
    /// kappa approaches xi_max).
    void prepare(double sampleRate, double xiMin, double xiMax, double perDecade) noexcept
    {
        h_ = 1.0 / sampleRate;
        const double decades = std::log10(xiMax / xiMin);
        count_ = std::clamp(static_cast<int>(std::ceil(decades * perDecade)) + 1, 2, N - 1);
        const double delta = std::log(xiMax / xiMin) / (count_ - 1);
        for (int k = 0; k < count_; ++k) {
            xi_[k] = xiMin * std::exp(delta * k);
            weight_[k] = std::sqrt(xi_[k]) * delta / std::numbers::pi;
        }
        // int_0^{xi_lo} xi^{-1/2} dxi / pi with xi_lo the lower edge of the first cell.
        const double xiLo = xiMin * std::exp(-0.5 * delta);
        xi_[count_] = xiLo / 3.0;
        weight_[count_] = 2.0 * std::sqrt(xiLo) / std::numbers::pi;
        ++count_;
        tailCapacity_ = 2.0 / (std::numbers::pi * std::sqrt(xiMax * std::exp(0.5 * delta)));
        tailRate_ = tailCapacity_ / h_;
        for (int k = 0; k < count_; ++k) baseDecay_[k] = std::exp(-xi_[k] * h_);
        // Pad to whole blocks with inert poles (zero weight) so the hot loops vectorise.
        // Unused slots are inert (zero weight); every loop runs over all of them.
        for (int k = count_; k < N; ++k) { xi_[k] = 1.0; weight_[k] = 0.0; baseDecay_[k] = 0.0; }
        for (int k = 0; k < N; ++k) {
            xiT_[k / kLanes][k % kLanes] = static_cast<T>(xi_[k]);
            weightT_[k / kLanes][k % kLanes] = static_cast<T>(weight_[k]);
            weightXiT_[k / kLanes][k % kLanes] = static_cast<T>(weight_[k] * xi_[k]);
            baseDecayT_[k / kLanes][k % kLanes] = static_cast<T>(baseDecay_[k]);
        }
        kappa_ = -1.0;
        setKappa(0.0);
        reset();
    }

    void reset() noexcept
    {
        for (Pack& z : z_) z = Pack{};
        thetaPrev_ = 0.0;
        // The 2 % rule of setKappa remembers the last kappa: forget it, so a reset bank
        // behaves exactly like a freshly prepared one.
        kappa_ = -1.0;
        setKappa(0.0);
    }

    /// [audio thread] Surface-renewal rate (1/s). Coefficients are recomputed only when it moves
    /// by more than 2 % (or to/from zero), which during sticking is never.
    void setKappa(double kappa) noexcept
    {
        if (kappa == kappa_) return;
        if (kappa > 0.0 && kappa_ > 0.0 && std::abs(kappa - kappa_) < 0.02 * kappa_) return;
        kappa_ = kappa;
        // Runs on most slipping samples: kept in T and in packs so it vectorises.
        const T ek = static_cast<T>(std::exp(-kappa * h_)), kap = static_cast<T>(kappa);
        Pack g{};
        for (int p = 0; p < kPacks; ++p) {
            const Pack eps = baseDecayT_[p] * ek;
            const Pack b = (T(1) - eps) / (xiT_[p] + kap);
            decay_[p] = eps;
            gain_[p] = b;
            historyWeight_[p] = weightXiT_[p] * eps;
            g += weightT_[p] * (T(1) - xiT_[p] * b);
        }
        double gamma = 0.0;
        for (int j = 0; j < kLanes; ++j) gamma += static_cast<double>(g[j]);
        gamma_ = gamma;
        gammaTotal_ = gamma + tailCapacity_ * (1.0 / h_ + kappa);
    }

    /// This step's flux (per unit area and effusivity) is gamma() * theta_new - history().
    double gamma() const noexcept { return gammaTotal_; }

    /// History part of this step's flux (depends on past states only).
    double history() const noexcept
    {
        Pack acc = historyWeight_[0] * z_[0];
        for (int p = 1; p < kPacks; ++p) acc += historyWeight_[p] * z_[p];
        T s = T(0);
        for (int j = 0; j < kLanes; ++j) s += acc[j];
        return static_cast<double>(s) + tailRate_ * thetaPrev_;
    }

    /// Commit the step with the new temperature.
    void advance(T theta) noexcept
    {
        for (int p = 0; p < kPacks; ++p) z_[p] = decay_[p] * z_[p] + gain_[p] * theta;
        thetaPrev_ = static_cast<double>(theta);
    }

    /// Flux (per unit area and effusivity) if the temperature is held at theta from now on
    /// (the capacity term then contributes only its kappa part).
    double flux(double theta) const noexcept
    {
        double s = tailCapacity_ * kappa_ * theta;
        for (int k = 0; k < count_; ++k) s += weight_[k] * (theta - xi_[k] * static_cast<double>(z_[k / kLanes][k % kLanes]));
        return s;
    }

    int poleCount() const noexcept { return count_; }

private:
    static constexpr int N = config::thermalPoleSlots;
    // 16-byte packs of T (GCC/Clang vector extension): 4 floats or 2 doubles per operation.
    typedef T Pack __attribute__((vector_size(16)));
    static constexpr int kLanes = 16 / static_cast<int>(sizeof(T));
    static constexpr int kPacks = N / kLanes;
    double h_ = 1.0 / 48000.0, kappa_ = -1.0, gamma_ = 0.0, gammaTotal_ = 0.0, tailCapacity_ = 0.0, tailRate_ = 0.0, thetaPrev_ = 0.0;
    int count_ = 0;
    std::array<double, N> xi_{}, weight_{}, baseDecay_{};
    // Plain arrays: GCC drops the vector attribute of Pack inside std::array<Pack, ...>.
    Pack z_[kPacks]{}, decay_[kPacks]{}, gain_[kPacks]{}, historyWeight_[kPacks]{};
    Pack xiT_[kPacks]{}, weightT_[kPacks]{}, weightXiT_[kPacks]{}, baseDecayT_[kPacks]{};
};

/// Contact temperature rise theta (K above ambient) driven by frictional heating.
template <typename T>
class ThermalContact {
public:
    /// [setup thread]
    void prepare(double sampleRate, const ThermalParams& params) noexcept
    {
        params_ = params;
        h_ = 1.0 / sampleRate;
        rate_ = sampleRate;
        const double xiMax = params.xiMaxOverSampleRate * sampleRate;
        stringSide_.prepare(sampleRate, params.xiMin, xiMax, params.polesPerDecade);
        rodSide_.prepare(sampleRate, params.xiMin, xiMax, params.polesPerDecade);
        reset();
    }

    void reset() noexcept
    {
        stringSide_.reset();
        rodSide_.reset();
        theta_ = 0.0;
    }

    /// [audio thread] One implicit step (PHYSICS.md 3.4). heat = |f dv| and slidingSpeed = |dv|
    /// of the previous step; area (m^2) from the contact law. heatSlope = d(heat)/d(theta) at
    /// that state (<= 0 while slipping: friction falls as the contact warms). Taking the heat
    /// input implicitly to first order keeps the update stable where mu(theta) is steep; the
    /// explicit form oscillates there once the step is long against the layer's storage time.
    /// Returns the new theta.
    double step(double heat, double slidingSpeed, double area, double heatSlope = 0.0) noexcept
    {
        if (!(area > 0.0)) {
            // Bow off the string: no contact, the rosin spot relaxes to ambient.
            theta_ = 0.0;
            stringSide_.advance(T(0));
            rodSide_.setKappa(0.0);
            rodSide_.advance(T(0));
            return theta_;
        }
        if (area != areaCached_) {
            areaCached_ = area;
            radiusCached_ = std::sqrt(area / std::numbers::pi);
            renewalPerSpeed_ = 3.0 / (8.0 * radiusCached_);
        }
        const double radius = radiusCached_;
        const double rhoCDelta = params_.rosinHeatCapacity * params_.layerThickness;
        const double storage = rhoCDelta * area * rate_;
        const double advection = rhoCDelta * params_.advectionWidthFactor * radius * slidingSpeed;
        rodSide_.setKappa(renewalPerSpeed_ * slidingSpeed); // kappa = 3 |dv| / (8 a)
        const double es = area * params_.stringEffusivity, er = area * params_.rodEffusivity;
        const double slope = std::min(heatSlope, 0.0);
        const double num = storage * theta_ + heat - slope * theta_ + es * stringSide_.history() + er * rodSide_.history();
        // While sticking nothing in the denominator moves, so its reciprocal is reused: the
        // division sits on the sample-to-sample dependency chain and is its slowest link.
        const double den = storage + advection - slope + es * stringSide_.gamma() + er * rodSide_.gamma();
        if (den != denCached_) {
            denCached_ = den;
            invDenCached_ = 1.0 / den;
        }
        theta_ = std::max(0.0, num * invDenCached_);
        stringSide_.advance(static_cast<T>(theta_));
        rodSide_.advance(static_cast<T>(theta_));
        return theta_;
    }

    double temperature() const noexcept { return theta_; }
    const ThermalParams& params() const noexcept { return params_; }

private:
    ThermalParams params_;
    double h_ = 1.0 / 48000.0, rate_ = 48000.0, theta_ = 0.0, areaCached_ = -1.0, radiusCached_ = 0.0, renewalPerSpeed_ = 0.0, denCached_ = 0.0, invDenCached_ = 0.0;
    ConductionBank<T> stringSide_, rodSide_;
};

} // namespace rosin::dsp
