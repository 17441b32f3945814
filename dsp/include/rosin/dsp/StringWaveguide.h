// Digital-waveguide string seen from the bow (PHYSICS.md 1.1-1.5).
//
// The bow splits the string into a bridge side (length beta L) and a finger side. Each side is
// a round trip of outgoing velocity waves through a delay and a reflection filter. The bridge
// side is split in two halves so the bridge force is taken from the wave as it arrives there,
// with all of that side's loss in the reflected path. Torsional waves run in their own pair of
// lines with their own speed, impedance and damping; only transverse waves reach the bridge.
//
// Per sample: vh = beginSample(); solve the junction for f; endSample(f).
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>

#include "Config.h"
#include "DelayLine.h"
#include "ReflectionFilter.h"
#include "Simd.h"
#include "StringParams.h"

namespace rosin::dsp {

struct WaveguideOptions {
    bool losses = true;       ///< frequency-dependent loss in both reflections
    bool torsion = true;      ///< torsional waves (lower the load-line slope)
    bool dispersion = false;  ///< bending-stiffness allpasses in the finger-side reflection
    int dispersionSections = 2;
    /// MSW83 Gaussian-pulse reflections instead of one-pole loss + Lagrange delay (a second,
    /// independent design: data simulated with it tests that analysis does not depend on ours).
    bool gaussianReflections = false;
    /// Plain strings (one-pole losses, no dispersion, no touched harmonic) run their four lossy
    /// reflections as the lanes of one SIMD pack; false runs them one at a time. Same equations,
    /// summed in another order: kept to check the packed path against.
    bool packedReflections = true;
    /// Lowest fundamental the delay lines must hold, as a fraction of the open string's: a
    /// playable voice bends below the open pitch; research runs keep 1.
    double lowestPitchRatio = 1.0;
    /// Corner of the low shelf that gives each lossy reflection back its DC, as a fraction of
    /// f0, so that a held deflection holds (ReflectionFilter.h; 0.5 is the measured choice).
    /// 0 = off, the reflections lose at DC about what they lose at f0 and a sticking bow's ramp
    /// creeps soft. Off by default until the instrument's tuning and the diagnosis are
    /// calibrated with it (docs/model.md): with it on, the violin's open E sounds 5.9 cents flat,
    /// a stopped martele bow holds the string bent, and two strings need over 20 periods to
    /// reach Helmholtz at the default velocity.
    double dcRestoreCorner = 0.0;
    /// The same for the two torsional reflections alone (0 = as dcRestoreCorner). Their loss
    /// (Q_t 15-60) is the heaviest, so a held twist crept most: a rolling string under a sticking
    /// bow went 3-5 % softer than its series stiffness in 0.2 s beyond the transverse creep. Off
    /// by default; the diagnosis measured it and kept it off (docs/model.md).
    double torsionDcRestoreCorner = 0.0;
};

template <typename T>
class StringWaveguide {
public:
    /// [setup thread] Allocates the delay lines for this string at this rate.
    void prepare(double sampleRate, const StringParams& params, const WaveguideOptions& options = {})
    {
        fs_ = sampleRate;
        params_ = params;
        options_ = options;
        z0_ = params.impedance();
        zt_ = params.torsionImpedance();
        halfAdmittance_ = static_cast<T>(0.5 / z0_); // a multiply per sample instead of a divide
        halfTorsionAdmittance_ = static_cast<T>(0.5 / zt_);
        f0_ = params.fundamental();
        w0_ = 2.0 * std::numbers::pi * f0_ / fs_;
        fLossProbe_ = std::min(5.0 * f0_, 0.4 * fs_);
        wLossProbe_ = 2.0 * std::numbers::pi * fLossProbe_ / fs_;
        const double ratio = std::clamp(options.lowestPitchRatio, 0.05, 1.0);
        const double period = fs_ / (f0_ * ratio);
        lowestFundamental_ = f0_ * ratio;
        lines_.prepare(kLineCount, period / std::min(1.0, params.torsionSpeedRatio) + 16.0);
        harmonic_ = 0;
        designDispersion();
        updatePlain();
        beta_ = -1.0;
        setBeta(0.0899);
        reset();
    }

    void reset() noexcept
    {
        lines_.reset();
        lossState_ = Pack4{};
        topState_ = Pack4{};
        dispersion_.reset();
        u1In_ = u2In_ = u1tIn_ = u2tIn_ = T(0);
        bridgeForce_ = T(0);
    }

