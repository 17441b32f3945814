// The bow-string contact: intersects the load line v = vh + f/(2 Zeff) with the friction law
// of the chosen model, sample by sample, without allocation (PHYSICS.md 2.2-2.3, 3.7, 4.4).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "Config.h"
#include "FrictionLaws.h"
#include "TemperatureLaw.h"
#include "ThermalContact.h"

namespace rosin::dsp {

enum class FrictionModel {
    FrictionCurve, ///< mu depends on sliding speed only, with the stick/slip jump rule
    Thermal,       ///< mu depends on contact temperature only (Woodhouse 2003)
    Enhanced       ///< mu = y(theta) h(|dv|), temperature and speed (Woodhouse & Galluzzo 2025)
};

struct FrictionParams {
    FrictionModel model = FrictionModel::Thermal;
    SteadyFit fit = SteadyFit::SmithWoodhouse;
    std::optional<SteadyCurve> steadyCurve; ///< a measured curve; overrides `fit` when set
    SteadyCurve effectiveSteadyCurve() const noexcept { return steadyCurve ? *steadyCurve : SteadyCurve::of(fit); }
    SpeedFunction speedFunction = SpeedFunction::Rod;
    std::optional<SpeedLaw> speedLaw; ///< overrides the preset speedFunction when set
    SpeedLaw effectiveSpeedLaw() const noexcept { return speedLaw ? *speedLaw : SpeedLaw::of(speedFunction); }
    ContactLaw contactLaw = ContactLaw::Amontons;
    double contactExponent = 2.0 / 3.0;
    ThermalParams thermal;
    /// Build the temperature laws of both thermal models in prepare(), so setModel() can switch
    /// between all three on the audio thread (a playable instrument); off for sweeps, which
    /// fix the model and would pay for a table they never read.
    bool switchable = false;
};

enum class ContactState { Stick, SlipForward, SlipBackward };

template <typename T>
struct JunctionResult {
    T force;        ///< friction force on the string f (N)
    T velocity;     ///< string surface velocity at the bow v (m/s)
    T temperature;  ///< contact temperature rise theta (K)
    bool stick;
};

template <typename T>
class BowJunction {
public:
    /// [setup thread] Builds the temperature tables for the chosen model.
    void prepare(double sampleRate, const FrictionParams& params)
    {
        params_ = params;
        area_.configure(params.contactLaw, params.contactExponent, params.thermal);
        speed_ = params.effectiveSpeedLaw();
        steady_ = params.effectiveSteadyCurve();
        const bool both = params.switchable;
        if (both || params.model == FrictionModel::Thermal) thermalLaw_.build(params.effectiveSteadyCurve(), std::nullopt, params.thermal);
        if (both || params.model == FrictionModel::Enhanced)
            enhancedLaw_.build(params.effectiveSteadyCurve(), std::optional<SpeedLaw>(speed_), params.thermal);
        applyShiftAndScale();
        thermal_.prepare(sampleRate, params.thermal);
        muAtRest_ = speedLaw(0.0).mu;
        forceCached_ = -1.0; // the load for a force depends on the contact law just configured
        zEffCached_ = -1.0;
        reset();
    }

    /// [audio thread] Ambient temperature (C) without rebuilding the temperature law.
    void setAmbient(double celsius) noexcept
    {
        if (!std::isfinite(celsius) || celsius == params_.thermal.ambientCelsius) return;
        params_.thermal.ambientCelsius = celsius;
        applyShiftAndScale();
    }

    /// [audio thread] A softer or harder rosin: its glass transition (C) shifts the law.
    void setGlassTransition(double celsius) noexcept
    {
        if (!std::isfinite(celsius) || celsius == params_.thermal.glassTransitionCelsius) return;
        params_.thermal.glassTransitionCelsius = celsius;
        applyShiftAndScale();
    }

    /// [audio thread] Footprint ratio r_A (bow / steady test): scales the temperature law and the heated area.
    void setFootprintRatio(double ratio) noexcept
    {
        if (!(ratio > 0.0) || !std::isfinite(ratio) || ratio == params_.thermal.footprintRatio) return;
        params_.thermal.footprintRatio = ratio;
        area_.configure(params_.contactLaw, params_.contactExponent, params_.thermal);
        applyShiftAndScale();
    }

