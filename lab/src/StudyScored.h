// One scored set of a study (its truth beside its diagnosis), read from its folder, and the
// figure of a study's sets: what StudyScore.cpp's tables are made from. Internal to lab/.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "rosin/lab/Diagnose.h"

namespace rosin::lab::scoring {

inline bool has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }

/// How far an effect is from its own absence, for detection against size (thermal memory has
/// no such value: the thermal law is a different law, not a parameter's end).
double effectSize(const std::string& effect, const std::map<std::string, double>& truth);
/// The unit effectSize() is in, for tables and legends.
const char* sizeName(const std::string& effect);

/// The tolerances issue 20 asks of a named parameter (relative where marked).
struct Tolerance {
    double value;
    bool relative;
};
const std::map<std::string, Tolerance>& tolerances();

/// Nulls from which the usual residual is their 95th percentile rather than their largest.
inline constexpr std::size_t kNullsForPercentile = 20;
/// The usual residual that null sets' final errors over floor (sorted, not empty) measure: their
/// 95th percentile by nearest rank, the ceil(0.95 n)-th smallest, which is the largest for
/// fewer than twenty.
double usualResidualOf(const std::vector<double>& sortedNullOverFloor);

struct Scored {
    int index = 0;
    std::string study; ///< the study folder's name, when several studies are scored together
    std::uint64_t seed = 0;
    std::vector<std::string> hidden, found;
    std::map<std::string, double> truth;
    std::map<std::string, std::array<double, 3>> estimate; ///< value, ci low, ci high
    /// round 1's reading of each physical parameter, from its own effect's candidate, named or not
    std::map<std::string, double> firstReading;
    /// the interval without the drive halves' refits (bootstrap and curvature only), where given
    std::map<std::string, std::array<double, 2>> withoutHalves;
    /// the statistical interval (bootstrap, curvature, drive halves), and that with the rig
    /// unknowns' moves added: the reported one less the model discrepancy, where given
    std::map<std::string, std::array<double, 2>> statistical, withRig;
    std::set<std::string> unidentified; ///< reported as not identified: interval = search range
    std::map<std::string, std::array<double, 3>> calibration; ///< nuisance -> value, ci low, ci high
    std::map<std::string, std::array<double, 2>> calibrationCurvature; ///< nuisance -> its curvature interval alone, where given
    /// fitted nuisances whose reported interval is the curvature's alone: diagnosed before the
    /// calibration discrepancy widened it (no ci95_curvature beside it)
    std::set<std::string> calibrationNotWidened;
    std::map<std::string, double> rig;
    double baseline = 0, final = 0;
    bool unexplained = false;
    bool beyondUsual = false;  ///< the residual is above the usual ratio the diagnosis compared it with
    bool firmlyBeyondUsual = false; ///< ... and above kFirmlyBeyondUsual times it (the report's "the rig has something the model lacks")
    std::vector<std::string> standIns; ///< effects set aside beside a residual beyond the usual one (rule 6): not named
    double overFloor = 0;      ///< the final error over the set's noise-and-chaos floor
    std::string units;         ///< "V" or "N" as the diagnosis read the set ("" when it does not say)
    /// how the diagnosis dealt the strokes into fit, validation and test (split.json's "method";
    /// diagnoses from before the stratified split have no method and were all "random")
    std::string splitMethod = "random";
    std::uint64_t splitSeed = 0; ///< split.json's seed (0 where the diagnosis wrote none)
    std::map<std::string, bool> search; ///< diagnosis.json's search switches (empty: not recorded)
    std::array<double, 5> metricWeights = ErrorParts::kWeights; ///< diagnosis.json's metric weights
};

/// Whether named parameter p's reported 95 % interval holds its truth; nothing where the set does
/// not count toward coverage: p not hidden or not estimated, its effect not named, or p reported
/// as not identified (an interval as wide as the search range holds any truth and says nothing).
std::optional<bool> truthInInterval(const Scored& s, const std::string& p);

/// A study's set folders (DIR/sets/NNN) that hold both a truth and a diagnosis, in order;
/// throws naming `study` when it has no sets/ folder.
std::vector<std::filesystem::path> diagnosedSetFolders(const std::filesystem::path& study);
/// One set's truth and diagnosis, as the scoring needs them (`f` is DIR/sets/NNN).
Scored readScored(const std::filesystem::path& f);
/// study.png: detection and false positives per effect, and detection against effect size.
void drawFigure(const std::filesystem::path& file, const std::vector<Scored>& sets);

} // namespace rosin::lab::scoring