    /// [audio thread] Stops the string (a finger) so it sounds at f (Hz): the vibrating length
    /// becomes c / 2f, the bow stays at the same fraction beta of it. Tension, mass and
    /// inharmonicity are kept (B really grows as 1/L^2; the dispersion fit is not redone here).
    /// Clamped to the lowest fundamental prepare() made room for.
    void setFundamental(double f) noexcept
    {
        if (!std::isfinite(f) || f <= 0.0) return;
        f = std::clamp(f, lowestFundamental_, 0.45 * fs_);
        if (f == f0_) return;
        f0_ = f;
        params_.length = params_.waveSpeed() / (2.0 * f);
        w0_ = 2.0 * std::numbers::pi * f0_ / fs_;
        fLossProbe_ = std::min(5.0 * f0_, 0.4 * fs_);
        wLossProbe_ = 2.0 * std::numbers::pi * fLossProbe_ / fs_;
        const double beta = beta_;
        beta_ = -1.0;
        setBeta(beta);
    }

    /// [audio thread] A light finger touching the string at the node of harmonic n (n >= 2; 0 =
    /// no touch): a point damper of resistance `damping` x Z0 at L/n from the finger end. Modes
    /// with a node there pass; the others are damped, so the string speaks its n-th harmonic.
    void setHarmonic(int n, double damping = 1.0) noexcept
    {
        n = n >= 2 && n <= 16 ? n : 0;
        const double r = std::clamp(std::isfinite(damping) ? damping : 1.0, 0.01, 100.0);
        if (n == harmonic_ && r == nodeDamping_) return;
        if (harmonic_ == 0 && n > 0) { // the node lines sat unwritten: start them silent
            lines_.clear(kNodeBackLine);
            lines_.clear(kNodeRoundLine);
        }
        harmonic_ = n;
        nodeDamping_ = r;
        designNode();
        updatePlain();
    }
    int harmonic() const noexcept { return harmonic_; }

    /// [audio thread] Moves the bow point. Cheap closed-form redesign; skipped when unchanged.
    void setBeta(double beta) noexcept
    {
        if (!std::isfinite(beta)) return;
        beta = std::clamp(beta, config::minBeta, config::maxBeta);
        if (beta == beta_) return;
        beta_ = beta;
        const double c = params_.waveSpeed();
        const double L = params_.length;
        const double tau1 = 2.0 * beta * L / c, tau2 = 2.0 * (1.0 - beta) * L / c;
        designLoss(lossBridge_, tau1, false);
        designLoss(lossFinger_, tau2, false);
        delayBridgeOut_ = 0.5 * tau1 * fs_;
        delayBridgeBack_ = 0.5 * tau1 * fs_ - lossBridge_.phaseDelay(w0_);
        delayFinger_ = tau2 * fs_ - lossFinger_.phaseDelay(w0_) - dispersion_.phaseDelay(w0_);
        const double ct = c * params_.torsionSpeedRatio;
        const double tau1t = 2.0 * beta * L / ct, tau2t = 2.0 * (1.0 - beta) * L / ct;
        designLoss(lossTorsionBridge_, tau1t, true);
        designLoss(lossTorsionFinger_, tau2t, true);
        delayTorsionBridge_ = tau1t * fs_ - lossTorsionBridge_.phaseDelay(w0_);
        delayTorsionFinger_ = tau2t * fs_ - lossTorsionFinger_.phaseDelay(w0_);
        tapBridgeOut_ = lines_.tap(kBridgeOutLine, delayBridgeOut_);
        tapBridgeBack_ = lines_.tap(kBridgeBackLine, delayBridgeBack_);
        tapFinger_ = lines_.tap(kFingerLine, delayFinger_);
        tapTorsionBridge_ = lines_.tap(kTorsionBridgeLine, delayTorsionBridge_);
        tapTorsionFinger_ = lines_.tap(kTorsionFingerLine, delayTorsionFinger_);
        // One way, bow to finger, read after this sample's write: one sample further back.
        tapFarEnd_ = lines_.tap(kFingerLine, 0.5 * tau2 * fs_ + 1.0);
        const OnePoleLoss<T>* loss[4] = {&lossBridge_, &lossFinger_, &lossTorsionBridge_, &lossTorsionFinger_};
        for (int k = 0; k < 4; ++k) {
            lossB0_[k] = loss[k]->b0;
            lossA1_[k] = loss[k]->a1;
            top0_[k] = loss[k]->top0;
            top1_[k] = loss[k]->top1;
            shelfPole_[k] = loss[k]->shelfPole;
        }
        weightsBridgeOut_ = stencilWeights(tapBridgeOut_);
        weightsFinger_ = stencilWeights(tapFinger_);
        weightsTorsionBridge_ = stencilWeights(tapTorsionBridge_);
        weightsTorsionFinger_ = stencilWeights(tapTorsionFinger_);
        designNode();
        if (options_.gaussianReflections) {
            auto design = [&](GaussianReflection<T>& g, double delay, double tau, bool torsional) {
                const double etaLow = torsional ? 1.0 / params_.qTorsion
                                                : lossFactor(f0_, f0_, params_.qLow, params_.qHigh, params_.qHighFrequency);
                const double etaHigh = torsional ? 1.0 / params_.qTorsion
                                                 : lossFactor(fLossProbe_, f0_, params_.qLow, params_.qHigh, params_.qHighFrequency);
                const double m1 = options_.losses ? segmentMagnitude(f0_, tau, etaLow) : 1.0;
                const double m2 = options_.losses ? segmentMagnitude(fLossProbe_, tau, etaHigh) : 1.0;
                g.design(delay, m1, w0_, m2, wLossProbe_);
            };
            design(gaussBridge_, 0.5 * tau1 * fs_, tau1, false);
            design(gaussFinger_, tau2 * fs_, tau2, false);
            design(gaussTorsionBridge_, tau1t * fs_, tau1t, true);
            design(gaussTorsionFinger_, tau2t * fs_, tau2t, true);
        }
    }

