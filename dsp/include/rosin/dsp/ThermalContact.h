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
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

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
    ///
    /// renewalGrid: also tabulate the kappa-dependent sums on a fine grid of kappa (allocates;
    /// see setKappa). Only a side whose surface moves needs it.
    void prepare(double sampleRate, double xiMin, double xiMax, double perDecade, bool renewalGrid = false)
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
        packs_ = (count_ + kLanes - 1) / kLanes; // the per-sample loops skip packs of inert poles
        for (int k = 0; k < N; ++k) {
            xiT_[k / kLanes][k % kLanes] = static_cast<T>(xi_[k]);
            weightT_[k / kLanes][k % kLanes] = static_cast<T>(weight_[k]);
            weightXiDecayT_[k / kLanes][k % kLanes] = static_cast<T>(weight_[k] * xi_[k] * baseDecay_[k]);
            baseDecayT_[k / kLanes][k % kLanes] = static_cast<T>(baseDecay_[k]);
        }
        buildRenewalGrid(renewalGrid);
        kappa_ = -1.0;
        setKappa(0.0);
        reset();
    }

    void reset() noexcept
    {
        for (Pack& z : z_) z = Pack{};
        thetaPrev_ = 0.0;
        pendingPoles_ = 0.0; // no history yet
        // The 2 % rule of setKappa remembers the last kappa: forget it, so a reset bank
        // behaves exactly like a freshly prepared one.
        kappa_ = -1.0;
        setKappa(0.0);
        pendingGain_ = historyGain_; // as if advance() had run: with no states the history is 0 anyway
    }

    /// [audio thread] Surface-renewal rate (1/s). True when the coefficients changed.
    ///
    /// With the renewal grid, a kappa inside it is rounded to the nearest grid value (at most
    /// 0.8 % away) and the coefficients change only when that grid value does. Elsewhere (and
    /// without the grid) they are recomputed only when kappa moves by more than 2 % (or to or
    /// from zero), the tolerance of PHYSICS.md 3.4. During sticking neither ever happens.
    bool setKappa(double kappa) noexcept
    {
        if (kappa == kappa_) return false;
        if (kappa >= gridLow_ && kappa < gridHigh_) {
            const int index = gridIndex(kappa);
            if (index == gridIndex_) return false;
            // While slipping kappa follows the sliding speed, which follows this sample's
            // temperature, so the next temperature waits for these coefficients. The grid turns
            // the exponential and the sums over the poles into one table read on that path.
            const RenewalEntry& e = renewal_[static_cast<std::size_t>(index)];
            gridIndex_ = index;
            kappa_ = e.kappa;
            fillCoefficients<false>(e.kappa, e.decay);
            gammaTotal_ = e.gamma;
            historyGain_ = e.historyGain;
            return true;
        }
        if (kappa > 0.0 && kappa_ > 0.0 && std::abs(kappa - kappa_) < 0.02 * kappa_) return false;
        gridIndex_ = -1;
        kappa_ = kappa;
        fillCoefficients<true>(kappa, static_cast<T>(std::exp(-kappa * h_)));
        return true;
    }

    /// The renewal rate the coefficients were computed for (a grid value when on the grid).
    double kappa() const noexcept { return kappa_; }
    /// Range of kappa (1/s) served by the renewal grid; empty without it.
    double renewalGridLow() const noexcept { return gridLow_; }
    double renewalGridHigh() const noexcept { return gridHigh_; }

    /// This step's flux (per unit area and effusivity) is gamma() * theta_new - history().
    double gamma() const noexcept { return gammaTotal_; }

    /// History part of this step's flux (depends on past states only), from the prediction
    /// advance() left: historyDrive() + historyThetaGain() * (the temperature it was given).
    double history() const noexcept { return historyDrive() + historyThetaGain() * thetaPrev_; }

    /// The history split for the implicit update, which folds the second part into its own
    /// temperature term: historyDrive() does not depend on the last temperature, so it is ready
    /// before that is solved.
    double historyDrive() const noexcept { return static_cast<double>(renewalDecay_) * pendingPoles_; }
    double historyThetaGain() const noexcept { return static_cast<double>(renewalDecay_) * pendingGain_ + tailRate_; }

    /// The same, summed from the pole states now (what the prediction in advance() must equal).
    /// The weights w xi eps carry kappa only through the common factor exp(-kappa h), applied
    /// after the sum.
    double recomputedHistory() const noexcept
    {
        Pack acc = weightXiDecayT_[0] * z_[0];
        for (int p = 1; p < packs_; ++p) acc += weightXiDecayT_[p] * z_[p];
        return static_cast<double>(sum(acc)) * static_cast<double>(renewalDecay_) + tailRate_ * thetaPrev_;
    }

    /// Commit the step with the new temperature.
    ///
    /// Also predicts the next step's history. With weights w xi eps0 exp(-kappa' h) for the
    /// kappa' of that step and z' = eps z + b theta, it is
    ///   exp(-kappa' h) [sum(w xi eps0 eps z) + sum(w xi eps0 b) theta] + tail theta.
    /// The pole sum needs only the old states, so it runs while theta is still being solved;
    /// the new kappa enters as one factor, so a change of kappa keeps the prediction; and theta
    /// reaches the next step as one coefficient of the implicit update, not through the bank
    /// (the sample-to-sample chain is what limits a voice's speed).
    void advance(double theta) noexcept
    {
        // A fixed pack count unrolls the loops; 44.1-96 kHz need one pack fewer than the slots.
        if (packs_ == kPacks - 1) advancePacks<kPacks - 1>(theta, kPacks - 1);
        else advancePacks<kPacks>(theta, packs_);
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
    /// Renewal grid: every float whose mantissa ends in 17 zero bits, i.e. 64 values per octave,
    /// 0.8-1.6 % apart, from 1/4 to 2^24 per second (below, kappa is under the slowest poles'
    /// rates; above, the contact would be a few microns wide). Rounding the float's bits finds
    /// the nearest value without a logarithm.
    static constexpr int kGridShift = 23 - 6;
    static constexpr float kGridLow = 0.25f, kGridHigh = 16777216.0f;
    /// The grid's ends as bit patterns shifted down: entry i is the float with bits (first + i) << shift.
    static constexpr std::uint32_t kGridFirst = std::bit_cast<std::uint32_t>(kGridLow) >> kGridShift;
    static constexpr std::uint32_t kGridLast = std::bit_cast<std::uint32_t>(kGridHigh) >> kGridShift;

    struct RenewalEntry {
        double kappa, gamma, historyGain;
        T decay; // exp(-kappa h), as the coefficients take it
    };

    static int gridIndex(double kappa) noexcept
    {
        const std::uint32_t bits = std::bit_cast<std::uint32_t>(static_cast<float>(kappa));
        return static_cast<int>(((bits + (1u << (kGridShift - 1))) >> kGridShift) - kGridFirst);
    }

    void buildRenewalGrid(bool wanted)
    {
        renewal_.clear();
        gridLow_ = gridHigh_ = 0.0; // empty range: setKappa never looks for the grid
        gridIndex_ = -1;
        if (!wanted) return;
        renewal_.reserve(kGridLast - kGridFirst + 1);
        for (std::uint32_t i = kGridFirst; i <= kGridLast; ++i) {
            RenewalEntry e{};
            e.kappa = static_cast<double>(std::bit_cast<float>(i << kGridShift));
            e.decay = static_cast<T>(std::exp(-e.kappa * h_));
            fillCoefficients<true>(e.kappa, e.decay); // the same arithmetic as the exact path
            e.gamma = gammaTotal_;
            e.historyGain = historyGain_;
            renewal_.push_back(e);
        }
        // Values that round onto the last entry stay inside; the top half-step falls back.
        gridLow_ = static_cast<double>(kGridLow);
        gridHigh_ = static_cast<double>(kGridHigh);
    }

    /// Pole coefficients for renewal rate kappa with ek = exp(-kappa h); WithSums also forms
    /// gamma and the history gain (the grid has them tabulated).
    template <bool WithSums>
    void fillCoefficients(double kappa, T ek) noexcept
    {
        // Runs on most slipping samples: kept in T and in packs so it vectorises.
        const T kap = static_cast<T>(kappa);
        Pack g{}, c{};
        for (int p = 0; p < kPacks; ++p) {
            const Pack eps = baseDecayT_[p] * ek;
            const Pack b = (T(1) - eps) / (xiT_[p] + kap);
            decay_[p] = eps;
            gain_[p] = b;
            historyDecay_[p] = weightXiDecayT_[p] * eps; // exp(-kappa h) is applied to the sum
            if constexpr (WithSums) {
                g += weightT_[p] * (T(1) - xiT_[p] * b);
                c += weightXiDecayT_[p] * b;
            }
        }
        renewalDecay_ = ek;
        if constexpr (WithSums) {
            double gamma = 0.0, gain = 0.0;
            for (int j = 0; j < kLanes; ++j) {
                gamma += static_cast<double>(g[j]);
                gain += static_cast<double>(c[j]);
            }
            gammaTotal_ = gamma + tailCapacity_ * (1.0 / h_ + kappa);
            historyGain_ = gain;
        }
    }

    static constexpr int N = config::thermalPoleSlots;
    // 16-byte packs of T (GCC/Clang vector extension): 4 floats or 2 doubles per operation.
    typedef T Pack __attribute__((vector_size(16)));
    static constexpr int kLanes = 16 / static_cast<int>(sizeof(T));
    static constexpr int kPacks = N / kLanes;

    /// P: packs the compiler unrolls for; packs: how many carry poles (<= P).
    template <int P>
    void advancePacks(double theta, int packs) noexcept
    {
        const T th = static_cast<T>(theta);
        Pack q = historyDecay_[0] * z_[0];
        for (int p = 1; p < P; ++p)
            if (p < packs) q += historyDecay_[p] * z_[p];
        for (int p = 0; p < P; ++p)
            if (p < packs) z_[p] = decay_[p] * z_[p] + gain_[p] * th;
        pendingPoles_ = static_cast<double>(sum(q));
        pendingGain_ = historyGain_;
        thetaPrev_ = theta;
    }

    /// Sum of the lanes by halving (two shuffles for floats, one for doubles).
    static T sum(Pack x) noexcept
    {
        if constexpr (kLanes == 4) {
            x += __builtin_shufflevector(x, x, 2, 3, 0, 1);
            x += __builtin_shufflevector(x, x, 1, 0, 3, 2);
        } else {
            x += __builtin_shufflevector(x, x, 1, 0);
        }
        return x[0];
    }

    double h_ = 1.0 / 48000.0, kappa_ = -1.0, gammaTotal_ = 0.0, tailCapacity_ = 0.0, tailRate_ = 0.0, thetaPrev_ = 0.0;
    double historyGain_ = 0.0;  // sum(w xi eps0 b) of the coefficients in use
    double pendingPoles_ = 0.0, pendingGain_ = 0.0; // the prediction of the last advance()
    int count_ = 0, packs_ = kPacks, gridIndex_ = -1;
    double gridLow_ = 0.0, gridHigh_ = 0.0;
    std::vector<RenewalEntry> renewal_;
    std::array<double, N> xi_{}, weight_{}, baseDecay_{};
    // Plain arrays: GCC drops the vector attribute of Pack inside std::array<Pack, ...>.
    static constexpr auto kPackSlots = static_cast<std::size_t>(kPacks);
    Pack z_[kPackSlots]{}, decay_[kPackSlots]{}, gain_[kPackSlots]{}, historyDecay_[kPackSlots]{};
    Pack xiT_[kPackSlots]{}, weightT_[kPackSlots]{}, weightXiDecayT_[kPackSlots]{}, baseDecayT_[kPackSlots]{};
    T renewalDecay_ = T(1); // exp(-kappa h) of the coefficients in use
};

