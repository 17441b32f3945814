// `rosin synth-data`: measurement sets simulated by a model with chosen hidden effects
// (shared/docs/DIAGNOSIS.md vocabulary) and the artefacts of a real rig, so that diagnosis can
// be tested against a known answer. The answer goes to a separate truth file, never into the set.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rosin/dsp.h"
#include "rosin/lab/Measurement.h"

namespace rosin::lab {

/// Effect ids of DIAGNOSIS.md.
inline const std::vector<std::string>& effectIds()
{
    static const std::vector<std::string> ids{"thermal_memory", "rate_dependence", "hertzian_contact",
                                              "rosin_temperature_shift", "torsional_compliance"};
    return ids;
}

struct SynthSpec {
    std::vector<std::string> effects;   ///< empty = the baseline model ("none")
    std::map<std::string, double> params; ///< r_A, load_exponent, shift_k, zt_ratio; drawn from the seed if absent
    std::uint64_t seed = 1;
    int grid = 12;                        ///< strokes per axis (grid x grid Guettler strokes)
    double aMin = 0.15, aMax = 3.0, fMin = 0.15, fMax = 3.0, beta = 0.0899;
    double simRate = 96000.0;             ///< rate of the simulation behind the data
    double outRate = 48000.0;             ///< rate of the written files
    std::string units = "V";              ///< V: an unknown gain is applied; N: calibrated
    double noise = 0.01;                  ///< white noise, relative to the ideal flyback at 1 m/s / beta... in N
    double humHz = 50.0, humLevel = 0.03; ///< mains hum (N before gain), 0 Hz = none
    double dcLevel = 0.2;                 ///< DC offset (N before gain)
    double triggerMax = 0.02;             ///< gesture starts up to this late in each file (s)
    double jitter = 0.01;                 ///< per-stroke relative jitter of true force and acceleration
    double seconds = 0.35;                ///< length of each stroke after the trigger
    bool gaussianReflections = false;     ///< another reflection-filter design than the project's own
    int twoEnded = 2;                     ///< steady strokes recorded at both ends (0 = none)
    /// "model": dsp/'s own model makes the data (a consistency check of the diagnosis);
    /// "reference": the reference simulator (lab/reference, no code shared with dsp/) on a
    /// rig drawn with every nuisance a lab never knows exactly (ReferenceData.h);
    /// "model-on-rig": the same draws as "reference" (effects, rig, sensor, noise), but dsp/'s
    /// model makes the strokes (modelOnRig()): the diagnosis's ceiling, where nothing but the
    /// nuisances it fits and the recording differ from its model.
    std::string generator = "model";
    std::map<std::string, double> rig;    ///< reference: rig values fixed instead of drawn (referenceRigKeys())
    /// reference: a hidden parameter drawn from this range instead of its whole prior (a study
    /// at the edge of detection); each range lies within referenceEffectPriors().
    std::map<std::string, std::pair<double, double>> paramRanges;
    /// reference: what the lab states it knows of its rig ("tension", "beta": +-fraction): the
    /// error is drawn within it and the manifest says so (parseStatedUncertainties()).
    std::map<std::string, double> statedUncertainty;
    int oversampling = 4;                 ///< reference: simulation rate / file rate (>= 4)
    /// reference: guettler (a x F grid), exp_speed (initial acceleration v0/tv x F, v0 fixed),
    /// exp_force (bow speed x F0, tf fixed) or mixed (the three in turn over the grid).
    std::string gesture = "guettler";
    double expV0 = 0.1;                   ///< exp_speed: final bow speed (m/s)
    double expTf = 0.02;                  ///< exp_force: force time constant (s)
    double vMin = 0.05, vMax = 0.5;       ///< exp_force: bow speeds of the grid (m/s)
};

struct SynthTruth {
    std::vector<std::string> effects;
    std::map<std::string, double> params;
    double gain = 1.0; ///< signal units per newton
    std::map<std::string, double> triggers; ///< stroke id -> gesture start in its file (s)
    std::string generator = "model";
    std::map<std::string, double> rig;      ///< reference: every drawn rig value (referenceRigKeys())
    std::map<std::string, std::pair<double, double>> strokes; ///< stroke id -> true (drive, force): drive as Gesture::drive()
    double clippedFraction = 0.0;           ///< share of samples at full scale
};

/// OUT.truth.json (rosin-synth-truth/1): the hidden effects and parameters, the gain, the
/// triggers and, for reference sets, every drawn rig value and each stroke's true gesture.
void writeTruth(const std::filesystem::path& file, const SynthTruth& truth, std::uint64_t seed);

/// Simulates the set (all cores) and returns it with the hidden truth.
MeasurementSet synthesize(const SynthSpec& spec, SynthTruth& truth, const std::function<void(double)>& progress = {});

/// The model of DIAGNOSIS.md's baseline (friction curve, Amontons, no torsion, reference rosin)
/// with the given effects switched on.
dsp::BowedStringConfig modelWithEffects(const std::vector<std::string>& effects, const std::map<std::string, double>& params);

/// The diagnosis's own model standing in for a drawn reference rig (`--generator model-on-rig`):
/// the hidden effects at their values, on the rig's true string (its tension, tuned to the
/// manifest's pitch f0), with the rig's steady-sliding curve and bow-side effusivity, the values
/// the diagnosis fits or reads from the set; everything the model holds fixed (stiffness, losses,
/// a rigid bridge, the contact's other thermal constants, the torsional wave speed) at its own.
dsp::BowedStringConfig modelOnRig(const std::vector<std::string>& effects, const std::map<std::string, double>& params,
                                  const std::map<std::string, double>& rig, double f0);

} // namespace rosin::lab