    /// [audio thread] Reads the incoming waves of this sample; returns v_h (PHYSICS.md 1.3).
    T beginSample() noexcept
    {
        if (plain_) return options_.torsion ? beginSamplePacked<true>() : beginSamplePacked<false>();
        const T arriving = lines_.read(tapBridgeOut_);
        const T reflected = -loss(kBridge, arriving);
        bridgeForce_ = static_cast<T>(z0_) * (arriving - reflected);
        if (options_.gaussianReflections) return beginSampleGaussian(arriving);
        u1In_ = lines_.read(tapBridgeBack_);
        lines_.write(kBridgeBackLine, reflected);
        if (harmonic_ > 0) {
            // Finger side split at the touched node: bow <-> node (A), node <-> finger end (B).
            const T aIn = lines_.read(tapNodeA_);
            const T bIn = -loss(kFinger, dispersion_.process(lines_.read(tapNodeRound_)));
            const T v = nodeGain_ * (aIn + bIn); // 2Z (a + b) / (2Z + R)
            u2In_ = lines_.read(tapNodeBack_);
            lines_.write(kNodeBackLine, v - aIn);
            lines_.write(kNodeRoundLine, v - bIn);
        } else {
            u2In_ = -loss(kFinger, dispersion_.process(lines_.read(tapFinger_)));
        }
        if (options_.torsion) {
            u1tIn_ = -loss(kTorsionBridge, lines_.read(tapTorsionBridge_));
            u2tIn_ = -loss(kTorsionFinger, lines_.read(tapTorsionFinger_));
        }
        return u1In_ + u2In_ + u1tIn_ + u2tIn_;
    }

    /// [audio thread] Launches the outgoing waves for friction force f (bow on string).
    void endSample(T f) noexcept { options_.torsion ? endSampleWith<true>(f) : endSampleWith<false>(f); }

    /// endSample() with the torsion switch known at compile time (a voice's inner loop).
    template <bool Torsion>
    void endSampleWith(T f) noexcept
    {
        const T dv = f * halfAdmittance_;
        lines_.write(kBridgeOutLine, u2In_ + dv);
        lines_.write(kFingerLine, u1In_ + dv);
        if (Torsion) {
            const T dvt = f * halfTorsionAdmittance_;
            lines_.write(kTorsionBridgeLine, u2tIn_ + dvt);
            lines_.write(kTorsionFingerLine, u1tIn_ + dvt);
        }
        lines_.advance(); // every line written this sample moves on together
    }

