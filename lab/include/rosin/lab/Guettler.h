// Guettler diagrams (PHYSICS.md 6): a constant-acceleration stroke from rest for every
// (acceleration, force, beta) cell, classified; optionally the minimum over perturbed
// variants (6.7). Cells are independent, so they run on all cores and, under mpirun, across
// processes, with results that do not depend on how the work was split.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "rosin/dsp.h"
#include "rosin/lab/Classifier.h"
#include "rosin/lab/Playability.h" // guettlerBounds

namespace rosin::lab {

struct SweepSpec {
    dsp::BowedStringConfig config;
    std::string label = "thermal";     ///< name of the model, for titles and files
    double sampleRate = 48000.0;
    std::vector<double> accelerations; ///< m/s^2
    std::vector<double> forces;        ///< N
    std::vector<double> betas{0.0899};
    int variants = 1;                  ///< 1 = plain; N = minimum over N perturbed runs
    std::uint64_t seed = 1;
    double periodsAfterSlip = 32.0;    ///< simulated after the first slip (cap 25 + 5 settled + margin)
    double maxSeconds = 1.0;           ///< a stroke that has not slipped by then is NoSlip

    /// Linear grid lo..hi with n points (Guettler's axes start near zero; PHYSICS.md 6.2).
    static std::vector<double> grid(double lo, double hi, int n);
};

struct CellResult {
    double acceleration = 0, force = 0, beta = 0;
    double firstSlipTime = -1;      ///< s
    double forceBeforeSlip = 0;     ///< bridge force just before the first slip (N)
    double firstJump = 0;           ///< friction-force drop at the first slip sample (N)
    int transientPeriods = -1;      ///< N_T (min over variants), -1 for failure
    Regime regime = Regime::NoSlip; ///< regime of the variant that achieved the minimum
    double peakTemperature = 0;     ///< K above ambient
    int variant = 0;                ///< which variant gave the minimum
};

struct SweepResult {
    SweepSpec spec;
    std::vector<CellResult> cells;  ///< index (ib * nForce + iF) * nAccel + ia
    double wallSeconds = 0;
    long long simulatedSamples = 0;

    const CellResult& at(std::size_t ia, std::size_t iF, std::size_t ib = 0) const
    {
        return cells[(ib * spec.forces.size() + iF) * spec.accelerations.size() + ia];
    }
    int successCount() const;
};

/// One stroke: returns the classification and fills the per-cell record. Exposed for tests
/// and for the single-transient figures. `trace` (optional) receives every simulated frame.
/// `cellIndex` selects the perturbation stream, as the sweep does for its cell of that index.
CellResult simulateCell(const SweepSpec& spec, double accel, double force, double beta, int variant,
                        std::vector<dsp::BowFrame<double>>* trace = nullptr, std::uint64_t cellIndex = 0);

/// Runs the whole grid. `progress` gets the finished fraction (from any thread).
SweepResult runSweep(const SweepSpec& spec, const std::function<void(double)>& progress = {});

/// Table outputs: CSV (one row per cell) and JSON (spec + cells).
void writeSweepCsv(const std::filesystem::path& file, const SweepResult& r);
void writeSweepJson(const std::filesystem::path& file, const SweepResult& r);

/// Fit of the lower boundary of the successful region, F = c a^p (PHYSICS.md 5.4).
struct BoundaryFit {
    bool valid = false;
    double c = 0, p = 0, pLow = 0, pHigh = 0; ///< p with its 95 % confidence interval
    std::vector<double> accelerations, forces; ///< the boundary points used
};
BoundaryFit fitLowerBoundary(const SweepResult& r, std::size_t betaIndex = 0);

} // namespace rosin::lab