    /// [audio thread] Amontons or power-law contact; the contact temperature carries on.
    void setContactLaw(ContactLaw law, double exponent) noexcept
    {
        if (law == params_.contactLaw && exponent == params_.contactExponent) return;
        if (!(exponent > 0.0 && exponent <= 1.0)) return;
        params_.contactLaw = law;
        params_.contactExponent = exponent;
        area_.configure(law, exponent, params_.thermal);
        forceCached_ = -1.0;
    }

    /// [audio thread] Switch the friction model. The thermal models need their table from
    /// prepare() (FrictionParams::switchable); a request for a missing one is ignored and
    /// reported false. Heat state carries over, so a switch mid-note does not restart the note.
    bool setModel(FrictionModel model) noexcept
    {
        if (model == params_.model) return true;
        if (model == FrictionModel::Thermal && !thermalLaw_.built()) return false;
        if (model == FrictionModel::Enhanced && !enhancedLaw_.built()) return false;
        params_.model = model;
        muAtRest_ = speedLaw(0.0).mu; // the jump rule's static limit follows the model's speed law
        applyShiftAndScale();
        if (model == FrictionModel::Thermal && state_ != ContactState::Stick) xPrev_ = 0.0;
        return true;
    }

    /// [audio thread] Relative noise on the friction force while slipping (0 = off), from a
    /// seeded generator: the "different seed" perturbation of PHYSICS.md 6.7.
    void setSlipNoise(double relative, std::uint64_t seed) noexcept
    {
        noiseLevel_ = relative;
        noiseState_ = seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
        if (noiseState_ == 0) noiseState_ = 1;
    }

    void reset() noexcept
    {
        thermal_.reset();
        state_ = ContactState::Stick;
        xPrev_ = 0.0;
        heatPerLoadPrev_ = 0.0;
        slidePrev_ = 0.0;
        heatSlopePerLoadPrev_ = 0.0;
        forgetKnownLimit();
    }

    /// [audio thread] Solve this sample. vh: history velocity; vb: bow speed; fb: bow force;
    /// zEff: impedance seen by the bow. Non-finite inputs are treated as zero.
    JunctionResult<T> solve(T vhIn, T vbIn, T fbIn, double zEff) noexcept
    {
        const Speeds s = takeInputs(vhIn, vbIn, fbIn, zEff);
        // The thermal model is the instrument's default and the lightest: its own small path,
        // which the compiler can inline into the voice's loop; the others share one out of line.
        if (params_.model == FrictionModel::Thermal) return solveThermal(s.history, s.bow);
        return solveSpeedDependent(s.history, s.bow);
    }

    /// Bow force and speed of a block made safe as solve() makes them (non-finite -> 0, then
    /// clamped), in one pass the compiler vectorises, for solveThermalCleanControls().
    static void cleanControls(const T* force, const T* speed, T* forceOut, T* speedOut, int n) noexcept
    {
        for (int i = 0; i < n; ++i) {
            forceOut[i] = cleanForce(force[i]);
            speedOut[i] = cleanSpeed(speed[i]);
        }
    }

    /// solve() for a junction known to run the thermal model (a voice's inner loop checks the
    /// model once per block instead of every sample), with controls already passed through
    /// cleanControls().
    [[gnu::always_inline]] JunctionResult<T> solveThermalCleanControls(T vhIn, T vb, T fb, double zEff) noexcept
    {
        updateLoadLine(static_cast<double>(fb), zEff);
        return solveThermal(finiteOr(vhIn), static_cast<double>(vb));
    }

    /// Largest friction force the contact can hold without slipping at temperature theta and
    /// bow force fb (the stick limit), for tests and diagnostics.
    double stickLimit(double fb, double theta) const noexcept
    {
        const double load = area_.effectiveLoad(fb);
        switch (params_.model) {
        case FrictionModel::FrictionCurve: return load * steady_(0.0).mu;
        case FrictionModel::Thermal: return load * law()(theta);
        case FrictionModel::Enhanced: return load * law()(theta) * speed_(0.0).mu;
        }
        return 0.0;
    }