    /// Force of the string on the bridge for the current sample (valid after beginSample).
    T bridgeForce() const noexcept { return bridgeForce_; }
    /// Force on the far (finger or nut) end for the sample just completed (call after
    /// endSample), for two-ended measurements (PHYSICS.md 7.2): twice Z0 times the wave
    /// arriving there, signed like the bridge force. Read on demand: a voice never needs it.
    T farEndForce() const noexcept { return static_cast<T>(2.0 * z0_) * lines_.read(tapFarEnd_); }

    /// Transverse part of the history velocity (what the bow would see with torsion ignored).
    T transverseHistory() const noexcept { return u1In_ + u2In_; }

    /// Impedance the bow sees: 1/Zeff = 1/Z0 + 1/Zt (torsion only lowers the load-line slope).
    double effectiveImpedance() const noexcept
    {
        return options_.torsion ? 1.0 / (1.0 / z0_ + 1.0 / zt_) : z0_;
    }
    double impedance() const noexcept { return z0_; }
    double fundamental() const noexcept { return f0_; }
    double sampleRate() const noexcept { return fs_; }
    double beta() const noexcept { return beta_; }
    const StringParams& params() const noexcept { return params_; }
    const WaveguideOptions& options() const noexcept { return options_; }

    /// Total wave energy held in the lines (J): each stored sample of a travelling wave u on a
    /// line of impedance Z carries Z u^2 / fs. Exact for integer delays and lossless ends.
    double waveEnergy() const noexcept
    {
        const double h = 1.0 / fs_;
        auto count = [](double d) { return static_cast<std::size_t>(std::ceil(d - 1e-9)); };
        double e = z0_ * (lines_.sumOfSquares(kBridgeOutLine, count(delayBridgeOut_))
                          + lines_.sumOfSquares(kBridgeBackLine, count(delayBridgeBack_))
                          + lines_.sumOfSquares(kFingerLine, count(delayFinger_)));
        if (options_.torsion)
            e += zt_ * (lines_.sumOfSquares(kTorsionBridgeLine, count(delayTorsionBridge_))
                        + lines_.sumOfSquares(kTorsionFingerLine, count(delayTorsionFinger_)));
        return e * h;
    }

    /// Delays (samples) currently used, for tests and diagnostics.
    double bridgeRoundTripDelay() const noexcept { return delayBridgeOut_ + delayBridgeBack_; }
    double fingerRoundTripDelay() const noexcept { return delayFinger_; }

    /// True when beginSample() takes the packed path (a plain string): a voice's inner loop
    /// then calls beginSamplePacked<torsion>() itself and skips the per-sample dispatch.
    bool packed() const noexcept { return plain_; }

    /// The plain string (one-pole losses, no dispersion, no touched harmonic; torsion on or off),
    /// which is what a playing voice runs: the four lossy reflections are four lanes of one
    /// pack, read (four 4-point stencils), summed and filtered together. Same equations as the
    /// general path, summed in a different order. Only for a packed() string: beginSample()
    /// dispatches here, a voice's inner loop calls it directly with torsion fixed.
    template <bool Torsion>
    T beginSamplePacked() noexcept
    {
        const T* origin = lines_.origin();
        const Pack4 reads = simd::sumEach<T>(loadStencil(origin, tapBridgeOut_) * weightsBridgeOut_,
                                             loadStencil(origin, tapFinger_) * weightsFinger_,
                                             loadStencil(origin, tapTorsionBridge_) * weightsTorsionBridge_,
                                             loadStencil(origin, tapTorsionFinger_) * weightsTorsionFinger_);
        const Pack4 lowPassed = lossB0_ * reads - lossA1_ * lossState_;
        const Pack4 top = top0_ * lowPassed + top1_ * lossState_ + shelfPole_ * topState_;
        const Pack4 filtered = lowPassed + top;
        lossState_ = lowPassed;
        topState_ = top;
        const T arriving = reads[kBridge];
        bridgeForce_ = static_cast<T>(z0_) * (arriving + filtered[kBridge]);
        u1In_ = lines_.read(tapBridgeBack_);
        lines_.write(kBridgeBackLine, -filtered[kBridge]);
        u2In_ = -filtered[kFinger];
        if (Torsion) { // the torsional lines are silent otherwise; their lanes are ignored
            u1tIn_ = -filtered[kTorsionBridge];
            u2tIn_ = -filtered[kTorsionFinger];
        }
        return u1In_ + u2In_ + u1tIn_ + u2tIn_;
    }

private:
    typedef simd::Pack4<T> Pack4;
    /// Lanes of the four lossy reflections: the waves arriving at the bridge and at the finger,
    /// transverse and torsional.
    static constexpr int kBridge = 0, kFinger = 1, kTorsionBridge = 2, kTorsionFinger = 3;
    /// The delay lines, all one size and advanced together at the end of each sample: the two
    /// halves of the bridge side, the finger side, the torsional sides, and the two pieces of
    /// the finger side a touched harmonic splits off.
    enum Line : int {
        kBridgeOutLine, kBridgeBackLine, kFingerLine, kTorsionBridgeLine, kTorsionFingerLine, kNodeBackLine, kNodeRoundLine,
        kLineCount
    };
    using Tap = typename DelayLines<T>::Tap;

