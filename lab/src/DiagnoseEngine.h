// The diagnosis's simulation engine (internal to lab/): measured and simulated stroke features,
// their per-stroke disagreement, and a cache of prepared voices per thread.
#pragma once
#include <Eigen/Core>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <functional>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "rosin/dsp.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Guettler.h"
#include "rosin/lab/Measurement.h"

namespace rosin::lab::diag {

struct StringInfo {
    double f0 = 0, beta = 0, z0 = 0, tension = 0, length = 0;
    /// The manifest's stated priors of tension and bow position (a fraction either way); unset:
    /// parameterBounds()'s.
    std::optional<double> tensionPrior, betaPrior;
    /// The string's Q at f0 and at 5 kHz as the manifest states them; unset: the model's own.
    std::optional<double> qAtF0, qAt5kHz;
    /// The string's c_t / c and torsional Q as the manifest states them; unset: the model's own.
    std::optional<double> torsionSpeedRatio, qTorsion;
    /// Each pair counts only whole (the manifest reader refuses half of one).
    bool statesQ() const { return qAtF0 && qAt5kHz; }
    bool statesTorsion() const { return torsionSpeedRatio && qTorsion; }
};

struct Prepared {
    std::string id;
    Gesture gesture;           ///< as the manifest states it (t = 0 at the gesture start)
    std::vector<double> force; ///< N at the diagnosis rate, t = 0 at the gesture start
    double noise = 0;          ///< rms noise of the recording (N), added to its simulations
    /// The least drop within 0.1 ms that is a first slip and not the rig's noise (N), for the
    /// recording and its simulations alike; unset: each signal's own estimate (noiseLevel).
    std::optional<double> slipFloor;
    StrokeFeatures feat;
};

constexpr double kCompareCutoff = 5000.0; // both signals see the same low-pass before comparison

/// Classifier input for a stroke of gesture g on string s: the bow speed follows the gesture, and
/// a rising-force stroke (which slides from the start) gives the shape of its pre-slip force.
ClassifierInput strokeInput(std::vector<double> f, double fs, const Gesture& g, const StringInfo& s);
/// True when the list of effects (or names) v holds x.
inline bool has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }
/// x printed with the printf format f, for the report's sentences and tables and the figures' data.
inline std::string fmt(double x, const char* f = "%.3g")
{
    char b[64];
    std::snprintf(b, sizeof b, f, x);
    return b;
}

/// Noise of a low-passed recording: the robust spread of its sample-to-sample steps.
double noiseLevel(const std::vector<double>& f);
/// Features of a stroke's force f. A first slip must drop the force within 0.1 ms by 2 % of the bow
/// force and by `slipFloor` (N); unset, by six times f's own noiseLevel() after the low-pass.
StrokeFeatures features(std::vector<double> f, double fs, const Gesture& g, const StringInfo& s, std::optional<double> slipFloor = std::nullopt);
/// Lag-0.1 ms second differences of the rest before a gesture (N at rate fs), low-passed as the
/// comparison is and away from the segment's ends: the rig's noise alone, any drift cancelled.
/// Empty when the rest is too short (under about 3 ms).
std::vector<double> restDifferences(std::vector<double> rest, double fs);
/// The rig's noise as the white noise (rms, N) at rate fs that, low-passed and differenced as
/// restDifferences() does, spreads as `differences` do: what the simulations must carry so
/// that they and the recordings meet the comparison's low-pass with the same noise.
double whiteNoiseOfRests(const std::vector<double>& differences, double fs);
/// Six standard deviations of the fall that noise alone makes over 0.1 ms, from rest differences:
/// at that lag (the low-pass's first correlation zero) their spread is sqrt(3) times the fall's.
double slipFloorOf(std::vector<double> differences);
/// Per-part disagreement of simulated features s with measured m, for a stroke of gesture g: the
/// waveform is measured against the flyback the bow speed at the measured first slip would give.
/// The parts carry `weights` (DiagnoseOptions::metricWeights) into their total().
ErrorParts compare(const StrokeFeatures& m, const StrokeFeatures& s, const Gesture& g, const StringInfo& info,
                   const std::array<double, 5>& weights = ErrorParts::kWeights);