    /// mu(x) at zero temperature scale; the speed law used with the jump rule.
    MuSlope speedLaw(double x) const noexcept
    {
        return params_.model == FrictionModel::Enhanced ? speed_(x) : steady_(x);
    }

    ContactState state() const noexcept { return state_; }
    double temperature() const noexcept { return thermal_.temperature(); }
    const TemperatureLaw& temperatureLaw() const noexcept { return law(); }
    const ContactArea& contactArea() const noexcept { return area_; }
    const FrictionParams& params() const noexcept { return params_; }
    ThermalContact<T>& thermal() noexcept { return thermal_; }

private:
    /// The table the current model reads (an index, not a pointer, so copies stay valid).
    const TemperatureLaw& law() const noexcept
    {
        return params_.model == FrictionModel::Enhanced ? enhancedLaw_ : thermalLaw_;
    }


    void applyShiftAndScale() noexcept
    {
        for (auto* law : {&thermalLaw_, &enhancedLaw_}) {
            law->setShift(params_.thermal.temperatureShift());
            law->setScale(params_.thermal.footprintRatio);
        }
        forgetKnownLimit();
    }

    /// The thermal path's remembered lookup (see solveThermal) belongs to the law as it was.
    void forgetKnownLimit() noexcept
    {
        knownTheta_ = -1.0;
        knownMuFloor_ = -1.0;
        thermalLawFalls_ = thermalLaw_.nonIncreasing();
    }

    /// Uniform in [-1, 1) from xorshift64*: cheap, seeded, the same on every platform.
    double nextNoise() noexcept
    {
        noiseState_ ^= noiseState_ >> 12;
        noiseState_ ^= noiseState_ << 25;
        noiseState_ ^= noiseState_ >> 27;
        const std::uint64_t r = noiseState_ * 0x2545F4914F6CDD1Dull;
        return static_cast<double>(r >> 11) * (2.0 / 9007199254740992.0) - 1.0;
    }

    static double finiteOr(T x) noexcept { return std::isfinite(static_cast<double>(x)) ? static_cast<double>(x) : 0.0; }

    /// Non-finite -> 0, then clamped. Done in T: the limits are exact in float, so this equals
    /// clamping the double, and a block of it vectorises.
    static T cleanControl(T x, T lo, T hi) noexcept
    {
        return std::abs(x) <= std::numeric_limits<T>::max() ? std::clamp(x, lo, hi) : T(0);
    }
    static T cleanForce(T x) noexcept { return cleanControl(x, T(0), static_cast<T>(config::maxBowForce)); }
    static T cleanSpeed(T x) noexcept
    {
        return cleanControl(x, static_cast<T>(-config::maxBowSpeed), static_cast<T>(config::maxBowSpeed));
    }

    /// Friction-curve and enhanced models: mu(x) = scale * law(x) falls with sliding speed, so
    /// the load line may cut it three times; the McIntyre-Woodhouse hysteresis rule picks one.
    double solveWithJumpRule(double D, double fStick, double load, double scale, double twoZ) noexcept
    {
        const double muStatic = scale * muAtRest_;
        const bool canStick = std::abs(fStick) <= muStatic * load;
        const double side = D >= 0.0 ? 1.0 : -1.0;
        if (state_ == ContactState::Stick) {
            if (canStick) return fStick;
            return slipOn(side, D, load, scale, twoZ, 0.0);
        }
        const double sidePrev = state_ == ContactState::SlipForward ? 1.0 : -1.0;
        if (auto x = outerRoot(sidePrev * D, load, scale, twoZ, xPrev_)) return commitSlip(sidePrev, *x, load, scale);
        if (canStick) { state_ = ContactState::Stick; xPrev_ = 0.0; return fStick; }
        return slipOn(-sidePrev, D, load, scale, twoZ, 0.0);
    }

    double slipOn(double side, double D, double load, double scale, double twoZ, double guess) noexcept
    {
        if (auto x = outerRoot(side * D, load, scale, twoZ, guess)) return commitSlip(side, *x, load, scale);
        // Only reachable with zero load (nothing holds the string): the string runs free.
        state_ = side > 0 ? ContactState::SlipForward : ContactState::SlipBackward;
        xPrev_ = std::abs(D);
        return 0.0;
    }

