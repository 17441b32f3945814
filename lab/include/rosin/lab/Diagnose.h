// `rosin diagnose` (shared/docs/DIAGNOSIS.md): simulate the strokes of a measurement set with a
// baseline model, find where it disagrees with the data, try each physical extension fitted on
// part of the strokes, keep the one that helps most on the strokes held out (if significantly),
// and repeat until nothing helps.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rosin/lab/Classifier.h"
#include "rosin/lab/Measurement.h"

namespace rosin::lab {

/// A model as the list of effects switched on (DIAGNOSIS.md ids) and their parameters.
struct EffectModel {
    std::vector<std::string> effects;
    std::map<std::string, double> params;
    std::string name() const; ///< friction_curve, thermal or enhanced (+ hertz, torsion, shift)
};

/// What is compared per stroke (PHYSICS.md 7.1), from a bridge force in newtons that starts
/// at the gesture start, sampled at the diagnosis rate.
struct StrokeFeatures {
    double firstSlip = -1;      ///< s
    double forceBeforeSlip = 0; ///< N
    double firstDrop = 0;       ///< N, fall over 0.1 ms at the first slip
    int transientPeriods = -1;  ///< -1 = failure
    Regime regime = Regime::NoSlip;
    std::vector<double> wave;   ///< the first 2 periods after the first slip
};

/// Per-stroke disagreement, each part capped at 1. The first-slip parts are deterministic
/// functions of the physics; transient length and late waveform are chaotic (sensitive
/// dependence), so they weigh less: otherwise their scatter hides real effects.
struct ErrorParts {
    double firstSlip = 0, forceBeforeSlip = 0, jump = 0, transient = 0, waveform = 0;
    double total() const { return 0.25 * firstSlip + 0.25 * forceBeforeSlip + 0.25 * jump + 0.10 * transient + 0.15 * waveform; }
};

struct DiagnoseOptions {
    std::uint64_t seed = 1;
    double fitFraction = 2.0 / 3.0;
    double simRate = 48000.0;
    int bootstrap = 2000;       ///< resamples for the held-out gain CI
    int parameterBootstrap = 10;///< refits on resampled fit sets for parameter CIs
    int maxEvaluations = 30;    ///< NLopt evaluations per candidate fit
    double minRelativeGain = 0.05;  ///< a finding must also lower the held-out error by 5 %
    bool quiet = false;
};

struct Finding {
    std::string effect;
    std::string evidence;
    std::map<std::string, std::vector<double>> parameters; ///< name -> {value, ci low, ci high}
    double heldoutBefore = 0, heldoutAfter = 0;
};

/// One candidate extension tried in one round, with its fitted parameters and held-out gain.
struct Trial {
    int round = 0;
    std::string effect;
    std::map<std::string, double> parameters;
    double fitError = 0, gain = 0, gainLow = 0, gainHigh = 0; ///< gain = held-out error fall (absolute)
    bool kept = false;
};

/// A two-ended steady stroke: measured and final-model (v, f) loops by Schumacher's method.
struct LoopComparison {
    std::string id;
    double measuredArea = 0, finalArea = 0; ///< signed (v, f) areas: positive = anticlockwise
    std::vector<double> measuredV, measuredF, finalV, finalF; ///< the last three periods
};

struct Diagnosis {
    std::vector<Trial> trials;
    std::vector<LoopComparison> loops;
    std::string setName;
    EffectModel baseline, final;
    std::vector<Finding> findings;
    double baselineError = 0, finalError = 0, relativeGain = 0, gainLow = 0, gainHigh = 0;
    std::size_t nFit = 0, nHeldout = 0;
    std::vector<std::string> fitIds, heldoutIds;
    double scale = 1.0;         ///< N per signal unit
    bool triggersDetected = false; ///< gesture starts estimated from pre-slip ramps
    std::vector<std::string> warnings;
    double seconds = 0;
    long long simulations = 0;
    // For the report: features per stroke (measured, baseline, final), in set order.
    std::vector<std::string> ids;
    std::vector<double> accel, force;
    std::vector<StrokeFeatures> measured, baselineSim, finalSim;
    std::vector<std::vector<double>> measuredForce, baselineForce, finalForce; ///< first 12 periods
};

Diagnosis diagnose(const MeasurementSet& set, const DiagnoseOptions& options,
                   const std::function<void(const std::string&, double)>& progress = {});

/// diagnosis.json (DIAGNOSIS.md), report.md and the figures, into `dir`.
void writeDiagnosis(const std::filesystem::path& dir, const Diagnosis& d, const DiagnoseOptions& options);

} // namespace rosin::lab
