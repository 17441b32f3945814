// Measurement sets `rosin-measurement/1` (shared/docs/MEASUREMENT_FORMAT.md): a folder with a
// manifest and one bridge-force file per stroke, from a rig or from any simulator.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rosin/lab/Gesture.h"

namespace rosin::lab {

struct MeasuredStroke {
    std::string id;
    std::filesystem::path file;
    int channel = 0;
    /// guettler, exp_speed or exp_force: the set's kind, or the stroke's own in a mixed set.
    std::string gesture = "guettler";
    // Gesture (by kind): guettler uses accel and force; exp_speed v0 and tv (and force);
    // exp_force speed, f0 and tf.
    double accel = 0, force = 0, v0 = 0, tv = 0, speed = 0, f0 = 0, tf = 0;
    std::optional<double> trigger;   ///< s into the file where the gesture starts, when known
    std::vector<double> signal;      ///< in the sensor's units, at the set's sample rate
};

/// A steady stroke recorded at both string ends (PHYSICS.md 7.2).
struct TwoEndedRecording {
    std::string id;
    std::filesystem::path file;
    double bowSpeed = 0, force = 0;
    int bridgeChannel = 0, farChannel = 1;
    std::vector<double> bridge, far; ///< sensor units, at the set's rate
};

/// One row of steady_sliding.csv: friction measured in steady sliding at one speed.
struct SteadySlidingPoint {
    double speed = 0, mu = 0;
    double force = 0; ///< N; 0 when the file has no force column
};

struct MeasurementSet {
    std::filesystem::path folder;
    std::string description;
    // rig.string (f0 required; the others may be filled from a preset of the same name)
    std::string stringName;
    double f0 = 0;
    std::optional<double> length, tension, z0;
    double beta = 0;
    /// How well the lab knows its tension and bow position: the true value is within this
    /// fraction of the stated one (rig.string.tension_uncertainty, rig.beta_uncertainty). Unset:
    /// the diagnosis's own priors (+-5 %, +-4 %).
    std::optional<double> tensionUncertainty, betaUncertainty;
    /// The string's transverse Q as the lab measured it (rig.string.q_f0, rig.string.q_5khz: from
    /// the decays of its partials at the fundamental and near 5 kHz). Unset: the model's own.
    std::optional<double> qAtF0, qAt5kHz;
    /// The string's torsional wave speed over its transverse one and its torsional Q as the lab
    /// measured them (rig.string.torsion_speed_ratio, rig.string.q_torsion: from its torsional
    /// resonances). Unset: the model's own (5.2 and 30). They matter only where the string rolls.
    std::optional<double> torsionSpeedRatio, qTorsion;
    std::string exciter = "unknown";   ///< bow, rod or unknown
    std::optional<double> ambient;     ///< C
    std::string units = "N";           ///< N (calibrated) or V (scale unknown)
    double sampleRate = 0;             ///< the manifest's rate: authoritative
    std::string gesture = "guettler";  ///< guettler, exp_speed, exp_force, or mixed (each stroke names its own)
    std::vector<MeasuredStroke> strokes;
    std::optional<std::filesystem::path> steadySliding;
    std::vector<SteadySlidingPoint> steady; ///< its rows (read from, or written to, steady_sliding.csv)
    std::vector<TwoEndedRecording> twoEnded;
    std::vector<std::string> warnings; ///< what the reader had to decide (said, not silently done)
};

/// The stroke's gesture as controls over time (t = 0 at the gesture start), at bow position beta.
Gesture strokeGesture(const MeasuredStroke& s, double beta);

/// Reads and checks a set. Throws LabError naming the file and the field on any breach of
/// the format; reads every signal so a broken file is found before anything is computed.
MeasurementSet readMeasurementSet(const std::filesystem::path& folder);

/// Writes a set (manifest + signal files) into `folder`, which must not exist yet; the whole
/// folder appears only when complete.
void writeMeasurementSet(const std::filesystem::path& folder, const MeasurementSet& set, int wavFormat);

} // namespace rosin::lab
