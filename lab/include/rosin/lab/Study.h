// `rosin study`: how well does `diagnose` do on data it did not make? Generates N reference sets
// (lab/reference, rigs drawn with every nuisance), diagnoses each from its files, and scores the
// findings against the hidden truth: detection per effect, false positives, parameter error,
// coverage of the reported 95 % intervals, and detection against effect size. Run by hand
// (minutes per set); under mpirun the sets are dealt to ranks through the same code path.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rosin/lab/Diagnose.h"

namespace rosin::lab {

struct StudyOptions {
    int sets = 30;             ///< N >= 30 in a real study
    int nulls = 8;             ///< of which with no hidden effect
    int grid = 12;             ///< strokes per axis of each set
    std::uint64_t seed = 1;    ///< the plan, and each set's seed, follow from it
    /// Which effects a plan can hide together. 1: the plans of every study up to seed 2042,
    /// where no set hides a rate dependence beside a rosin shift; 2 adds that pair (so the
    /// diagnosis's rule for a shift beside a rate law meets true shifts too).
    int plan = 2;
    int oversampling = 4;
    /// The sets' strokes (synth-data --gesture): guettler, exp_speed, exp_force (then
    /// calibrated in newtons: rising-force strokes alone cannot set a volt scale) or mixed.
    std::string gesture = "guettler";
    /// The sensor's units (synth-data --units): V (an unknown gain, which the pre-slip ramps set)
    /// or N (calibrated, to within the rig's calibration_error). exp_force sets are always N.
    std::string units = "V";
    /// What makes the sets: "reference" (the reference simulator, the studies' verdicts) or
    /// "model-on-rig" (the same plan and draws, made by dsp/'s own model: what the diagnosis
    /// could do if its model were the rig's physics, a ceiling and a consistency check).
    std::string generator = "reference";
    /// Rig values fixed in every set instead of drawn (synth-data --rig-param): a study of rigs
    /// that differ from the model in a way no candidate names, such as a strongly stiff string.
    std::map<std::string, double> rig;
    /// Hidden parameters drawn from a narrower range than their prior (synth-data's
    /// paramRanges): a study of effects near their detection limit. Part of the plan.
    std::map<std::string, std::pair<double, double>> paramRanges;
    /// Rigs whose lab states its tension and bow position to +-U (synth-data's
    /// statedUncertainty): what a better-measured rig can name. Part of the plan.
    std::map<std::string, double> statedUncertainty;
    bool keepSets = false;     ///< keep the generated WAV sets (regenerable from their seeds)
    bool generateOnly = false; ///< simulate and keep the sets, diagnose none (a later run diagnoses the kept sets)
    /// Run only these planned sets now (by index; empty = all) and only those hiding this effect
    /// (empty = any): a later run of the same folder does the rest. The plan is always the whole.
    std::vector<int> only;
    std::string hiding;
    DiagnoseOptions diagnose;
    /// Each set's diagnosis split (and bootstraps) seeded from the set's own seed and
    /// diagnose.seed. Without it every set is diagnosed with diagnose.seed, so the sets of one
    /// grid share one split: the study measures a single draw of which strokes fit, validate and
    /// test, and its rates are conditional on that draw.
    bool splitPerSet = false;
    bool quiet = false;
};

/// The diagnosis seed of a set under StudyOptions::splitPerSet: reproducible from the set's seed
/// and the study's diagnosis seed, written to the set's split.json.
std::uint64_t perSetDiagnoseSeed(std::uint64_t diagnoseSeed, std::uint64_t setSeed);

/// One planned set: its hidden effects and the seed its rig and parameters are drawn from.
struct StudySet {
    int index = 0;
    std::uint64_t seed = 0;
    std::vector<std::string> effects;
};

/// The plan: `nulls` null sets, then singles (45 %), doubles (35 %) and triples of the
/// vocabulary, in an order shuffled from the seed.
std::vector<StudySet> planStudy(const StudyOptions& o);

/// A set's effects as one label, "thermal_memory+hertzian_contact" ("none" for a null set), as
/// the study's files and progress lines write them.
std::string effectsLabel(const std::vector<std::string>& effects);

/// Runs the plan into `dir` (DIR/sets/NNN/{truth.json, diagnosis/}), then scores it.
void runStudy(const std::filesystem::path& dir, const StudyOptions& o, const std::function<void(const std::string&, double)>& progress = {});

/// Scores every DIR/sets/NNN/{truth.json, diagnosis/diagnosis.json} and writes DIR/study.csv,
/// DIR/study.json, DIR/summary.md and DIR/study.png. Returns the summary's markdown.
std::string scoreStudy(const std::filesystem::path& dir);

/// Scores the sets of several studies as one (seeds differ, the rig population does not: their
/// grid, gesture, units and fixed rig values must match, and no set seed may appear twice), and
/// writes the same four files into `dir`, which must not be one of them. More sets pin the
/// detection against size, the coverage and the usual residual better than any one study.
std::string scoreStudies(const std::filesystem::path& dir, const std::vector<std::filesystem::path>& studies);

/// Sets the same plan's sets diagnosed under several splits (one study folder per split) side by
/// side: how many are named alike under every split, each effect named under every split, some or
/// none, labels where nothing was hidden under any split, and each split's exact count and
/// coverage. Writes `dir`/splits.md and splits.json (dir must be none of the studies) and returns
/// the markdown. The studies must share plan and procedure and differ in their split.
std::string compareSplits(const std::filesystem::path& dir, const std::vector<std::filesystem::path>& studies);

} // namespace rosin::lab