    double commitSlip(double side, double x, double load, double scale) noexcept
    {
        state_ = side > 0 ? ContactState::SlipForward : ContactState::SlipBackward;
        xPrev_ = x;
        return side * load * scale * speedLaw(x).mu;
    }

    /// Largest root of g(x) = 2Z(d - x) - load*scale*mu(x) on (0, d]. mu is convex and falling,
    /// so g is concave: Newton from the right of the largest root walks down to it without
    /// overshoot, and meeting g' >= 0 first means there is no root.
    std::optional<double> outerRoot(double d, double load, double scale, double twoZ, double guess) const noexcept
    {
        if (!(d > 0.0)) return std::nullopt;
        const double k = load * scale;
        if (k <= 0.0) return std::nullopt;
        auto eval = [&](double x, double& g, double& gp) {
            const MuSlope m = speedLaw(x);
            g = twoZ * (d - x) - k * m.mu;
            gp = -twoZ - k * m.slope;
        };
        double x = d, g = 0.0, gp = 0.0;
        if (guess > 0.0 && guess < d) {
            eval(guess, g, gp);
            if (g <= 0.0 && gp < 0.0) x = guess;
        }
        eval(x, g, gp);
        for (int it = 0; it < 100; ++it) {
            if (g == 0.0) return x;
            if (gp >= 0.0) return std::nullopt;
            const double next = x - g / gp;
            if (next <= 0.0) return std::nullopt;
            const bool done = std::abs(next - x) <= 1e-14 * (1.0 + d);
            x = next;
            eval(x, g, gp);
            if (done) return x;
        }
        return x;
    }

    struct Speeds {
        double history, bow;
    };

    /// Non-finite inputs become zero, speed and force are clamped; the load line follows the
    /// force and impedance. Returns v_h and v_b.
    Speeds takeInputs(T vhIn, T vbIn, T fbIn, double zEff) noexcept
    {
        updateLoadLine(static_cast<double>(cleanForce(fbIn)), zEff);
        return {finiteOr(vhIn), static_cast<double>(cleanSpeed(vbIn))};
    }

    void updateLoadLine(double fb, double zEff) noexcept
    {
        if (fb != forceCached_) setLoad(fb); // pow() for the power law: only when the force moves
        if (zEff != zEffCached_) {
            zEffCached_ = zEff;
            twoZ_ = 2.0 * zEff;
            invTwoZ_ = 0.5 / zEff;
        }
    }

    void setLoad(double fb) noexcept
    {
        forceCached_ = fb;
        loadCached_ = area_.effectiveLoad(fb);
        invLoadCached_ = loadCached_ > 0.0 ? 1.0 / loadCached_ : 0.0;
    }

    /// Friction and heat carry per unit load, so a sudden drop in force does not pour the last
    /// sample's heat into a tiny footprint. The heat spreads over the bow's own footprint
    /// (ContactArea carries r_A K_A): r_A is the bow's area over the steady test's, so it
    /// scales the area that takes the heat as well as the friction (the law's scale does that).
    double stepTemperature() noexcept
    {
        const double load = loadCached_;
        return thermal_.step(heatPerLoadPrev_ * load, slidePrev_, area_.areaPerNewton * load,
                             heatSlopePerLoadPrev_ * load);
    }

    /// What this sample leaves for the next temperature step: heat |f dv| and sliding speed, and
    /// d(heat)/d(theta) at fixed sliding speed for the semi-implicit step (all per unit load).
    void keepHeat(double f, double dv, double heatSlopePerLoad) noexcept
    {
        heatPerLoadPrev_ = std::abs(f) * dv * invLoadCached_;
        slidePrev_ = dv;
        heatSlopePerLoadPrev_ = heatSlopePerLoad;
    }