double mean(const std::vector<ErrorParts>& e);
/// The metric's first four parts with their signs (simulated - measured, scaled and weighted as
/// in the metric, not capped): what a linearised fit can take up. Zero where a stroke has no slip.
std::array<double, 4> signedParts(const StrokeFeatures& m, const StrokeFeatures& s, const Gesture& g,
                                  const std::array<double, 5>& weights = ErrorParts::kWeights);
inline double median(std::vector<double> v)
{
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

/// A rosin shift and the bow side's effusivity look alike in Guettler strokes: a shift of s K
/// fits about as well as an effusivity scale 1 + s / kShiftPerEffusivity with r_A free (measured
/// on study sets: 13-22 K per unit; docs/diagnosis.md).
constexpr double kShiftPerEffusivity = 18.0;
/// The report's paragraph saying so, with the shift the calibrated effusivity could equally be;
/// empty when the effusivity was not calibrated or a shift is in the final model.
std::string shiftOrEffusivityNote(const Diagnosis& d);
/// The value a parameter takes where its effect is absent, in words ("" when it has none).
std::string noEffectValue(const std::string& name);
/// True when the reported 95 % interval (statistical, rig unknowns and the studies' model
/// discrepancy) stays clear of the no-effect value; parameters without one count as clear.
bool clearOfNoEffect(const Finding& f, const std::string& name);
/// The c_t / c the lab's models take for a rolling string (the data do not fix it).
double assumedTorsionSpeedRatio();
/// A rolling string's softening of the bow point (rollingSoftening) in the lab's model at this
/// Z_t/Z_0, with the c_t / c the manifest states (unset: the model's own).
double softeningAt(double ztRatio, std::optional<double> statedSpeedRatio = std::nullopt);
/// A string that rolls readily (reference rigs draw Z_t/Z_0 1.2-8): the roll a model without
/// torsion is tried against as a rig unknown, whose softening a free ramp scale starts from and
/// which the reported scale's interval leaves room for when no torsion is named.
constexpr double kReadilyRollingZt = 2.0;
/// A named torsion's softening at its value and at the ends of its reported Z_t/Z_0 interval.
std::array<double, 3> rollingSofteningOf(const Finding& f, std::optional<double> statedSpeedRatio = std::nullopt);
/// What a finding's numbers can and cannot say beyond its table, in plain words for report.md:
/// a reported interval that reaches the no-effect value, and what a torsion's Z_t/Z_0 rests on.
std::string findingCaveats(const Finding& f, std::optional<double> statedSpeedRatio = std::nullopt);

/// A finding's evidence in plain words: which part of the comparison the extension mended most.
std::string describe(const std::string& effect, const std::vector<ErrorParts>& before, const std::vector<ErrorParts>& after,
                     const std::vector<std::size_t>& ids, const EffectModel& from, double errBefore, double errAfter);

/// A fit of one effect alone, made in the round that named it with another.
struct AloneFit {
    EffectModel model;
    std::vector<ErrorParts> val;
};
/// A finding's evidence and the validation errors it compares.
struct FindingEvidence {
    std::string text;
    double before = 0, after = 0;
};
/// The evidence for `effect`, one of the effects a round named together (`named`). Alone, it is
/// the round's start against its end. A candidate that brings thermal memory along (a rate law or
/// a rosin shift bends the thermal law) is told apart with the round's fit of thermal memory
/// alone: thermal memory from the round's start to that fit, the other effect from there to the
/// end, so each finding says what it added. A pair says what each of the two did alone.
FindingEvidence roundEvidence(const std::string& effect, const std::vector<std::string>& named, const std::map<std::string, AloneFit>& alone,
                              const std::vector<ErrorParts>& atStart, const std::vector<ErrorParts>& atEnd, const std::vector<std::size_t>& ids,
                              const EffectModel& from);

/// Step 1 of a diagnosis: every recording low-passed, cleaned (DC always; mains hum where most
/// recordings show it), its gesture start found from the pre-slip ramp, one scale for the set;
/// what was taken out goes into d.calibration, what had to be assumed into d.warnings.
/// The set's string: the manifest, completed from the cello D where it is silent (tension, length),
/// Z0 from them when the manifest does not give it.
StringInfo stringInfoOf(const MeasurementSet& set);
std::vector<Prepared> prepareStrokes(const MeasurementSet& set, const StringInfo& info, const DiagnoseOptions& o, Diagnosis& d);

/// What a lab never knows exactly and diagnosis fits as calibration, not as a finding.
struct Nuisance {
    std::string name;
    std::string meaning;     ///< what its value is, in the report's words
    bool thermalOnly = false; ///< matters only to a thermal model: free once thermal memory is in the model or the candidate
};
/// Every nuisance, in the order the fits append them.
const std::vector<Nuisance>& nuisances();
bool isNuisance(const std::string& p);
/// What a nuisance's value means, in the report's words.
std::string nuisanceMeaning(const std::string& p);

/// A rig property that neither the fits nor the metric can fix, set to one end of its prior:
/// the model gets `adds` and the fixed `params` (not fitted).
struct RigUnknown {
    std::string name;
    std::string setting;
    std::vector<std::string> adds;
    std::map<std::string, double> params;
};
/// The rig unknowns that matter to model m (the contact radius to a thermal model; torsion when
/// it is not in the model).
std::vector<RigUnknown> rigUnknowns(const EffectModel& m);

/// Quasi-static share of the bow's travel that deflects the string rather than rolling it: the
/// bow point's transverse stiffness T / (beta (1 - beta) L) in series with the torsional one,
/// Z_t c_t / (beta (1 - beta) L), so K_eff / K_transverse = 1 / (1 + Z_0 c / (Z_t c_t)); 1 without
/// torsion. The pre-slip ramps of a rolling string are that much softer.
double rollingSoftening(const dsp::BowedStringConfig& c);
/// A pre-slip ramp's slope, bridge force per bow travel T / (beta L), at a tension and bow
/// position off the manifest's (as scales of them) over the manifest string's.
double relativeRampSlope(double tensionScale, double betaScale);

class Engine;

/// One extension the diagnosis may try: the effects it adds and the parameters it fits.
struct Candidate {
    std::string effect;
    std::vector<std::string> adds, names;
    std::vector<double> lo, hi, start;
    std::size_t scanned = 0; ///< the grid covers the first `scanned` parameters (0: all); the rest start where they are
    std::vector<std::size_t> gridAlso; ///< further parameters (by index) the grid covers, though they are not the candidate's own
};

/// Bounds of every parameter any extension has (for the joint refit).
const std::map<std::string, std::pair<double, double>>& parameterBounds();
/// A parameter's search range for this set: parameterBounds(), except tension and bow position
/// where the manifest states how well it knows them.
std::pair<double, double> boundsOf(const std::string& name, const StringInfo& info);
/// False for a parameter no data can fix: h0 cancels out of the enhanced law when y(theta) is the
/// inversion of steady sliding (docs/diagnosis.md), so whatever curvature the chaotic errors show
/// along it is noise and its interval is its whole search range.
bool identifiable(const std::string& parameter);
/// A candidate adding `effect` with the given parameters, bounded by parameterBounds().
Candidate candidate(const std::string& effect, std::vector<std::string> names, std::vector<double> start);
/// The candidate with the model's nuisances, and the parameters of effects already named, free too.
Candidate withNuisances(Candidate c, const EffectModel& m);
/// True for an effect that exists only inside the thermal model (rate dependence, the rosin
/// shift): offered without thermal memory it brings it along, and thermal memory cannot be
/// taken out from under it.
bool needsThermal(const std::string& effect);
/// The extensions not yet in m (those that need thermal memory bring it along).
std::vector<Candidate> candidates(const EffectModel& m);
/// The effects of a candidate's name: one, or two joined by '+' (a pair tried together).
std::vector<std::string> membersOf(const std::string& effect);
/// The pairs of effects tried together when a round names nothing (DiagnoseOptions::tryPairs).
const std::vector<std::pair<std::string, std::string>>& pairedEffects();
/// One candidate adding both: a's parameters, then b's that a lacks (a shared r_A once).
Candidate together(const Candidate& a, const Candidate& b);
/// Where a pair's search starts from its two effects' own fits: everything a's fit has (the
/// shared r_A and the nuisances included), then b's own parameters from b's fit.
std::vector<double> startFromParts(const Candidate& pair, const Candidate& a, const std::vector<double>& xa, const Candidate& b,
                                   const std::vector<double>& xb);
/// The candidate candidates(m) offers under this name, a pair "a+b" built by together(); none
/// when m already has one of its effects.
std::optional<Candidate> offered(const EffectModel& m, const std::string& effect);
/// True when the fitted parameters put the effect at its own absence (a pair: either effect).
bool atNull(const std::string& effect, const std::map<std::string, double>& p);
/// True when one of the candidate's own identifiable parameters ends within 1 % of its search
/// range's edge (rule 2's edge condition: a stand-in pushed past what the candidate can express). h0 is not asked:
/// nothing fixes it, so it ends wherever the search drifted.
bool pinnedAtEdge(const Candidate& c, const std::vector<double>& x);
/// 1.96 standard deviations of the bootstrap refits for each of the candidate's own parameters;
/// the identifiable ones whose refits all came back to the estimate (a spread under 0.1 % of the
/// search range) are added to `returned`.
std::vector<double> bootstrapHalfWidths(const Candidate& c, const std::vector<std::vector<double>>& refits, std::set<std::string>& returned);
/// Rule 5: refits on the two drive halves agree when neither puts the effect at its absence and
/// every identifiable parameter of the candidate's own differs between them by at most twice its
/// bootstrap half-width plus a tenth of its search range. Empty when they agree; otherwise why
/// not: each parameter too far apart, with both values and the allowance, and a half that fits
/// no effect.
std::string halvesDisagreement(const Candidate& c, const std::vector<double>& low, const std::vector<double>& high,
                               const std::map<std::string, double>& bootstrapHalfWidth);
/// The coarse grid fit() starts from, as (parameter index, points) pairs: 7, 5 or 3 points on
/// each of the candidate's own identifiable parameters (by their number), 3 on each gridAlso
/// parameter. h0 gets none: its points would all give the same error.
std::vector<std::pair<std::size_t, int>> gridDimensions(const Candidate& c);
/// The model base with the candidate's effects added and its parameters set to x.
EffectModel apply(const EffectModel& base, const Candidate& c, const std::vector<double>& x);
/// The grid point a second refinement starts from (DiagnoseOptions::secondStart): the lowest error
/// among the points at least two grid steps from `best` along some dimension of `dims`; empty when
/// the grid has one dimension or no such point. `points` pairs each grid point's error with its
/// [0, 1]-scaled position.
std::vector<double> secondGridStart(const std::vector<std::pair<double, std::vector<double>>>& points, const std::vector<double>& best,
                                    const std::vector<std::pair<std::size_t, int>>& dims);
/// The candidate with tension and bow position searched within the set's own priors, wherever it
/// was built (every fit and every curvature step uses these bounds); a start, when given, is
/// clamped into them.
Candidate withinSetPriors(Candidate c, const StringInfo& info, std::vector<double>* start = nullptr);
/// Fits the candidate's parameters on the strokes `on`: a coarse grid, then COBYLA from its best point
/// (and, with `secondStart`, from secondGridStart() too, keeping the better end).
/// Tension and bow position are searched within boundsOf() the engine's set, whatever the candidate says.
std::vector<double> fit(const Engine& engine, const EffectModel& base, const Candidate& c, const std::vector<std::size_t>& on,
                        std::vector<double> start, int maxEval, double step, double* best = nullptr, bool scan = true, bool secondStart = false);
/// Rule 5's refits on the low- and high-drive halves of the fit strokes (subset()): each a whole
/// search of the candidate's own parameters (grid and COBYLA), the nuisances starting at the
/// estimate, so the halves' values do not depend on where the estimate stood.
std::vector<std::vector<double>> driveHalves(const Engine& engine, const EffectModel& base, const Candidate& c, const std::vector<std::size_t>& fitSet,
                                             const std::vector<Prepared>& strokes, const std::vector<double>& estimate, int maxEval);
/// Paired bootstrap of the mean of before - after: {mean, low, high} (95 %).
std::array<double, 3> pairedGain(const std::vector<ErrorParts>& before, const std::vector<ErrorParts>& after, int B, std::uint64_t seed);
/// True when [lo, hi] reaches the parameter's no-effect value.
bool intervalAtNull(const std::string& name, double lo, double hi);
/// The 95 % half-width the studies' model discrepancy adds to a parameter at `value` (0 where
/// the options give none): 1.96 standard deviations, a share of the value for r_A and zt_ratio.
double discrepancyHalfWidth(const DiagnoseOptions& o, const std::string& name, double value);
/// The half-width rule 4 judges a parameter at `value` by: its bootstrap refits' half-width and
/// the model discrepancy's, in quadrature (the interval the report prints, before the curvature,
/// the drive halves and the rig unknowns widen it).
double namingHalfWidth(const DiagnoseOptions& o, const std::string& name, double value, double bootstrapHalfWidth);
/// The weakest value rule 4 can name with the options' model discrepancy and no scatter at all:
/// the least |shift| (K), the largest Z_t/Z_0 or load exponent, the least p; none for parameters
/// without a no-effect value. The bootstrap's own width comes on top.
std::optional<double> nameableEdge(const DiagnoseOptions& o, const std::string& name);
/// "; with it no shift under 15.7 K, ... can be named, whatever the scatter": nameableEdge of every
/// parameter with a model discrepancy, in words for the report's rules ("" when none has one).
std::string nameableEdgesText(const DiagnoseOptions& o);
/// Rule 2's larger margin for a rosin shift over a rate law, in words ("" when it is no larger
/// than the naming threshold).
std::string shiftMarginText(const DiagnoseOptions& o);
/// Rule 4 asked again of an earlier finding after a later joint refit moved its parameters to
/// `now`: does the interval it was named with (the same bootstrap half-width around the new
/// value, widened by the model discrepancy as rule 4 widens it) reach the no-effect value?
bool movedToNull(const Finding& f, const std::map<std::string, double>& now, const DiagnoseOptions& o);
/// What the report held when a round's winner was kept, before the earlier findings were asked
/// again beside it: enough to undo the round whole if the winner fails rule 4 after all.
struct RoundStart {
    std::vector<Finding> findings;
    std::set<std::string> dropped;
    std::size_t trials = 0;
};
RoundStart roundStart(const Diagnosis& d, const std::set<std::string>& dropped);
/// Undo a round whose winner the data no longer prove: the earlier findings it displaced come back
/// with the values they had, the trial rows written since `start` go, and the winner's trial
/// (`winnerTrial`) is marked not kept with `verdict`, which then names any displaced finding that
/// stands again; its effects (`winnerEffects`) are not tried again. Returns the effects that had
/// been displaced and are back.
std::vector<std::string> undoRound(Diagnosis& d, std::set<std::string>& dropped, const RoundStart& start, std::size_t winnerTrial,
                                   const std::vector<std::string>& winnerEffects, const std::string& verdict);
/// How far `after` lies below `before`, as a share of `before` (0 when there is nothing to fall from).
double relativeFall(double before, double after);
/// Rule 2's comparisons of candidate `c` (fitted as `trial`) with the round's other candidates,
/// whose validation errors `roundValidation` holds by effect: one that brings thermal memory along
/// must fall below thermal memory alone, and a rate dependence or a rosin shift below the other,
/// each by `threshold` (the shares go into the trial), a shift below the rate law by
/// `shiftOverRateMargin` when that is larger; a shift beside a named rate law must not flip
/// round 1's sign. Returns the failed rule's verdict, or "" when the candidate passes.
std::string standInVerdict(Trial& trial, const Candidate& c, const std::map<std::string, double>& roundValidation,
                           const std::vector<std::string>& namedEffects, const std::vector<Trial>& trials, double threshold,
                           double shiftOverRateMargin);
/// A second start for a later round's torsion candidate: its own parameter where round 1 left it
/// on the baseline (the rest where the model has them), unless round 1 fitted no torsion there.
std::optional<std::vector<double>> roundOneStart(const std::vector<Trial>& trials, const Candidate& c);
/// A rosin shift fitted beside a named rate law, `shiftNow`, against round 1's shift candidate
/// (fitted before any rate law): true when round 1 asked for at least `least` kelvin of one sign
/// and the shift now has the other. Round 1's `trials` give that candidate; none, no flip.
bool shiftFlippedBesideRateLaw(const std::vector<Trial>& trials, double shiftNow, double least = 10.0);
/// The strokes of `from` in the upper (or lower) half of their gesture's drive (bow acceleration
/// for Guettler strokes); the median is taken per gesture kind, so a mixed set splits evenly.
/// (Halves by force would take away the lever arm a load exponent is measured on.)
std::vector<std::size_t> subset(const std::vector<std::size_t>& from, const std::vector<Prepared>& strokes, bool upper);
/// For each stroke of `from`: is its drive at or above the median of its gesture kind?
std::vector<bool> upperDriveHalf(const std::vector<std::size_t>& from, const std::vector<Prepared>& strokes);

/// Covariance of x by the local curvature: residuals r(x), Jacobian by central differences with
/// the given steps, s^2 (J^T J)^-1 with s^2 = |r|^2 / (n - p); unconstrained directions get a
/// huge variance instead of a made-up one.
Eigen::MatrixXd curvatureCovariance(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& residuals, const Eigen::VectorXd& x,
                                    const Eigen::VectorXd& steps);
/// The Gauss-Newton move of the parameters that takes up a change dr of the residuals, given their
/// Jacobian (directions without curvature do not move).
Eigen::VectorXd gaussNewtonShift(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& dr);
/// How far each rig unknown that matters to the final model would move its parameters `names`
/// (at x; central differences with `steps` on the strokes `on`).
std::vector<RigUnknownTrial> rigUnknownMoves(const Engine& engine, const EffectModel& final, const std::vector<std::string>& names,
                                             const Eigen::VectorXd& x, const Eigen::VectorXd& steps, const std::vector<std::size_t>& on);
/// parameter -> {move down, move up}: the largest move per property and side, properties in quadrature.
std::map<std::string, std::array<double, 2>> movesBySide(const std::vector<RigUnknownTrial>& trials);

/// 1.96 standard deviations of each of the candidate's parameters at x from the local curvature
/// on the strokes `on` (all its parameters free together; a direction without curvature gets a
/// huge width).
std::vector<double> curvatureHalfWidths(const Engine& engine, const EffectModel& base, const Candidate& c, const std::vector<double>& x,
                                        const std::vector<std::size_t>& on);
/// The final model's parameters, calibration and findings alike, get intervals from the local
/// curvature on the fit strokes (nuisances widened by the studies' calibration discrepancy), and
/// the findings the moves of the rig's unknowns.
void addCurvatureIntervals(Diagnosis& d, const Engine& engine, const EffectModel& current, const std::vector<std::size_t>& fitSet,
                           const StringInfo& info, const DiagnoseOptions& o, const std::function<void(const std::string&)>& say);
/// Each two-ended steady stroke's friction loop, measured and as `final` shows it (`scale` takes
/// the set's sensor units to newtons).
std::vector<LoopComparison> compareTwoEnded(const MeasurementSet& set, const StringInfo& info, const Engine& engine, const EffectModel& final,
                                            double scale, const DiagnoseOptions& o, const std::function<void(const std::string&)>& say);

/// The rig's steady-sliding curve from its steady_sliding.csv: the SW00 shape with four factors
/// (level, the two speed scales, the high-speed floor) by Levenberg-Marquardt on relative residuals.
struct SteadyFitResult {
    dsp::SteadyCurve curve;
    double muStatic = 0, muStaticSd = 0, rms = 0;
};
SteadyFitResult fitSteadySliding(const std::vector<SteadySlidingPoint>& pts);

class Engine {
public:
    /// The strokes must keep their length and noise level while the engine lives. `scaleFromRamps`:
    /// the recordings' scale was taken from their pre-slip ramps assuming a string that does not roll.
    Engine(std::vector<Prepared>& strokes, const StringInfo& info, double fs, std::optional<dsp::SteadyCurve> steady,
           bool scaleFromRamps = false, const std::array<double, 5>& metricWeights = ErrorParts::kWeights);

    /// The voice of model m: its effects, the set's steady-sliding curve and the nuisances.
    dsp::BowedStringConfig config(const EffectModel& m) const;
    double beta(const EffectModel& m) const;
    /// The recordings' scale was read from their pre-slip ramps (a set in volts).
    bool scaleFromRamps() const { return scaleFromRamps_; }
    /// How much softer than a non-rolling string's model m's ramps are: its own roll's
    /// rollingSoftening(); 1 when the scale did not come from the ramps. A voice's recorded gain
    /// is its inverse.
    double rampSoftening(const EffectModel& m, const dsp::BowedStringConfig& c) const;
    double rampSoftening(const EffectModel& m) const { return rampSoftening(m, config(m)); }
    /// Simulated features of stroke i under model m as the rig would record them: the
    /// recording's own noise level is added (from a fixed seed per stroke, so a fit sees a
    /// smooth objective) and the first slip is found as in a recording. Force and acceleration
    /// are scaled by (1 + jitterF), (1 + jitterA) for the floor's re-runs, which also take
    /// another noise seed; optionally the first 12 periods (without noise).
    StrokeFeatures simulate(const EffectModel& m, std::size_t i, std::vector<double>* head = nullptr, double jitterF = 0.0,
                            double jitterA = 0.0, std::uint64_t noiseSeed = 0) const;
    std::vector<ErrorParts> errors(const EffectModel& m, const std::vector<std::size_t>& which) const;
    /// signedParts of every stroke in `which`, one after the other.
    Eigen::VectorXd signedResiduals(const EffectModel& m, const std::vector<std::size_t>& which) const;
    long long simulations() const { return simulations_.load(); }
    const StringInfo& info() const { return info_; }
    const std::array<double, 5>& metricWeights() const { return weights_; }

private:
    struct Voice {
        EffectModel model;
        std::unique_ptr<dsp::BowedString<double>> string;
        double gain = 1.0; ///< 1 / rampSoftening() of the model, taken when the voice is prepared
    };
    std::vector<Prepared>& strokes_;
    StringInfo info_;
    double fs_;
    std::optional<dsp::SteadyCurve> steady_;
    bool scaleFromRamps_ = false;
    std::array<double, 5> weights_;
    /// Each stroke's own noise (seed 0), drawn once: every evaluation adds the same to that stroke.
    std::vector<std::vector<double>> noise_;
    mutable std::atomic<long long> simulations_{0};
    mutable tbb::enumerable_thread_specific<Voice> voices_;
};

/// The residual against the usual one (DiagnoseOptions::usualResidualRatio), in words.
std::string usualResidualText(const Residual& r);
/// The floor of the test strokes (the final model against itself under the rig's scatter and
/// noise) and what the final model leaves above it: which parts, where, and what it looks like.
Residual measureResidual(const Engine& engine, const EffectModel& current, const std::vector<std::size_t>& testSet,
                         const std::vector<ErrorParts>& currentTest, const std::vector<Prepared>& strokes, const DiagnoseOptions& o);
/// Rule 6: beside a residual beyond the usual one, a rate law, a rosin shift or a rolling string
/// moves to d.standIns (the model lacks something, and a further bend of the thermal law or a
/// softer bow point can take its place); thermal memory and a contact law stay named. Returns
/// how many were set aside.
std::size_t setAsideStandIns(Diagnosis& d);
/// Rule 6 in words, with the usual ratio it applies beyond, for the report's rules.
std::string standInRuleText(double usualRatio);

/// The Guettler maps of the gesture a diagnosis shows (its Guettler strokes when it has them, else
/// its commonest kind), as report.md describes them.
struct ShownMaps {
    std::string gesture;
    SweepResult measured, baseline, final;
};

/// maps.png, overlays.png, jumps.png and strokes.csv (the maps' data) into dir.
ShownMaps writeStrokeFigures(const std::filesystem::path& dir, const Diagnosis& d);

/// loops.png: each two-ended stroke's friction against bow-point velocity, measured and final.
void writeLoopsFigure(const std::filesystem::path& file, const Diagnosis& d);

} // namespace rosin::lab::diag