    /// Loss of one reflection, low-pass then DC shelf (its lane of the packed filter state).
    T loss(int lane, T x) noexcept
    {
        const T y = lossB0_[lane] * x - lossA1_[lane] * lossState_[lane];
        const T top = top0_[lane] * y + top1_[lane] * lossState_[lane] + shelfPole_[lane] * topState_[lane];
        lossState_[lane] = y;
        topState_[lane] = top;
        return y + top;
    }

    static Pack4 stencilWeights(const Tap& t) noexcept { return Pack4{t.h3, t.h2, t.h1, t.h0}; }

    /// A tap's four samples. Short delays read narrow (see simd::load4Narrow): a line a few
    /// samples long reads what the last samples wrote. The branch follows the bow position,
    /// so it is predicted.
    static Pack4 loadStencil(const T* origin, const Tap& t) noexcept
    {
        const T* p = origin + t.offset;
        return t.base < kRecentSamples ? simd::load4Narrow(p) : simd::load4(p);
    }
    /// Stencils whose newest sample is younger than this read narrow. Measured: the torsional
    /// bridge side (newest sample 1-3 back) paid the wait; the bridge side at 4 did not.
    static constexpr std::size_t kRecentSamples = 4;

    void updatePlain() noexcept
    {
        plain_ = options_.packedReflections && !options_.gaussianReflections && dispersion_.sections == 0 && harmonic_ == 0;
    }

    /// Gaussian-pulse variant: the reflection at the bridge is pure (sign only) and the whole
    /// bridge-side smear and loss sits in the way back; the bridge sees the arriving wave.
    T beginSampleGaussian(T arriving) noexcept
    {
        bridgeForce_ = static_cast<T>(2.0 * z0_) * arriving;
        u1In_ = -lines_.readKernel(kBridgeBackLine, gaussBridge_.first, gaussBridge_.weights, gaussBridge_.taps);
        lines_.write(kBridgeBackLine, arriving);
        u2In_ = -lines_.readKernel(kFingerLine, gaussFinger_.first, gaussFinger_.weights, gaussFinger_.taps);
        if (options_.torsion) {
            u1tIn_ = -lines_.readKernel(kTorsionBridgeLine, gaussTorsionBridge_.first, gaussTorsionBridge_.weights, gaussTorsionBridge_.taps);
            u2tIn_ = -lines_.readKernel(kTorsionFingerLine, gaussTorsionFinger_.first, gaussTorsionFinger_.weights, gaussTorsionFinger_.taps);
        }
        return u1In_ + u2In_ + u1tIn_ + u2tIn_;
    }

    void designLoss(OnePoleLoss<T>& filter, double tau, bool torsional) noexcept
    {
        if (!options_.losses) { filter.setIdentity(); return; }
        const double etaLow = torsional ? 1.0 / params_.qTorsion
                                        : lossFactor(f0_, f0_, params_.qLow, params_.qHigh, params_.qHighFrequency);
        const double etaHigh = torsional ? 1.0 / params_.qTorsion
                                         : lossFactor(fLossProbe_, f0_, params_.qLow, params_.qHigh, params_.qHighFrequency);
        const double corner = torsional && options_.torsionDcRestoreCorner > 0.0 ? options_.torsionDcRestoreCorner : options_.dcRestoreCorner;
        const double wRestore = 2.0 * std::numbers::pi * std::max(corner, 0.0) * f0_ / fs_;
        filter.design(segmentMagnitude(f0_, tau, etaLow), w0_, segmentMagnitude(fLossProbe_, tau, etaHigh), wLossProbe_, wRestore);
    }