    [[gnu::always_inline]] JunctionResult<T> solveThermal(double vh, double vb) noexcept
    {
        const double load = loadCached_;
        const double D = vb - vh;
        const double fStick = twoZ_ * D;
        const bool wasStuck = state_ == ContactState::Stick;
        const double theta = stepTemperature();
        // mu falls as the contact warms, so a contact no warmer than at the last lookup holds at
        // least that lookup's mu. Most sticking samples cool and stay below that limit: they
        // decide without the table (the same decision; the margin covers rounding in it).
        if (theta <= knownTheta_ && std::abs(fStick) <= load * knownMuFloor_) return stick(wasStuck, fStick, vb, theta);
        const MuSlope m = thermalLaw_.at(theta);
        knownTheta_ = theta;
        knownMuFloor_ = thermalLawFalls_ ? m.mu * (1.0 - 1e-12) : -1.0;
        const double limit = load * m.mu;
        if (std::abs(fStick) <= limit) return stick(wasStuck, fStick, vb, theta);
        const bool forward = D >= 0.0;
        double f = forward ? limit : -limit;
        state_ = forward ? ContactState::SlipForward : ContactState::SlipBackward;
        if (noiseLevel_ > 0.0) f *= 1.0 + noiseLevel_ * nextNoise();
        const double v = vh + f * invTwoZ_;
        const double dv = std::abs(v - vb);
        keepHeat(f, dv, dv > 0.0 ? dv * m.slope : 0.0);
        return {static_cast<T>(f), static_cast<T>(v), static_cast<T>(theta), false};
    }

    [[gnu::always_inline]] JunctionResult<T> stick(bool wasStuck, double fStick, double vb, double theta) noexcept
    {
        // Sticking makes no heat. Stored as constants, not computed from f and dv (which are
        // zero anyway), so the next temperature does not wait for this sample's friction; a
        // sample that was already sticking left them so.
        if (!wasStuck) {
            state_ = ContactState::Stick;
            heatPerLoadPrev_ = 0.0;
            slidePrev_ = 0.0;
            heatSlopePerLoadPrev_ = 0.0;
        }
        return {static_cast<T>(fStick), static_cast<T>(vb), static_cast<T>(theta), true};
    }

    /// Friction-curve and enhanced models: mu falls with sliding speed (the jump rule).
    [[gnu::noinline]] JunctionResult<T> solveSpeedDependent(double vh, double vb) noexcept
    {
        const double load = loadCached_;
        const double D = vb - vh;
        const double fStick = twoZ_ * D;
        double theta = 0.0, scale = 1.0;
        if (params_.model == FrictionModel::Enhanced) {
            theta = stepTemperature();
            scale = enhancedLaw_(theta);
        }
        double f = solveWithJumpRule(D, fStick, load, scale, twoZ_);
        if (noiseLevel_ > 0.0 && state_ != ContactState::Stick) f *= 1.0 + noiseLevel_ * nextNoise();
        const double v = state_ == ContactState::Stick ? vb : vh + f * invTwoZ_;
        const double dv = std::abs(v - vb);
        const bool heats = dv > 0.0 && params_.model == FrictionModel::Enhanced;
        keepHeat(f, dv, heats ? dv * speed_(dv).mu * enhancedLaw_.slope(theta) : 0.0);
        return {static_cast<T>(f), static_cast<T>(v), static_cast<T>(theta), state_ == ContactState::Stick};
    }

    FrictionParams params_;
    ContactArea area_;
    TemperatureLaw thermalLaw_, enhancedLaw_;
    ThermalContact<T> thermal_;
    ContactState state_ = ContactState::Stick;
    double xPrev_ = 0.0, heatPerLoadPrev_ = 0.0, slidePrev_ = 0.0, heatSlopePerLoadPrev_ = 0.0;
    SpeedLaw speed_;
    SteadyCurve steady_;
    double muAtRest_ = 1.0, forceCached_ = -1.0, loadCached_ = 0.0, invLoadCached_ = 0.0;
    double zEffCached_ = -1.0, twoZ_ = 1.0, invTwoZ_ = 0.0;
    double noiseLevel_ = 0.0;
    std::uint64_t noiseState_ = 1;
    double knownTheta_ = -1.0, knownMuFloor_ = -1.0; // the thermal path's last lookup
    bool thermalLawFalls_ = false;
};

} // namespace rosin::dsp
