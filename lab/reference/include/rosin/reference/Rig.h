// The reference simulator's description of a bowing rig: string, bridge, contact and friction.
// Written from the physics (PHYSICS.md sections 1-5), not from dsp/: it shares no code with the
// model that diagnosis fits, so data made with it can test that model. Every constant is a field.
#pragma once
#include <string>
#include <vector>

namespace rosin::reference {

/// Steady-sliding friction coefficient mu_ss(|v|) (PHYSICS.md 2.1), times an overall level.
struct SteadySliding {
    enum class Shape { Exponentials, PowerLaw };
    Shape shape = Shape::Exponentials;
    double a1 = 0.4, v1 = 0.01, a2 = 0.45, v2 = 0.1, a3 = 0.35; ///< a1 e^(-v/v1) + a2 e^(-v/v2) + a3  [SW00]
    double c = 0.2, v0 = 0.011, p = 0.4;                        ///< c (v + v0)^(-p)                   [WG25]
    double level = 1.0;                                         ///< a rig's rosin is never the fit's

    double mu(double speed) const;
    double slope(double speed) const; ///< d mu / d|v|
};

/// Speed function of the enhanced law, h(v) = h0 ((|v| + v0) / v0)^(-p), so h(0) = h0.
struct SpeedFunction {
    double h0 = 0.563, v0 = 0.35, p = 0.4;
    double at(double speed) const;
};

/// Contact and heat constants (PHYSICS.md 3.3, 3.8), all at the steady-sliding test's load.
struct ContactConstants {
    double radiusAtReference = 250e-6;   ///< a at the reference load (m)
    double referenceLoad = 1.0;          ///< N
    double layerThickness = 1e-6;        ///< rosin layer (m)
    double rosinVolumetricHeat = 1.6e6;  ///< rho c of rosin (J m^-3 K^-1)
    double stringEffusivity = 2050.0;    ///< stationary side (W s^1/2 m^-2 K^-1)
    double rodEffusivity = 450.0;        ///< moving side, renewed at kappa = 3|dv|/(8a)
    double advectionWidthFactor = 2.0;   ///< advection width w = factor * a
};

enum class FrictionLaw {
    Curve,   ///< mu_ss(|dv|) with the stick/slip jump rule (PHYSICS.md 2.2-2.3)
    Thermal, ///< r_A mu(theta): friction follows the contact temperature (3.2)
    Enhanced ///< r_A y(theta) h(|dv|) with the jump rule (4.1-4.4)
};

struct Friction {
    FrictionLaw law = FrictionLaw::Curve;
    SteadySliding steady;                ///< what the rig's rosin does in steady sliding
    SpeedFunction speed;                 ///< enhanced law only
    double footprintRatio = 1.0;         ///< r_A: contact area per newton, bowing / steady test
    double temperatureShiftK = 0.0;      ///< positive: the rosin acts hotter (softer) than the reference
    double loadExponent = 1.0;           ///< area ~ load^n: 1 Amontons, 2/3 Hertz
    ContactConstants contact;
};

struct StringModel {
    double length = 0.69, tension = 102.6, massPerLength = 2.4357e-3; ///< m, N, kg/m
    double inharmonicity = 1e-5;         ///< B, so EI = B T L^2 / pi^2
    bool losses = true;
    double qLow = 500.0, qHigh = 150.0, fHigh = 5000.0; ///< Q at f0 and at fHigh
    bool torsion = false;
    double torsionSpeedRatio = 5.2, torsionImpedanceRatio = 2.0, qTorsion = 30.0;

    double waveSpeed() const;
    double impedance() const;     ///< Z0 = sqrt(T m)
    double flexuralRigidity() const; ///< EI
};

/// One resonance of the bridge's point admittance Y(w) = i w / (K - M w^2 + i w R): the
/// string end moves with the sum of its modes. Peak admittance 1/R at `frequency`.
struct BridgeMode {
    double frequency = 2000.0, q = 10.0, peakAdmittance = 0.02; ///< Hz, -, s/kg
};

struct Rig {
    StringModel string;
    std::vector<BridgeMode> bridge; ///< empty: a rigid end
    Friction friction;
    /// First thing wrong, or empty (the simulator refuses a rig that is not usable).
    std::string validate() const;
};

} // namespace rosin::reference