    void designNode() noexcept
    {
        if (harmonic_ <= 0) return;
        const double c = params_.waveSpeed(), L = params_.length;
        const double fromBow = std::max(L * (1.0 - 1.0 / harmonic_) - beta_ * L, 0.5 * c / fs_); // node beyond the bow
        const double beyond = L / harmonic_;
        const double delayA = fromBow / c * fs_;
        const double delayB = 2.0 * beyond / c * fs_ - lossFinger_.phaseDelay(w0_) - dispersion_.phaseDelay(w0_);
        tapNodeA_ = lines_.tap(kFingerLine, delayA);
        tapNodeBack_ = lines_.tap(kNodeBackLine, delayA);
        tapNodeRound_ = lines_.tap(kNodeRoundLine, std::max(delayB, config::minSegmentDelay));
        nodeGain_ = static_cast<T>(2.0 / (2.0 + nodeDamping_));
    }

    /// Fits the allpass coefficient so the partials follow a stiff string, f_n / f_1 =
    /// n sqrt((1 + B n^2) / (1 + B)), with the fundamental kept at f0.
    void designDispersion()
    {
        dispersion_.sections = 0;
        dispersion_.a = T(0);
        const double B = params_.inharmonicity;
        if (!options_.dispersion || B <= 0.0) return;
        const int K = std::clamp(options_.dispersionSections, 1, 8);
        const double period = fs_ / f0_;
        // First-order sections cannot follow the law up to high partials; fit the first 16 (below
        // 5 kHz), weighted towards the low ones whose tuning the ear follows most closely.
        const int nMax = std::clamp(static_cast<int>(std::min(0.25 * fs_, 5000.0) / f0_), 2, 16);
        double bestA = 0.0, bestErr = 1e300;
        for (int step = 1; step < 400; ++step) {
            const double a = -0.995 * step / 400.0;
            const double bulk = period - K * DispersionChain<T>::sectionPhaseDelay(a, w0_);
            if (bulk < 2.0) break;
            double err = 0.0;
            for (int n = 2; n <= nMax; ++n) {
                const double target = n * f0_ * std::sqrt((1.0 + B * n * n) / (1.0 + B));
                // loop delay at the target frequency -> frequency this partial actually takes
                const double w = 2.0 * std::numbers::pi * target / fs_;
                const double loop = bulk + K * DispersionChain<T>::sectionPhaseDelay(a, w);
                const double got = n * fs_ / loop;
                err += std::pow(std::log(got / target), 2.0) / n;
            }
            if (err < bestErr) { bestErr = err; bestA = a; }
        }
        dispersion_.sections = K;
        dispersion_.a = static_cast<T>(bestA);
    }

    double fs_ = 48000.0, f0_ = 146.83, w0_ = 0.0, fLossProbe_ = 0.0, wLossProbe_ = 0.0;
    double z0_ = 0.5, zt_ = 1.0, beta_ = -1.0, lowestFundamental_ = 20.0;
    StringParams params_;
    WaveguideOptions options_;
    DelayLines<T> lines_;
    int harmonic_ = 0;
    double nodeDamping_ = 1.0;
    T nodeGain_ = T(1), halfAdmittance_ = T(1), halfTorsionAdmittance_ = T(1);
    bool plain_ = true;
    Pack4 lossB0_{}, lossA1_{}, lossState_{};
    Pack4 top0_{}, top1_{}, shelfPole_{}, topState_{};
    Pack4 weightsBridgeOut_{}, weightsFinger_{}, weightsTorsionBridge_{}, weightsTorsionFinger_{};
    OnePoleLoss<T> lossBridge_, lossFinger_, lossTorsionBridge_, lossTorsionFinger_;
    DispersionChain<T> dispersion_;
    GaussianReflection<T> gaussBridge_, gaussFinger_, gaussTorsionBridge_, gaussTorsionFinger_;
    double delayBridgeOut_ = 1, delayBridgeBack_ = 1, delayFinger_ = 1, delayTorsionBridge_ = 1, delayTorsionFinger_ = 1;
    Tap tapBridgeOut_, tapBridgeBack_, tapFinger_, tapTorsionBridge_, tapTorsionFinger_, tapFarEnd_;
    Tap tapNodeA_, tapNodeBack_, tapNodeRound_;
    T u1In_ = T(0), u2In_ = T(0), u1tIn_ = T(0), u2tIn_ = T(0), bridgeForce_ = T(0);
};

} // namespace rosin::dsp