/// Contact temperature rise theta (K above ambient) driven by frictional heating.
template <typename T>
class ThermalContact {
public:
    /// [setup thread] Allocates (the rod side's renewal grid).
    void prepare(double sampleRate, const ThermalParams& params)
    {
        params_ = params;
        h_ = 1.0 / sampleRate;
        rate_ = sampleRate;
        const double xiMax = params.xiMaxOverSampleRate * sampleRate;
        stringSide_.prepare(sampleRate, params.xiMin, xiMax, params.polesPerDecade);
        rodSide_.prepare(sampleRate, params.xiMin, xiMax, params.polesPerDecade, true);
        areaCached_ = -1.0; // the per-area terms depend on the parameters just set
        reset();
    }

    void reset() noexcept
    {
        stringSide_.reset();
        rodSide_.reset();
        theta_ = 0.0;
        stillCached_ = false;
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
            stringSide_.advance(0.0);
            rodSide_.setKappa(0.0);
            rodSide_.advance(0.0);
            stillCached_ = false;
            return theta_;
        }
        const double slope = std::min(heatSlope, 0.0);
        // While sticking nothing in the update's coefficients moves (no sliding, no heat slope,
        // the same area and rod weights), so they and the reciprocal of den are kept from the
        // last still step: the division would otherwise sit on the sample-to-sample chain.
        const bool still = slidingSpeed == 0.0 && slope == 0.0;
        if (still && stillCached_ && area == areaCached_ && rodSide_.historyThetaGain() == rodGainCached_)
            return keptStep(heat + conductionDrive()); // (kappa is already 0: the last step was still)
        if (area != areaCached_) { // everything here follows the bow force only
            areaCached_ = area;
            const double radius = std::sqrt(area / std::numbers::pi);
            const double rhoCDelta = params_.rosinHeatCapacity * params_.layerThickness;
            renewalPerSpeed_ = 3.0 / (8.0 * radius);
            storage_ = rhoCDelta * area * rate_;
            advectionPerSpeed_ = rhoCDelta * params_.advectionWidthFactor * radius;
            stringEffusion_ = area * params_.stringEffusivity;
            rodEffusion_ = area * params_.rodEffusivity;
        }
        rodSide_.setKappa(renewalPerSpeed_ * slidingSpeed); // kappa = 3 |dv| / (8 a)
        // theta = num / den with num = (storage - slope) theta_prev + heat + the two sides'
        // histories. The histories' own theta_prev terms are gathered into one coefficient, so
        // the previous temperature passes through one multiply-add, and everything else in num
        // (the drive) is ready before it.
        const double drive = heat + conductionDrive();
        const double rodGain = rodSide_.historyThetaGain(); // follows the rod's kappa one step late
        const double den = storage_ + advectionPerSpeed_ * slidingSpeed - slope + stringEffusion_ * stringSide_.gamma()
                           + rodEffusion_ * rodSide_.gamma();
        const double self = storage_ - slope + stringEffusion_ * stringSide_.historyThetaGain() + rodEffusion_ * rodGain;
        stillCached_ = still;
        if (!still) { // slipping: the coefficients change every sample, divide once
            theta_ = std::max(0.0, (self * theta_ + drive) / den);
            return commit();
        }
        invDenCached_ = 1.0 / den;
        thetaGainCached_ = self * invDenCached_;
        rodGainCached_ = rodGain;
        return keptStep(drive);
    }

    double temperature() const noexcept { return theta_; }
    /// The footprint the last step's heat spread over (m^2).
    double footprintArea() const noexcept { return areaCached_; }
    const ThermalParams& params() const noexcept { return params_; }

private:
    /// The two sides' histories without their theta_prev terms, weighted by area and effusivity.
    double conductionDrive() const noexcept
    {
        return stringEffusion_ * stringSide_.historyDrive() + rodEffusion_ * rodSide_.historyDrive();
    }

    /// The implicit update with the coefficients kept from a still step.
    double keptStep(double drive) noexcept
    {
        theta_ = std::max(0.0, thetaGainCached_ * theta_ + drive * invDenCached_);
        return commit();
    }

    double commit() noexcept
    {
        stringSide_.advance(theta_);
        rodSide_.advance(theta_);
        return theta_;
    }

    ThermalParams params_;
    double h_ = 1.0 / 48000.0, rate_ = 48000.0, theta_ = 0.0, areaCached_ = -1.0;
    // The update's coefficients kept from the last still sample (see step).
    double invDenCached_ = 0.0, thetaGainCached_ = 0.0, rodGainCached_ = 0.0;
    bool stillCached_ = false;
    double renewalPerSpeed_ = 0.0, storage_ = 0.0, advectionPerSpeed_ = 0.0, stringEffusion_ = 0.0, rodEffusion_ = 0.0;
    ConductionBank<T> stringSide_, rodSide_;
};

} // namespace rosin::dsp
