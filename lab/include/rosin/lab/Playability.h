// Playability maps for one string and friction model: where a player's bow lands in Helmholtz
// motion. Schelleng's map (bow position beta against force, steady bow speed) classifies the
// steady motion; Guettler's map (acceleration against force, from rest) classifies the attack
// with the lab's transient classifier. The editor computes them in the background for the
// string being played; `rosin playability` writes them as figures.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "rosin/dsp.h"
#include "rosin/lab/Classifier.h"

namespace rosin::lab {

enum class MapKind { Schelleng, Guettler };
const char* mapKindName(MapKind k);

struct PlayabilitySpec {
    MapKind kind = MapKind::Schelleng;
    dsp::BowedStringConfig config;
    double sampleRate = 48000.0;
    double frequency = 0.0;        ///< stopped-string fundamental (Hz); 0 plays the open string
    std::vector<double> forces;    ///< N (y axis of both maps)
    std::vector<double> columns;   ///< beta (Schelleng) or acceleration m/s^2 (Guettler): the x axis
    double speed = 0.1;            ///< Schelleng: steady bow speed (m/s)
    double beta = 0.1;             ///< Guettler: bow position
    double settleSeconds = 1.0;    ///< Schelleng: simulated before the motion is judged (the contact warms for ~0.5 s)
    double judgeSeconds = 0.1;     ///< Schelleng: how long the motion is judged

    /// Axes around a player's bow: Schelleng forces log-spaced nominal/20..nominal*8 against
    /// betas 0.02-0.3; Guettler forces nominal/10..nominal*4 against accelerations linear up to
    /// 2.5x the attack's (m/s^2).
    static PlayabilitySpec around(MapKind kind, const dsp::BowedStringConfig& config, double nominalForce, double speed,
                                  double beta, double acceleration, double frequency, int columns, int rows);
};

struct PlayabilityCell {
    Regime regime = Regime::NoSlip;
    bool success = false;
    int transientPeriods = -1; ///< Guettler: N_T; Schelleng: -1
    double slipsPerPeriod = 0; ///< Schelleng: slip onsets per nominal period while judged
};

struct PlayabilityMap {
    PlayabilitySpec spec;
    std::vector<PlayabilityCell> cells; ///< index row * columns + column (row = force)
    std::vector<bool> done;             ///< which cells are computed (the map fills in row by row)
    double f0 = 0.0;                    ///< fundamental the map was computed for (Hz)
    double z0 = 0.0;                    ///< transverse impedance (kg/s)
    const PlayabilityCell& at(std::size_t column, std::size_t row) const { return cells[row * spec.columns.size() + column]; }
    std::size_t completed() const;
};

/// Schelleng's maximum force at bow position beta (PHYSICS.md 2.4), and Guettler's bounds as
/// forces per unit acceleration (PHYSICS.md 6.3), from the string and two friction coefficients.
double schellengMaxForce(double z0, double speed, double beta, double muS, double muD);
struct GuettlerBounds {
    double lowerPerAccel = 0, upperPerAccel = 0; ///< N per (m/s^2)
};
GuettlerBounds guettlerBounds(const dsp::StringParams& s, double beta, double muS, double muD);

/// One constant-acceleration stroke from rest (v_b = a t) on a prepared, reset string, run until
/// `periodsAfterSlip` periods after the first slip (or `maxSeconds`), then classified from the
/// bridge force and the stick record. The one stroke both Guettler's map and `rosin guettler` use.
struct GuettlerStroke {
    Classification classification;
    long firstSlip = -1;        ///< sample of the first slip, -1 if none
    double firstJump = 0;       ///< friction-force drop at the first slip (N)
    double peakTemperature = 0; ///< K above ambient
};
GuettlerStroke runGuettlerStroke(dsp::BowedString<double>& string, const dsp::BowedStringConfig& config, double sampleRate,
                                 double accel, double force, double beta, double periodsAfterSlip, double maxSeconds,
                                 std::vector<double>& bridge, std::vector<std::uint8_t>& stick,
                                 std::vector<dsp::BowFrame<double>>* trace = nullptr);

/// One cell, deterministic. Exposed for tests.
PlayabilityCell playabilityCell(const PlayabilitySpec& spec, double column, double force);

/// Fills the map row by row. `cancel` (optional) stops it between cells; `onRow` (optional)
/// sees the partial map after each row. Throws LabError for an empty or out-of-range axis.
PlayabilityMap computePlayability(const PlayabilitySpec& spec, const std::atomic<bool>* cancel = nullptr,
                                  const std::function<void(const PlayabilityMap&)>& onRow = {});

} // namespace rosin::lab
