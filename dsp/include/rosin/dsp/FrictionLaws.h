// Steady-sliding friction fits, speed functions of the enhanced model, the contact-area law
// and the thermal parameter set (PHYSICS.md 2.1, 3.8, 4.1, 5.3).
#pragma once
#include <cmath>
#include <numbers>

namespace rosin::dsp {

/// A friction coefficient and its slope d(mu)/dx at sliding speed x >= 0.
struct MuSlope {
    double mu;
    double slope;
};

enum class SteadyFit {
    SmithWoodhouse,   ///< 0.4 e^{-v/0.01} + 0.45 e^{-v/0.1} + 0.35            [SW00; W03]
    WoodhouseGalluzzo ///< 0.2 (v + 0.011)^{-0.4}, decays to zero at high speed [WG25 eq. 13]
};

/// A steady-sliding curve with its coefficients as fields: one of the two published fits, or a
/// rig's own measured curve (diagnosis fits it to a set's steady_sliding.csv).
struct SteadyCurve {
    SteadyFit shape = SteadyFit::SmithWoodhouse;
    double a1 = 0.4, v1 = 0.01, a2 = 0.45, v2 = 0.1, a3 = 0.35; ///< a1 e^{-v/v1} + a2 e^{-v/v2} + a3
    double k1 = 40.0, k2 = 4.5;                                 ///< a1/v1, a2/v2 (the slope's factors)
    double c = 0.2, v0 = 0.011, p = 0.4;                        ///< c (v + v0)^{-p}

    static SteadyCurve of(SteadyFit fit) noexcept
    {
        SteadyCurve s;
        s.shape = fit;
        return s;
    }
    /// Smith-Woodhouse shape with the rig's coefficients.
    static SteadyCurve exponentials(double a1, double v1, double a2, double v2, double a3) noexcept
    {
        SteadyCurve s;
        s.a1 = a1, s.v1 = v1, s.a2 = a2, s.v2 = v2, s.a3 = a3, s.k1 = a1 / v1, s.k2 = a2 / v2;
        return s;
    }
    MuSlope operator()(double x) const noexcept
    {
        x = std::abs(x);
        if (shape == SteadyFit::SmithWoodhouse) {
            const double e1 = std::exp(-x / v1), e2 = std::exp(-x / v2);
            return {a1 * e1 + a2 * e2 + a3, -k1 * e1 - k2 * e2};
        }
        const double q = std::pow(x + v0, -p);
        return {c * q, -p * c * q / (x + v0)};
    }
};

inline MuSlope steadySliding(SteadyFit fit, double x) noexcept { return SteadyCurve::of(fit)(x); }

enum class SpeedFunction {
    Bow, ///< h_bow = 0.5 (v + 0.27)^{-0.4}   [WG25 eq. 14]
    Rod  ///< h_rod = 0.37 (v + 0.35)^{-0.4}  [WG25 eq. 15]
};

/// Speed function of the enhanced model, h(v) = c (|v| + v0)^(-p). The bow and rod fits are
/// presets; diagnosis fits its own (DIAGNOSIS.md: h0 = h(0) and p).
struct SpeedLaw {
    double c = 0.37, v0 = 0.35, p = 0.4;

    static SpeedLaw of(SpeedFunction kind) noexcept
    {
        return kind == SpeedFunction::Bow ? SpeedLaw{0.5, 0.27, 0.4} : SpeedLaw{0.37, 0.35, 0.4};
    }
    /// The law with h(0) = h0 and exponent p, keeping v0.
    static SpeedLaw withRest(double h0, double p, double v0 = 0.35) noexcept { return {h0 * std::pow(v0, p), v0, p}; }
    double atRest() const noexcept { return c * std::pow(v0, -p); }
    MuSlope operator()(double x) const noexcept
    {
        x = std::abs(x);
        const double q = std::pow(x + v0, -p);
        return {c * q, -p * c * q / (x + v0)};
    }
};

inline MuSlope speedFunction(SpeedFunction kind, double x) noexcept { return SpeedLaw::of(kind)(x); }

enum class ContactLaw {
    Amontons, ///< real contact area proportional to load (many asperities, a bow)
    PowerLaw  ///< A proportional to F^n; n = 2/3 is a single Hertzian contact (a rod)
};

/// Thermal and contact constants (PHYSICS.md 3.8 defaults; all are parameters, several are
/// guesses in the literature).
struct ThermalParams {
    double contactRadiusAtRef = 250e-6;   ///< a at the reference load (m)        [W03 Table I]
    double referenceLoad = 1.0;           ///< F_ref of the steady-sliding test (N) [A]
    double layerThickness = 1e-6;         ///< rosin layer delta (m)              [W03]
    double rosinHeatCapacity = 1.6e6;     ///< rho_r c_r (J m^-3 K^-1)            [A]
    double stringEffusivity = 2050.0;     ///< e_s (W s^1/2 m^-2 K^-1)            [W03 Table I]
    double rodEffusivity = 450.0;         ///< e_r, the moving bow/rod side       [W03 Table I]
    double advectionWidthFactor = 2.0;    ///< w = factor * a                     [A]
    double footprintRatio = 1.0;          ///< r_A = K_A(bow) / K_A(steady test)  [E9.6.3]
    double ambientCelsius = 20.0;         ///< ambient of the simulation
    double referenceAmbientCelsius = 20.0;///< ambient of the steady-sliding measurement
    double glassTransitionCelsius = 49.0; ///< rosin of this preset
    double referenceGlassTransitionCelsius = 49.0; ///< violin rosin of the measurement [seed]
    double polesPerDecade = 1.5;          ///< conduction bank density (errors < 1 %)
    double xiMin = 0.3;                   ///< lowest pole (1/s)              [PHYSICS.md 3.4]
    double xiMaxOverSampleRate = 10.0;    ///< highest pole / fs (above: a capacity term)

    /// Temperature offset added to the contact rise before looking up the friction law:
    /// a warmer room, or a softer rosin (lower Tg), both act like a hotter contact.
    double temperatureShift() const noexcept
    {
        return (ambientCelsius - referenceAmbientCelsius)
               + (referenceGlassTransitionCelsius - glassTransitionCelsius);
    }
};

/// Contact area as a function of bow force, shared by friction and heat balance so both see
/// the same footprint. Friction = A * tau_y(theta), written as effectiveLoad * mu(theta).
/// The area is the bow's own, r_A K_A per unit load: the steady test's footprint times the
/// footprint ratio, so the heat spreads where the bow touches.
struct ContactArea {
    ContactLaw law = ContactLaw::Amontons;
    double exponent = 2.0 / 3.0;
    double referenceLoad = 1.0;
    double areaPerNewton = std::numbers::pi * 250e-6 * 250e-6; ///< r_A K_A, K_A = A_ref / F_ref

    void configure(ContactLaw l, double n, const ThermalParams& tp) noexcept
    {
        law = l;
        exponent = n;
        referenceLoad = tp.referenceLoad;
        areaPerNewton = tp.footprintRatio * std::numbers::pi * tp.contactRadiusAtRef * tp.contactRadiusAtRef / tp.referenceLoad;
    }

    /// The load that multiplies mu: F itself (Amontons) or F_ref (F/F_ref)^n, equal at F_ref.
    double effectiveLoad(double force) const noexcept
    {
        if (force <= 0.0) return 0.0;
        if (law == ContactLaw::Amontons) return force;
        return referenceLoad * std::pow(force / referenceLoad, exponent);
    }
    double area(double force) const noexcept { return areaPerNewton * effectiveLoad(force); }
};

} // namespace rosin::dsp
