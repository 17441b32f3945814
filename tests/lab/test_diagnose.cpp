// rosin diagnose, consistency checks: the data come from dsp/'s own model (--generator model),
// the same model diagnosis fits, so the truth lies inside the model space. These say the
// machinery works; they do not say the diagnosis is right about data it did not make (that is
// test_diagnose_reference.cpp).
#include <gtest/gtest.h>
#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "rosin/dsp.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/Resample.h"
#include "rosin/lab/SynthData.h"

#include <Eigen/QR>

#include "DiagnoseEngine.h" // lab/src: the Gauss-Newton move behind the rig unknowns
#include "DiagnoseRounds.h" // lab/src: the naming rounds and the rules they print

using namespace rosin::lab;
namespace fs = std::filesystem;

namespace {
struct Case {
    std::vector<std::string> effects;
    std::uint64_t seed;
    double rate = 48000;
    bool gaussian = false;
    bool torsionMayHide = false; ///< the long run: a set with torsion may name less, never more
};

/// The candidate offered for `effect`, if one is.
std::optional<diag::Candidate> offered(const std::vector<diag::Candidate>& cands, const std::string& effect)
{
    for (const auto& c : cands)
        if (c.effect == effect) return c;
    return std::nullopt;
}

/// A model-made set, written to disk and read back as the CLI would read it.
MeasurementSet modelSetFromDisk(const SynthSpec& spec, SynthTruth& truth)
{
    const fs::path dir = fs::temp_directory_path() / ("rosin-diag-" + std::to_string(::getpid()) + "-" + std::to_string(spec.seed));
    fs::remove_all(dir);
    fs::create_directories(dir);
    writeMeasurementSet(dir / "set", synthesize(spec, truth), SF_FORMAT_PCM_24);
    MeasurementSet set = readMeasurementSet(dir / "set");
    fs::remove_all(dir);
    return set;
}

/// A model-made 4x4 set's strokes, prepared as a diagnosis prepares them (its truth in `truthOut`
/// when given).
std::vector<diag::Prepared> preparedModelSet(std::vector<std::string> effects, std::uint64_t seed, diag::StringInfo& info, Diagnosis& d,
                                             SynthTruth* truthOut = nullptr)
{
    SynthSpec spec;
    spec.effects = std::move(effects);
    spec.seed = seed;
    spec.grid = 4;
    SynthTruth truth;
    const MeasurementSet set = modelSetFromDisk(spec, truth);
    if (truthOut) *truthOut = truth;
    info = diag::stringInfoOf(set);
    return diag::prepareStrokes(set, info, DiagnoseOptions{}, d);
}

/// Seed 27's model-made 4x4 set with a Hertzian contact hidden, prepared, with an engine on its
/// strokes, the first round's contact candidate and every stroke's index (the engine holds the
/// strokes by reference, so the set is built in place and not copied).
struct ContactModelSet {
    diag::StringInfo info;
    Diagnosis d;
    SynthTruth truth;
    std::vector<diag::Prepared> strokes = preparedModelSet({"hertzian_contact"}, 27, info, d, &truth);
    const DiagnoseOptions o;
    const diag::Engine engine{strokes, info, o.simRate, std::nullopt, false};
    const std::optional<diag::Candidate> contact = offered(diag::candidates(EffectModel{}), "hertzian_contact");
    std::vector<std::size_t> all = everyIndex(strokes.size());

    ContactModelSet() = default;
    ContactModelSet(const ContactModelSet&) = delete;
    ContactModelSet& operator=(const ContactModelSet&) = delete;

private:
    static std::vector<std::size_t> everyIndex(std::size_t n)
    {
        std::vector<std::size_t> i(n);
        std::iota(i.begin(), i.end(), std::size_t{0});
        return i;
    }
};

/// The case's 8x8 model-made set, from disk, diagnosed as the CLI would.
Diagnosis diagnoseModelSet(const Case& k, SynthTruth& truth)
{
    SynthSpec spec;
    spec.effects = k.effects;
    spec.seed = k.seed;
    spec.grid = 8;
    spec.outRate = k.rate;
    spec.gaussianReflections = k.gaussian;
    DiagnoseOptions o;
    o.seed = 5;
    return diagnose(modelSetFromDisk(spec, truth), o);
}

void check(const Case& k, Diagnosis* diagnosed = nullptr)
{
    SynthTruth truth;
    const Diagnosis d = diagnoseModelSet(k, truth);
    if (diagnosed) *diagnosed = d;

    std::vector<std::string> found;
    for (const auto& f : d.findings) found.push_back(f.effect);
    std::vector<std::string> want = truth.effects;
    std::sort(found.begin(), found.end());
    std::sort(want.begin(), want.end());
    std::string got;
    for (const auto& t : d.trials) got += " [" + std::to_string(t.round) + " " + t.effect + " " + std::to_string(t.gain) + "]";
    if (k.torsionMayHide && std::find(want.begin(), want.end(), "torsional_compliance") != want.end()) {
        // Torsional compliance is the diagnosis's known gap (docs/diagnosis-study.md): on these
        // 8x8 sets its gain often stays below the naming rules, and while it is unnamed an effect
        // beside it may be too. What must hold: nothing is named that was not hidden.
        for (const auto& f : found) EXPECT_NE(std::find(want.begin(), want.end(), f), want.end()) << f << " named, not hidden (seed " << k.seed << ")";
        if (found != want) return;
    } else {
        ASSERT_EQ(found, want) << "seed " << k.seed << "; tried:" << got;
    }
    const std::map<std::string, std::pair<double, bool>> tolerance{{"load_exponent", {0.1, false}}, {"shift_k", {5.0, false}},
                                                                    {"zt_ratio", {0.30, true}}, {"r_A", {0.25, true}}};
    for (const auto& f : d.findings)
        for (const auto& [name, v] : f.parameters) {
            const auto tol = tolerance.find(name);
            if (tol == tolerance.end()) continue; // h0 and p: estimated, no tolerance asked
            const double t = truth.params.at(name);
            const double err = tol->second.second ? std::abs(v[0] / t - 1.0) : std::abs(v[0] - t);
            EXPECT_LE(err, tol->second.first) << name << " found " << v[0] << " hidden " << t << " (seed " << k.seed << ")";
        }
    // The systematic part of the intervals: the rig unknowns that matter to the final model, and
    // the model discrepancy where the options set one; both only widen the statistical interval.
    std::set<std::string> tried;
    for (const auto& t : d.rigUnknowns) {
        tried.insert(t.setting);
        for (const auto& [name, move] : t.moves) EXPECT_TRUE(std::isfinite(move)) << t.setting << " " << name;
    }
    const bool thermal = std::find(d.final.effects.begin(), d.final.effects.end(), "thermal_memory") != d.final.effects.end();
    const bool torsion = std::find(d.final.effects.begin(), d.final.effects.end(), "torsional_compliance") != d.final.effects.end();
    std::set<std::string> expected;
    if (!d.findings.empty() && thermal) expected.insert({"contact radius 150 um", "contact radius 350 um"});
    if (!d.findings.empty() && !torsion) expected.insert("torsion at Z_t/Z_0 = 2");
    EXPECT_EQ(tried, expected);
    for (const auto& f : d.findings)
        for (const auto& [name, v] : f.parameters) {
            const auto [sLo, sHi] = statisticalInterval(f, name);
            const auto [lo, hi] = reportedInterval(f, name);
            EXPECT_LE(lo, sLo) << name;
            EXPECT_GE(hi, sHi) << name;
            // the calibration pooled over seeds 2038-2040: a share of the value for r_A and
            // zt_ratio, an absolute standard deviation for the others (h0 carries none)
            const std::map<std::string, double> halfwidth{{"r_A", 1.96 * 0.064 * std::abs(v[0])}, {"zt_ratio", 1.96 * 0.53 * std::abs(v[0])},
                                                          {"p", 1.96 * 0.073}, {"load_exponent", 1.96 * 0.018}, {"shift_k", 1.96 * 8.0}};
            if (halfwidth.count(name)) {
                EXPECT_NEAR(f.discrepancy.at(name), halfwidth.at(name), 1e-12) << name;
            } else {
                EXPECT_FALSE(f.discrepancy.count(name)) << name;
            }
        }
    if (!want.empty()) {
        EXPECT_GT(d.gainLow, 0.0) << "held-out gain CI " << d.gainLow << ".." << d.gainHigh;
        EXPECT_LT(d.finalError, d.baselineError);
    } else {
        EXPECT_EQ(d.finalError, d.baselineError);
    }
    // The unknown gain of a volt-calibrated set comes back from the physics, the report gives it
    // once, and its interval (the ramps' spread and the priors of tension and bow position) holds it.
    EXPECT_NEAR(d.scale * truth.gain, 1.0, 0.05);
    const auto scale = std::find_if(d.calibration.begin(), d.calibration.end(), [](const CalibrationValue& c) { return c.name == "scale_n_per_unit"; });
    ASSERT_NE(scale, d.calibration.end());
    EXPECT_EQ(scale->value, d.scale);
    EXPECT_LE(scale->low, 1.0 / truth.gain);
    EXPECT_GE(scale->high, 1.0 / truth.gain);
    // Without a named torsion the low end leaves room for a roll no model named (Z_t/Z_0 = 2, the
    // rig unknown's); a named torsion has taken its own softening into the value instead.
    const bool roomForARoll = scale->meaning.find("a roll of Z_t/Z_0 = 2 that no model named") != std::string::npos;
    EXPECT_EQ(roomForARoll, !torsion) << scale->meaning;
    if (!torsion) {
        EXPECT_LE(scale->low, d.scale * diag::softeningAt(diag::kReadilyRollingZt) * (1.0 + 1e-12));
    }
}
} // namespace

// The split. Random: the whole set shuffled (as every diagnosis before 2026-12-05 dealt it).
// Stratified: on a 12x12 Guettler grid every acceleration and every force gives the test and
// the validation strokes 3 of its 12, within one, where a shuffle gives some row 6 or more on
// most seeds; a mixed set gives each gesture its share. Both are fixed by the seed, disjoint and
// complete, and a set too small for three sets is refused naming it.
TEST(DiagnoseSplit, AStratifiedSplitGivesEveryRowAndColumnOfThePlaneItsShare)
{
    std::vector<StrokePlace> grid;
    for (int a = 0; a < 12; ++a)
        for (int f = 0; f < 12; ++f) grid.push_back({"guettler", 0.15 + 0.26 * a, 0.15 + 0.26 * f});
    auto worstRow = [&](const std::vector<std::size_t>& ids, bool byForce) {
        std::map<double, int> count;
        for (const auto& p : grid) count[byForce ? p.force : p.drive] = 0;
        for (auto i : ids) ++count[byForce ? grid[i].force : grid[i].drive];
        int worst = 0;
        for (const auto& [value, c] : count) worst = std::max(worst, std::abs(c - 3));
        return worst;
    };
    int shuffledRowsOff = 0;
    for (std::uint64_t seed = 1; seed <= 60; ++seed) {
        DiagnoseOptions o;
        o.seed = seed;
        o.stratifiedSplit = true;
        const StrokeSplit s = splitStrokes(grid, o, "grid");
        ASSERT_EQ(s.test.size(), 36u);
        ASSERT_EQ(s.validation.size(), 36u);
        ASSERT_EQ(s.fit.size(), 72u);
        std::set<std::size_t> all(s.fit.begin(), s.fit.end());
        all.insert(s.validation.begin(), s.validation.end());
        all.insert(s.test.begin(), s.test.end());
        EXPECT_EQ(all.size(), 144u);
        EXPECT_TRUE(std::is_sorted(s.validation.begin(), s.validation.end()));
        for (bool byForce : {false, true}) {
            EXPECT_LE(worstRow(s.test, byForce), 1) << "seed " << seed;
            EXPECT_LE(worstRow(s.validation, byForce), 1) << "seed " << seed;
        }
        const StrokeSplit again = splitStrokes(grid, o, "grid");
        EXPECT_EQ(again.validation, s.validation);
        o.stratifiedSplit = false;
        const StrokeSplit shuffled = splitStrokes(grid, o, "grid");
        EXPECT_EQ(shuffled.validation.size(), 36u);
        if (std::max(worstRow(shuffled.validation, false), worstRow(shuffled.validation, true)) >= 3) ++shuffledRowsOff;
    }
    EXPECT_GE(shuffledRowsOff, 30); // what the stratified split is for
    DiagnoseOptions o;
    o.stratifiedSplit = true;
    const auto first = splitStrokes(grid, o, "grid").validation;
    o.seed = 2;
    EXPECT_NE(splitStrokes(grid, o, "grid").validation, first);
    // A mixed set: 32 Guettler strokes and 16 rising-force ones; each gesture gives a quarter to validation.
    std::vector<StrokePlace> mixed;
    for (int k = 0; k < 32; ++k) mixed.push_back({"guettler", 0.2 * (k % 8), 0.3 * (k / 8)});
    for (int k = 0; k < 16; ++k) mixed.push_back({"exp_force", 0.1 * k, 1.0});
    const StrokeSplit m = splitStrokes(mixed, o, "mixed");
    const auto risingInValidation = std::count_if(m.validation.begin(), m.validation.end(), [](std::size_t i) { return i >= 32; });
    EXPECT_EQ(m.validation.size(), 12u);
    EXPECT_NEAR(static_cast<double>(risingInValidation), 4.0, 1.0);
    std::vector<StrokePlace> tiny(grid.begin(), grid.begin() + 13);
    try {
        splitStrokes(tiny, o, "tiny-set");
        FAIL() << "a set of 13 strokes was split";
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("tiny-set: too few strokes"), std::string::npos) << e.what();
    }
}

// The rig unknowns' moves: the least-squares change of the parameters that takes up a change of
// the signed residuals. On a linear problem it is exact; a direction the residuals do not feel
// (no curvature) does not move, rather than by a made-up amount.
TEST(DiagnoseSystematic, TheGaussNewtonMoveUndoesALinearChangeAndLeavesFlatDirections)
{
    Eigen::MatrixXd J(5, 3);
    J << 1.0, 0.5, 0.0, 0.2, -1.0, 0.0, 0.7, 0.3, 0.0, -0.4, 2.0, 0.0, 1.5, 0.1, 0.0;
    const Eigen::Vector3d change(0.03, -0.01, 0.0);
    const Eigen::VectorXd move = diag::gaussNewtonShift(J, J * change);
    EXPECT_NEAR(move[0], -0.03, 1e-12);
    EXPECT_NEAR(move[1], 0.01, 1e-12);
    EXPECT_EQ(move[2], 0.0);
    // a change the parameters cannot express at all leaves them where they are
    Eigen::VectorXd orthogonal = Eigen::VectorXd::Zero(5);
    const Eigen::MatrixXd Q = J.leftCols(2).fullPivHouseholderQr().matrixQ();
    orthogonal = Q.col(3);
    EXPECT_LT(diag::gaussNewtonShift(J, orthogonal).norm(), 1e-12);
}

// Rule 4 asked again after a later round's joint refit moved an earlier finding: a shift named at
// 11 K with +-5 K that moved to 1.8 K now reaches 0 K; one that moved to 9 K does not. A load
// exponent named at 0.70 +-0.06 reaches 1 at 0.95, not at 0.90. Thermal memory has no no-effect
// value, and a parameter the refit did not report is not judged.
TEST(DiagnoseParameters, AnEarlierFindingMovedTowardNoEffectIsJudgedByTheIntervalItWasNamedWith)
{
    DiagnoseOptions bootstrapOnly;
    bootstrapOnly.modelDiscrepancy.clear();
    Finding shift;
    shift.effect = "rosin_temperature_shift";
    shift.parameters["shift_k"] = {11.0, 6.0, 16.0};
    EXPECT_TRUE(diag::movedToNull(shift, {{"shift_k", 1.8}, {"r_A", 0.9}}, bootstrapOnly));
    EXPECT_FALSE(diag::movedToNull(shift, {{"shift_k", 9.0}, {"r_A", 0.9}}, bootstrapOnly));
    EXPECT_TRUE(diag::movedToNull(shift, {{"shift_k", -3.0}}, bootstrapOnly));
    EXPECT_FALSE(diag::movedToNull(shift, {{"r_A", 0.9}}, bootstrapOnly));
    // as rule 4 now judges it: the shipped 8 K discrepancy widens the half-width to 16.5 K
    const DiagnoseOptions shipped;
    EXPECT_TRUE(diag::movedToNull(shift, {{"shift_k", 9.0}, {"r_A", 0.9}}, shipped));
    EXPECT_TRUE(diag::movedToNull(shift, {{"shift_k", 16.0}}, shipped));
    EXPECT_FALSE(diag::movedToNull(shift, {{"shift_k", 17.0}}, shipped));
    Finding contact;
    contact.effect = "hertzian_contact";
    contact.parameters["load_exponent"] = {0.70, 0.64, 0.76};
    EXPECT_TRUE(diag::movedToNull(contact, {{"load_exponent", 0.95}}, bootstrapOnly));
    EXPECT_FALSE(diag::movedToNull(contact, {{"load_exponent", 0.90}}, bootstrapOnly));
    EXPECT_FALSE(diag::movedToNull(contact, {{"load_exponent", 0.90}}, shipped)); // 0.90 + hypot(0.06, 0.035) < 1
    EXPECT_TRUE(diag::movedToNull(contact, {{"load_exponent", 0.935}}, shipped)); // 0.935 + 0.070 reaches 1
    EXPECT_FALSE(diag::movedToNull(contact, {{"load_exponent", 0.935}}, bootstrapOnly)); // 0.935 + 0.06 does not
    Finding thermal;
    thermal.effect = "thermal_memory";
    thermal.parameters["r_A"] = {1.0, 0.8, 1.2};
    EXPECT_FALSE(diag::movedToNull(thermal, {{"r_A", 0.01}}, shipped));
}

// A round undone after its winner failed rule 4 (at the joint refit, or refitted without an earlier
// finding it displaced): the displaced finding comes back with the values it had, the rows the
// round wrote while asking earlier findings again go, the winner's row says why it is not kept and
// what stands again, and the winner's effect is not tried again. Nothing else in the report moves.
TEST(DiagnoseParameters, AnUndoneRoundRestoresTheFindingsItDisplacedAndNamesNothing)
{
    Diagnosis d;
    Finding thermal, shift;
    thermal.effect = "thermal_memory";
    thermal.parameters["r_A"] = {1.02, 0.97, 1.07};
    shift.effect = "rosin_temperature_shift";
    shift.parameters["shift_k"] = {18.0, 14.0, 22.0};
    d.findings = {thermal, shift};
    for (int k = 0; k < 3; ++k) {
        Trial t;
        t.round = 3;
        t.effect = k == 1 ? "hertzian_contact" : "torsional_compliance";
        t.verdict = k == 1 ? "named" : "validation fall not significant";
        d.trials.push_back(t);
    }
    d.trials[1].kept = true;
    std::set<std::string> dropped = {"rate_dependence"};
    const diag::RoundStart start = diag::roundStart(d, dropped);
    EXPECT_EQ(start.trials, 3u);

    // the round drops the shift beside the contact and records it, and the contact moves on
    d.findings.pop_back();
    d.findings.front().parameters["r_A"] = {0.91, 0.86, 0.96};
    Trial row;
    row.round = 3;
    row.effect = "rosin_temperature_shift";
    row.verdict = "dropped: beside hertzian_contact it no longer lowers the validation error by the threshold";
    d.trials.push_back(row);
    dropped.insert("rosin_temperature_shift");

    const auto back = diag::undoRound(d, dropped, start, 1, {"hertzian_contact"}, "passed rules 1-5, then it failed rule 4");
    ASSERT_EQ(back, std::vector<std::string>{"rosin_temperature_shift"});
    ASSERT_EQ(d.findings.size(), 2u);
    EXPECT_EQ(d.findings[1].effect, "rosin_temperature_shift");
    EXPECT_DOUBLE_EQ(d.findings[1].parameters.at("shift_k")[0], 18.0);
    EXPECT_DOUBLE_EQ(d.findings[0].parameters.at("r_A")[0], 1.02);
    ASSERT_EQ(d.trials.size(), 3u);
    EXPECT_FALSE(d.trials[1].kept);
    EXPECT_EQ(d.trials[1].verdict, "passed rules 1-5, then it failed rule 4; the round is undone and rosin_temperature_shift, which it had "
                                   "displaced, stands again");
    EXPECT_EQ(d.trials[0].verdict, "validation fall not significant");
    EXPECT_EQ(dropped, (std::set<std::string>{"rate_dependence", "hertzian_contact"}));

    // undone before anything was displaced: the verdict is the one given, and nothing comes back
    Diagnosis plain;
    plain.trials.resize(2);
    plain.trials[0].kept = true;
    std::set<std::string> none;
    const auto nothing = diag::undoRound(plain, none, diag::roundStart(plain, none), 0, {"torsional_compliance", "hertzian_contact"}, "failed rule 4");
    EXPECT_TRUE(nothing.empty());
    EXPECT_EQ(plain.trials.size(), 2u);
    EXPECT_FALSE(plain.trials[0].kept);
    EXPECT_EQ(plain.trials[0].verdict, "failed rule 4");
    EXPECT_EQ(none, (std::set<std::string>{"torsional_compliance", "hertzian_contact"}));
}

// Round 1's shift candidate (before any rate law) against the shift fitted beside a named one:
// only a sign flip after a round-1 shift of 10 K or more counts.
TEST(DiagnoseParameters, AShiftThatFlipsSignBesideARateLawIsAStandIn)
{
    auto trial = [](int round, const std::string& effect, double shift) {
        Trial t;
        t.round = round;
        t.effect = effect;
        t.parameters = {{"shift_k", shift}, {"r_A", 1.2}};
        return t;
    };
    const std::vector<Trial> trials{trial(1, "rate_dependence", 0.0), trial(1, "rosin_temperature_shift", 24.0), trial(2, "rosin_temperature_shift", -26.5)};
    EXPECT_TRUE(diag::shiftFlippedBesideRateLaw(trials, -26.5));
    EXPECT_TRUE(diag::shiftFlippedBesideRateLaw(trials, -1.0));
    EXPECT_FALSE(diag::shiftFlippedBesideRateLaw(trials, 8.0)); // same sign: a shift the strokes kept asking for
    const std::vector<Trial> small{trial(1, "rosin_temperature_shift", 6.2)}; // below 10 K round 1 says little
    EXPECT_FALSE(diag::shiftFlippedBesideRateLaw(small, -7.5));
    EXPECT_TRUE(diag::shiftFlippedBesideRateLaw(small, -7.5, 5.0));
    const std::vector<Trial> negative{trial(1, "rosin_temperature_shift", -13.0)};
    EXPECT_TRUE(diag::shiftFlippedBesideRateLaw(negative, 11.0));
    EXPECT_FALSE(diag::shiftFlippedBesideRateLaw({trial(2, "rosin_temperature_shift", 24.0)}, -20.0)); // no round-1 candidate
}

// The usual residual is what about 19 in 20 nulls stay within (5 of 100 fresh ones passed 8.6, by up
// to 38 %): the report calls a residual just beyond it a hint, and only one past 1.3 times it
// something the rig has.
TEST(DiagnoseResidualText, JustBeyondTheUsualResidualIsAHintAndFarBeyondItAFinding)
{
    Residual r;
    r.usual = 8.6;
    const auto says = [&](double ratio) {
        r.ratio = ratio;
        return diag::usualResidualText(r);
    };
    const std::string within = says(8.0), hint = says(9.7), firm = says(11.5), edge = says(11.1);
    EXPECT_NE(within.find("within the model's usual difference"), std::string::npos) << within;
    EXPECT_NE(hint.find("a hint that this rig has something the model lacks, not a finding"), std::string::npos) << hint;
    EXPECT_EQ(hint.find("something on this rig the model lacks"), std::string::npos) << hint;
    EXPECT_NE(hint.find("8.6 times the floor on about nineteen in twenty; 9.7 times"), std::string::npos) << hint;
    EXPECT_NE(firm.find("something on this rig the model lacks"), std::string::npos) << firm;
    EXPECT_EQ(firm.find("a hint"), std::string::npos) << firm;
    EXPECT_NE(edge.find("a hint"), std::string::npos) << "11.1 is under 1.3 x 8.6 = 11.18: " << edge;
    r.usual = 0.0;
    EXPECT_EQ(says(30.0), "no usual residual was given to compare it with");
}

// A later round's torsion candidate is searched also from round 1's Z_t/Z_0 (the rest of the start
// as the model has it), and only when round 1 fitted some torsion on the baseline.
// Rule 6: beside a residual beyond the usual one, a rate law, a rosin shift and a torsion are set
// aside as possible stand-ins, with their parameters; thermal memory and a contact law stay.
// Within the usual one (or with no comparison) the findings stay as the rounds named them.
TEST(DiagnoseParameters, BesideAnUnusualResidualOnlyThermalMemoryAndAContactStayNamed)
{
    const auto finding = [](const std::string& effect, const std::string& name, double value) {
        Finding f;
        f.effect = effect;
        f.parameters[name] = {value, value - 1.0, value + 1.0};
        return f;
    };
    Diagnosis d;
    d.findings = {finding("thermal_memory", "r_A", 1.35), finding("rosin_temperature_shift", "shift_k", 25.0),
                  finding("hertzian_contact", "load_exponent", 0.7), finding("torsional_compliance", "zt_ratio", 1.4),
                  finding("rate_dependence", "p", 0.3)};
    d.residual.present = true;
    d.residual.ratio = 8.8;
    d.residual.usual = 8.6;
    Diagnosis within = d;
    EXPECT_EQ(diag::setAsideStandIns(within), 0u) << "beyond_usual not set: nothing moves";
    EXPECT_EQ(within.findings.size(), 5u);
    EXPECT_TRUE(within.standIns.empty());
    d.residual.beyondUsual = true;
    EXPECT_EQ(diag::setAsideStandIns(d), 3u);
    ASSERT_EQ(d.findings.size(), 2u);
    EXPECT_EQ(d.findings[0].effect, "thermal_memory");
    EXPECT_EQ(d.findings[1].effect, "hertzian_contact");
    ASSERT_EQ(d.standIns.size(), 3u);
    EXPECT_EQ(d.standIns[0].effect, "rosin_temperature_shift");
    EXPECT_EQ(d.standIns[0].parameters.at("shift_k")[0], 25.0);
    EXPECT_EQ(d.standIns[1].effect, "torsional_compliance");
    EXPECT_EQ(d.standIns[2].effect, "rate_dependence");
    EXPECT_EQ(diag::setAsideStandIns(d), 0u) << "applied twice, it moves nothing more";

    // What a user reads: diagnosis.json lists the stand-ins under the residual with their
    // intervals and keeps them out of the findings; report.md gives them a section and rule 6.
    d.rules = {"(6) beside an unusual residual ..."};
    const fs::path dir = fs::temp_directory_path() / ("rosin-standins-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    writeDiagnosis(dir, d, DiagnoseOptions{});
    nlohmann::json doc;
    std::ifstream(dir / "diagnosis.json") >> doc;
    ASSERT_EQ(doc["findings"].size(), 2u);
    EXPECT_EQ(doc["findings"][0]["effect"], "thermal_memory");
    EXPECT_EQ(doc["findings"][1]["effect"], "hertzian_contact");
    const auto& standIns = doc["unexplained_residual"]["stand_ins"];
    ASSERT_EQ(standIns.size(), 3u);
    EXPECT_EQ(standIns[0]["effect"], "rosin_temperature_shift");
    EXPECT_DOUBLE_EQ(standIns[0]["parameters"]["shift_k"]["value"].get<double>(), 25.0);
    EXPECT_EQ(standIns[0]["parameters"]["shift_k"]["ci95"].size(), 2u);
    EXPECT_TRUE(doc["unexplained_residual"]["beyond_usual"].get<bool>());
    std::ifstream in(dir / "report.md");
    const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(md.find("### Possible stand-ins (not named)"), std::string::npos) << md;
    EXPECT_NE(md.find("The rounds named rosin_temperature_shift, torsional_compliance and rate_dependence under rules 1-5"), std::string::npos) << md;
    EXPECT_NE(md.find("| rosin_temperature_shift | shift_k | 25 |"), std::string::npos) << md;
    EXPECT_EQ(md.find("### rosin_temperature_shift"), std::string::npos) << "a stand-in has no finding's section";
    EXPECT_NE(md.find("### thermal_memory"), std::string::npos);
    fs::remove_all(dir);
}

TEST(DiagnoseParameters, ALaterTorsionSearchAlsoStartsWhereRoundOneLeftItsZt)
{
    auto trial = [](int round, const std::string& effect, std::map<std::string, double> p) {
        Trial t;
        t.round = round;
        t.effect = effect;
        t.parameters = std::move(p);
        return t;
    };
    EffectModel named;
    named.effects = {"thermal_memory", "rate_dependence"};
    named.params = {{"r_A", 1.25}, {"h0", 0.75}, {"p", 0.68}, {"tension_scale", 0.98}, {"beta_scale", 1.02}, {"rod_effusivity_scale", 1.0}};
    const auto cands = diag::candidates(named);
    const auto torsion = offered(cands, "torsional_compliance");
    ASSERT_TRUE(torsion);
    const diag::Candidate c = diag::withNuisances(*torsion, named);
    ASSERT_EQ(c.names.front(), "zt_ratio");

    const std::vector<Trial> rolled{trial(1, "thermal_memory", {{"r_A", 1.35}}), trial(1, "torsional_compliance", {{"zt_ratio", 1.06}, {"tension_scale", 0.97}}),
                                    trial(2, "torsional_compliance", {{"zt_ratio", 7.9}})};
    const auto start = diag::roundOneStart(rolled, c);
    ASSERT_TRUE(start.has_value());
    ASSERT_EQ(start->size(), c.start.size());
    EXPECT_DOUBLE_EQ(start->front(), 1.06);
    for (std::size_t k = 1; k < c.start.size(); ++k) EXPECT_DOUBLE_EQ((*start)[k], c.start[k]) << c.names[k]; // r_A, p, nuisances as named

    EXPECT_FALSE(diag::roundOneStart({trial(1, "torsional_compliance", {{"zt_ratio", 7.6}})}, c).has_value()); // round 1 saw no torsion
    EXPECT_FALSE(diag::roundOneStart({trial(2, "torsional_compliance", {{"zt_ratio", 1.2}})}, c).has_value()); // not round 1's
    const auto contact = offered(cands, "hertzian_contact");
    ASSERT_TRUE(contact);
    EXPECT_FALSE(diag::roundOneStart({trial(1, "hertzian_contact", {{"load_exponent", 0.7}})}, diag::withNuisances(*contact, named)).has_value());
}

// Rule 2's edge condition and rule 5 (the drive halves) judge what the data fix. h0 cancels out of the enhanced law, so its value is
// wherever the search drifted: seed 2049's set 5 (p 0.48) had a rate law 57 % better refused
// because h0 ended on 1.2.
TEST(DiagnoseParameters, TheEdgeAndDriveHalvesRulesIgnoreTheUnidentifiedH0)
{
    diag::Candidate rate = diag::withNuisances(diag::candidate("rate_dependence", {"h0", "p"}, {0.563, 0.4}), {});
    ASSERT_EQ(rate.scanned, 2u);
    ASSERT_EQ(rate.names[0], "h0");
    std::vector<double> x = rate.start;
    x.resize(rate.names.size(), 1.0);
    x[0] = 1.2; // h0 on its upper bound
    x[1] = 0.55;
    EXPECT_FALSE(diag::pinnedAtEdge(rate, x));
    x[1] = 0.8 - 0.005; // p within 1 % of its range from its bound: a stand-in
    EXPECT_TRUE(diag::pinnedAtEdge(rate, x));
    x[1] = 0.8 - 0.008; // 1.1 % of 0.7 away
    EXPECT_FALSE(diag::pinnedAtEdge(rate, x));
    x[0] = 0.3;
    x[1] = 0.1 + 0.006; // just inside the lower edge of p
    EXPECT_TRUE(diag::pinnedAtEdge(rate, x));

    // The two halves: h0 may differ by its whole range; p may differ by twice its half-width plus
    // a tenth of its range (0.07), and neither half may put the effect at its absence (p < 0.12).
    const std::map<std::string, double> width{{"h0", 0.0}, {"p", 0.05}};
    std::vector<double> low = rate.start, high = rate.start;
    low.resize(rate.names.size(), 1.0);
    high.resize(rate.names.size(), 1.0);
    low[0] = 0.3, high[0] = 1.2;
    low[1] = 0.40, high[1] = 0.56; // 0.16 apart, 0.17 allowed
    EXPECT_EQ(diag::halvesDisagreement(rate, low, high, width), ""); // consistent
    high[1] = 0.58; // 0.18 apart
    // Refused, saying which parameter, both halves' values and what was allowed.
    EXPECT_EQ(diag::halvesDisagreement(rate, low, high, width), "p 0.4 on the low half, 0.58 on the high (0.18 apart, at most 0.17 allowed)");
    low[1] = 0.11, high[1] = 0.15; // close together, but the low half has no rate law
    EXPECT_EQ(diag::halvesDisagreement(rate, low, high, width), "the low half fits no effect");

    diag::Candidate contact = diag::withNuisances(diag::candidate("hertzian_contact", {"load_exponent"}, {0.8}), {});
    std::vector<double> y = contact.start;
    y.resize(contact.names.size(), 1.0);
    y[0] = 0.4;
    EXPECT_TRUE(diag::pinnedAtEdge(contact, y));
    y[0] = 0.66;
    EXPECT_FALSE(diag::pinnedAtEdge(contact, y));
}

// Seed 2060's set 15 on the stratified split: the later-round contact's 5x5 grid over (load
// exponent, r_A) had its best point at (1.03, 0.95), error 0.132, and the far end of the same
// diagonal valley at (0.75, 1.25), 0.134; COBYLA from the first stopped at the contact's absence.
// The second start is that far end, not the next-best point beside the first.
TEST(DiagnoseParameters, TheSecondStartIsTheBestGridPointTwoStepsAway)
{
    using Dims = std::vector<std::pair<std::size_t, int>>;
    const Dims dims{{0, 5}, {1, 5}};
    const auto at = [](int i, int j) { return std::vector<double>{(i + 0.5) / 5, (j + 0.5) / 5, 0.4}; }; // a third, ungridded parameter
    std::vector<std::pair<double, std::vector<double>>> grid;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) grid.push_back({0.5, at(i, j)});
    const auto set = [&](int i, int j, double e) { grid[static_cast<std::size_t>(i * 5 + j)].first = e; };
    set(4, 1, 0.1318); // exponent 1.03, r_A 0.95: the grid's best
    set(3, 1, 0.1362); // beside it, second best of all
    set(3, 2, 0.1400); // one step away along both
    set(2, 2, 0.1338); // the valley's far end
    set(0, 4, 0.1500);
    EXPECT_EQ(diag::secondGridStart(grid, at(4, 1), dims), at(2, 2));
    set(2, 2, 0.2000); // without that end, the best of what is two steps away
    EXPECT_EQ(diag::secondGridStart(grid, at(4, 1), dims), at(0, 4));
    // one gridded parameter: no second start (its best point already brackets the valley)
    EXPECT_TRUE(diag::secondGridStart(grid, at(4, 1), Dims{{0, 7}}).empty());
    // nothing two steps away on a 2x2 grid
    EXPECT_TRUE(diag::secondGridStart({{0.1, {0.25, 0.25}}, {0.2, {0.75, 0.75}}}, {0.25, 0.25}, Dims{{0, 2}, {1, 2}}).empty());
}

// The coarse grid spends its points on what the data fix. h0 cancels out of the enhanced law, so
// a grid along it repeats each error three times: round 1's 27 points over (r_A, h0, p) were nine
// distinct ones (seed 2050's set 8 was fitted at p 0.307 for 0.162 from that grid).
TEST(DiagnoseParameters, TheGridSpansOnlyParametersTheDataFix)
{
    using Dims = std::vector<std::pair<std::size_t, int>>;
    const EffectModel none;
    const auto first = diag::candidates(none);
    const auto rate = offered(first, "rate_dependence");
    ASSERT_TRUE(rate);
    const diag::Candidate rate1 = diag::withNuisances(*rate, none);
    ASSERT_EQ(rate1.names[0], "r_A");
    ASSERT_EQ(rate1.names[1], "h0");
    ASSERT_EQ(rate1.names[2], "p");
    EXPECT_EQ(diag::gridDimensions(rate1), (Dims{{0, 5}, {2, 5}})); // 25 points over (r_A, p), h0 at its start

    EffectModel thermal;
    thermal.effects = {"thermal_memory"};
    thermal.params = {{"r_A", 1.1}, {"tension_scale", 1.0}, {"beta_scale", 1.0}, {"rod_effusivity_scale", 1.0}};
    const auto later = diag::candidates(thermal);
    const auto rate2 = offered(later, "rate_dependence");
    ASSERT_TRUE(rate2);
    EXPECT_EQ(diag::gridDimensions(diag::withNuisances(*rate2, thermal)), (Dims{{1, 7}})); // seven over p alone
    const auto torsion = offered(later, "torsional_compliance");
    ASSERT_TRUE(torsion);
    EXPECT_EQ(diag::gridDimensions(diag::withNuisances(*torsion, thermal)), (Dims{{0, 5}, {1, 5}})); // Z_t/Z_0 and r_A

    // Thermal memory alone keeps its three points along the bow side's effusivity (gridAlso).
    const auto memory = offered(first, "thermal_memory");
    ASSERT_TRUE(memory);
    EffectModel calibrated;
    calibrated.params = {{"tension_scale", 1.0}, {"beta_scale", 1.0}};
    const diag::Candidate m = diag::withNuisances(*memory, calibrated);
    ASSERT_EQ(m.gridAlso.size(), 1u);
    EXPECT_EQ(diag::gridDimensions(m), (Dims{{0, 7}, {m.gridAlso[0], 3}}));
}

// Rule 5 asks whether the effect holds on the low- and the high-drive half of the fit strokes.
// Refitted from the estimate with a few COBYLA steps, both halves had ended within 0.1 % of it for
// 48 of 100 named parameters of two studies: the rule then asked the estimate, not the data.
// Each half is now a whole search, so where the estimate stood does not matter.
TEST(DiagnoseParameters, RuleFiveSearchesEachDriveHalfAfreshWhereverTheEstimateStood)
{
    ContactModelSet set;
    ASSERT_TRUE(set.contact);
    ASSERT_EQ(set.contact->names, std::vector<std::string>{"load_exponent"});
    const auto fromNoEffect = diag::driveHalves(set.engine, EffectModel{}, *set.contact, set.all, set.strokes, {1.05}, set.o.maxEvaluations);
    const auto fromFarBelow = diag::driveHalves(set.engine, EffectModel{}, *set.contact, set.all, set.strokes, {0.45}, set.o.maxEvaluations);
    ASSERT_EQ(fromNoEffect.size(), 2u);
    const double hidden = set.truth.params.at("load_exponent");
    for (std::size_t h = 0; h < 2; ++h) {
        EXPECT_EQ(fromNoEffect[h][0], fromFarBelow[h][0]) << "half " << h;
        EXPECT_NEAR(fromNoEffect[h][0], hidden, 0.1) << "half " << h;
    }
}

// Bootstrap refits that all come back to the estimate (seed 2081/25's and 2082/5's contacts after
// a restart: a spread of 2e-6) say where the search sticks, not what the data allow; rule 5 then
// allowed halves only a tenth of the range apart and refused load exponents of 0.67 and 0.62.
TEST(DiagnoseParameters, RefitsThatAllReturnToTheEstimateAreToldApartFromAFirmBootstrap)
{
    const diag::Candidate contact = diag::withNuisances(diag::candidate("hertzian_contact", {"load_exponent"}, {0.8}), {});
    ASSERT_EQ(contact.scanned, 1u);
    std::vector<std::vector<double>> refits(10, contact.start);
    for (auto& r : refits) r.resize(contact.names.size(), 1.0), r[0] = 0.668823;
    std::set<std::string> returned;
    auto width = diag::bootstrapHalfWidths(contact, refits, returned);
    ASSERT_EQ(width.size(), 1u);
    EXPECT_LT(width[0], 1e-9);
    EXPECT_EQ(returned, std::set<std::string>{"load_exponent"});

    // A spread of sd 0.01 is a measurement: 1.96 sd, not marked.
    const double offsets[10] = {-0.015, -0.01, -0.005, 0.0, 0.005, 0.01, 0.015, -0.0125, 0.0125, 0.0};
    for (std::size_t b = 0; b < refits.size(); ++b) refits[b][0] = 0.67 + offsets[b];
    returned.clear();
    width = diag::bootstrapHalfWidths(contact, refits, returned);
    double m = 0, v = 0;
    for (double o : offsets) m += o / 10.0;
    for (double o : offsets) v += (o - m) * (o - m) / 9.0;
    EXPECT_NEAR(width[0], 1.96 * std::sqrt(v), 1e-12);
    EXPECT_TRUE(returned.empty());

    // h0, which no data fix, is never marked, however still its refits stand.
    const diag::Candidate rate = diag::withNuisances(diag::candidate("rate_dependence", {"h0", "p"}, {0.6, 0.3}), {});
    std::vector<std::vector<double>> rateRefits(10, rate.start);
    for (std::size_t b = 0; b < rateRefits.size(); ++b) rateRefits[b].resize(rate.names.size(), 1.0), rateRefits[b][1] = 0.3 + 0.002 * static_cast<double>(b);
    returned.clear();
    diag::bootstrapHalfWidths(rate, rateRefits, returned);
    EXPECT_TRUE(returned.empty());
}

// The width those parameters take instead: the local curvature on the fit strokes, which narrows
// as strokes are added (about as one over their root) and stays well inside the search range.
TEST(DiagnoseParameters, TheRoundsCurvatureWidthNarrowsWithMoreStrokes)
{
    ContactModelSet set;
    ASSERT_TRUE(set.contact);
    std::vector<std::size_t> quarter;
    for (std::size_t i = 0; i < set.all.size(); i += 4) quarter.push_back(i);
    const std::vector<double> at{set.truth.params.at("load_exponent")};
    const double onAll = diag::curvatureHalfWidths(set.engine, EffectModel{}, *set.contact, at, set.all)[0];
    const double onQuarter = diag::curvatureHalfWidths(set.engine, EffectModel{}, *set.contact, at, quarter)[0];
    EXPECT_GT(onAll, 1e-3);
    EXPECT_LT(onAll, 0.1 * (set.contact->hi[0] - set.contact->lo[0]));
    // a quarter of the strokes: twice as wide for a smooth surface; between 1.3 and 4 times here
    EXPECT_GT(onQuarter, 1.3 * onAll);
    EXPECT_LT(onQuarter, 4.0 * onAll);
}

// A contact and a roll tried together (seed 2056's set 36: the roll alone fitted worse than no
// effect, the pair a third better than the contact alone): one candidate adding both, with the
// r_A both span once, a grid of three points on each of its three parameters, and at its own
// absence when either effect is.
TEST(DiagnoseParameters, AContactAndARollTriedTogetherShareOneRAAndAreAbsentWhenEitherIs)
{
    const std::string pair = "hertzian_contact+torsional_compliance";
    ASSERT_EQ(diag::pairedEffects().size(), 1u);
    EXPECT_EQ(diag::pairedEffects().front().first + "+" + diag::pairedEffects().front().second, pair);
    EXPECT_EQ(diag::membersOf(pair), (std::vector<std::string>{"hertzian_contact", "torsional_compliance"}));
    EXPECT_EQ(diag::membersOf("thermal_memory"), (std::vector<std::string>{"thermal_memory"}));

    EffectModel thermal;
    thermal.effects = {"thermal_memory"};
    thermal.params = {{"r_A", 1.1}, {"tension_scale", 1.0}, {"beta_scale", 1.0}, {"rod_effusivity_scale", 1.0}};
    const auto both = diag::offered(thermal, pair);
    ASSERT_TRUE(both);
    EXPECT_EQ(both->effect, pair);
    EXPECT_EQ(both->adds, (std::vector<std::string>{"hertzian_contact", "torsional_compliance"}));
    EXPECT_EQ(both->names, (std::vector<std::string>{"load_exponent", "r_A", "zt_ratio"}));
    EXPECT_EQ(both->start, (std::vector<double>{0.8, 1.1, 2.0}));
    EXPECT_DOUBLE_EQ(both->lo[2], 0.7);
    EXPECT_DOUBLE_EQ(both->hi[2], 8.0);
    const diag::Candidate c = diag::withNuisances(*both, thermal);
    EXPECT_EQ(c.scanned, 3u);
    using Dims = std::vector<std::pair<std::size_t, int>>;
    EXPECT_EQ(diag::gridDimensions(c), (Dims{{0, 3}, {1, 3}, {2, 3}}));
    // before thermal memory: no r_A, two parameters of five points each
    const auto bare = diag::offered(EffectModel{}, pair);
    ASSERT_TRUE(bare);
    EXPECT_EQ(bare->names, (std::vector<std::string>{"load_exponent", "zt_ratio"}));
    EXPECT_EQ(diag::gridDimensions(*bare), (Dims{{0, 5}, {1, 5}}));
    // once either is named the pair is not offered
    EffectModel contact = thermal;
    contact.effects.push_back("hertzian_contact");
    contact.params["load_exponent"] = 0.8;
    EXPECT_FALSE(diag::offered(contact, pair).has_value());
    EXPECT_TRUE(diag::offered(contact, "torsional_compliance").has_value());

    EXPECT_FALSE(diag::atNull(pair, {{"load_exponent", 0.82}, {"zt_ratio", 1.5}}));
    EXPECT_TRUE(diag::atNull(pair, {{"load_exponent", 0.98}, {"zt_ratio", 1.5}})); // Amontons
    EXPECT_TRUE(diag::atNull(pair, {{"load_exponent", 0.82}, {"zt_ratio", 7.4}})); // no roll
    std::vector<double> x(c.names.size(), 1.0);
    x[0] = 0.8, x[1] = 1.1, x[2] = 8.0 - 0.05; // Z_t/Z_0 within 1 % of its range from the top
    EXPECT_TRUE(diag::pinnedAtEdge(c, x));
    x[2] = 3.0;
    EXPECT_FALSE(diag::pinnedAtEdge(c, x));
}

// Rule 2's comparisons with the round's other candidates, in their order, with the shares written
// into the trial.
TEST(DiagnoseParameters, RuleTwoComparesARateLawAndAShiftWithThermalMemoryAloneAndWithEachOther)
{
    diag::Candidate shift;
    shift.effect = "rosin_temperature_shift";
    shift.adds = {"rosin_temperature_shift", "thermal_memory"};
    diag::Candidate rate = shift;
    rate.effect = "rate_dependence";
    rate.adds = {"rate_dependence", "thermal_memory"};
    auto trialOf = [](const std::string& effect, double shiftK) {
        Trial t;
        t.round = 2;
        t.effect = effect;
        t.parameters = {{"shift_k", shiftK}};
        return t;
    };
    // 0.20 alone, 0.18 with a shift: 10 % better; the rate law at 0.185: 2.7 % behind the shift
    Trial t = trialOf("rosin_temperature_shift", 12.0);
    EXPECT_EQ(diag::standInVerdict(t, shift, {{"thermal_memory", 0.20}, {"rosin_temperature_shift", 0.18}, {"rate_dependence", 0.185}}, {}, {}, 0.05, 0.0),
              "no better than rate_dependence (the data do not tell the two apart)");
    EXPECT_NEAR(t.overThermal, 0.10, 1e-12);
    EXPECT_NEAR(t.overRival, 0.005 / 0.185, 1e-12);
    // 0.191 with the shift is 4.5 % under 0.20 alone: the thermal rule fails first, the rival is not judged
    t = trialOf("rosin_temperature_shift", 12.0);
    EXPECT_EQ(diag::standInVerdict(t, shift, {{"thermal_memory", 0.20}, {"rosin_temperature_shift", 0.191}, {"rate_dependence", 0.30}}, {}, {}, 0.05, 0.0),
              "no better than thermal_memory alone");
    EXPECT_EQ(t.overRival, 0.0);
    // the rate law well ahead of both: passes, and its shares are recorded
    Trial r = trialOf("rate_dependence", 0.0);
    EXPECT_EQ(diag::standInVerdict(r, rate, {{"thermal_memory", 0.20}, {"rosin_temperature_shift", 0.18}, {"rate_dependence", 0.10}}, {}, {}, 0.05, 0.0), "");
    EXPECT_NEAR(r.overThermal, 0.5, 1e-12);
    EXPECT_NEAR(r.overRival, 0.08 / 0.18, 1e-12);
    // beside a named rate law (no rate candidate this round) a shift that flipped round 1's sign fails
    const std::vector<Trial> earlier{[] {
        Trial first;
        first.round = 1;
        first.effect = "rosin_temperature_shift";
        first.parameters = {{"shift_k", 24.0}};
        return first;
    }()};
    const std::map<std::string, double> besideRate{{"rosin_temperature_shift", 0.10}};
    t = trialOf("rosin_temperature_shift", -26.5);
    EXPECT_EQ(diag::standInVerdict(t, shift, besideRate, {"thermal_memory", "rate_dependence"}, earlier, 0.05, 0.0),
              "sign flipped beside rate_dependence (round 1 asked for the other sign): a stand-in for the rate law's form");
    t = trialOf("rosin_temperature_shift", -26.5);
    EXPECT_EQ(diag::standInVerdict(t, shift, besideRate, {"thermal_memory"}, earlier, 0.05, 0.0), "");
    // a shift's larger margin over a rate law: 0.18 against 0.22 is 18 % better, enough for the
    // threshold and not for a 30 % margin; the same margin leaves a rate law at the threshold
    t = trialOf("rosin_temperature_shift", 23.0);
    const std::map<std::string, double> close{{"thermal_memory", 0.30}, {"rosin_temperature_shift", 0.18}, {"rate_dependence", 0.22}};
    EXPECT_EQ(diag::standInVerdict(t, shift, close, {}, {}, 0.05, 0.0), "");
    EXPECT_NEAR(t.overRival, 0.04 / 0.22, 1e-12);
    t = trialOf("rosin_temperature_shift", 23.0);
    EXPECT_EQ(diag::standInVerdict(t, shift, close, {}, {}, 0.05, 0.3),
              "18 % better than rate_dependence, under the 30 % a rosin shift must clear (a missing stiffness or contact constant gives a shift that margin)");
    t = trialOf("rosin_temperature_shift", 23.0);
    EXPECT_EQ(diag::standInVerdict(t, shift, close, {}, {}, 0.05, 0.17), "");
    r = trialOf("rate_dependence", 0.0);
    EXPECT_EQ(diag::standInVerdict(r, rate, {{"thermal_memory", 0.30}, {"rosin_temperature_shift", 0.22}, {"rate_dependence", 0.18}}, {}, {}, 0.05, 0.3), "");
    // a contact or torsion is not compared with anything here
    diag::Candidate contact;
    contact.effect = "hertzian_contact";
    t = trialOf("hertzian_contact", 0.0);
    EXPECT_EQ(diag::standInVerdict(t, contact, {{"hertzian_contact", 0.5}, {"thermal_memory", 0.1}}, {}, {}, 0.05, 0.0), "");
}

// A bootstrap resample repeats strokes; the engine simulates each distinct stroke once and scores
// it as often as it appears. The scores must be those of the strokes taken one at a time, in the
// resample's order, for the error parts and the signed residuals alike.
TEST(DiagnoseNoise, TheSlipFloorIsSixDeviationsOfTheFallNoiseMakesInATenthOfAMillisecond)
{
    // White noise at 48 kHz, low-passed as the comparison is: what falls over 0.1 ms is what
    // the first-slip detector must not take for a slip.
    const double fs = 48000.0, sigma = 0.01;
    std::mt19937_64 rng(3);
    std::normal_distribution<double> g(0.0, sigma);
    std::vector<double> noise(static_cast<std::size_t>(0.2 * fs));
    for (double& x : noise) x = g(rng);
    std::vector<double> lowPassed = noise;
    zeroPhaseLowPass(lowPassed, diag::kCompareCutoff, fs);
    const int w = 5; // 0.1 ms at 48 kHz
    double sum = 0, sum2 = 0;
    int count = 0;
    for (std::size_t i = 1000; i + w + 1000 < lowPassed.size(); ++i, ++count) {
        const double fall = lowPassed[i] - lowPassed[i + w];
        sum += fall;
        sum2 += fall * fall;
    }
    const double fallSd = std::sqrt(sum2 / count - (sum / count) * (sum / count));
    const double floor = diag::slipFloorOf(diag::restDifferences(noise, fs));
    EXPECT_NEAR(floor, 6.0 * fallSd, 0.08 * 6.0 * fallSd);
    // A drift under the noise changes nothing: the differences cancel a ramp.
    std::vector<double> drifting = noise;
    for (std::size_t i = 0; i < drifting.size(); ++i) drifting[i] += 2.0 * static_cast<double>(i) / fs;
    EXPECT_NEAR(diag::slipFloorOf(diag::restDifferences(drifting, fs)), floor, 0.02 * floor);
    // Read from the low-passed signal itself (the detector's floor before), the noise looks
    // several times smaller than the falls it makes.
    EXPECT_LT(6.0 * diag::noiseLevel(lowPassed), 0.4 * floor);
    // A rest too short to read is no estimate.
    EXPECT_TRUE(diag::restDifferences(std::vector<double>(100, 0.0), fs).empty());
}

TEST(DiagnoseNoise, NoiseAloneFiresNoFirstSlipAtLowForce)
{
    // A model-made 4x4 set with 0.01 N of white noise (the default): its lowest bow force,
    // 0.15 N, sticks to about its static friction before the first slip. The recordings'
    // first slips must be read there, not where a fall of noise first passes 2 % of the force.
    diag::StringInfo info;
    Diagnosis d;
    const std::vector<diag::Prepared> strokes = preparedModelSet({}, 12, info, d);
    const DiagnoseOptions o;
    const auto floor = std::find_if(d.calibration.begin(), d.calibration.end(), [](const CalibrationValue& c) { return c.name == "slip_noise_floor_n"; });
    ASSERT_NE(floor, d.calibration.end()) << "the floor is reported as calibration";
    EXPECT_LE(floor->low, floor->value);
    EXPECT_GE(floor->high, floor->value);
    int low = 0, early = 0, earlyBefore = 0;
    for (const diag::Prepared& p : strokes) {
        if (p.gesture.force > 0.2) continue;
        ++low;
        ASSERT_TRUE(p.slipFloor.has_value());
        EXPECT_NEAR(*p.slipFloor, floor->value, 1e-12);
        early += p.feat.firstSlip < 0 || p.feat.forceBeforeSlip < 0.5 * p.gesture.force;
        const StrokeFeatures before = diag::features(p.force, o.simRate, p.gesture, info); // each signal's own floor
        earlyBefore += before.firstSlip < 0 || before.forceBeforeSlip < 0.5 * p.gesture.force;
    }
    EXPECT_EQ(low, 4);
    EXPECT_EQ(early, 0) << "a fall of noise read as the first slip";
    EXPECT_GE(earlyBefore, 2) << "the stroke's own noise estimate, which this floor replaced, fired early here";
}

TEST(DiagnoseSystematic, ARepeatedStrokeIsSimulatedOnceAndScoredAsOftenAsItAppears)
{
    diag::StringInfo info;
    Diagnosis d;
    std::vector<diag::Prepared> strokes = preparedModelSet({"thermal_memory"}, 31, info, d);
    const DiagnoseOptions o;
    ASSERT_EQ(strokes.size(), 16u);
    const diag::Engine engine(strokes, info, o.simRate, std::nullopt, false);
    for (const EffectModel& m : {EffectModel{}, EffectModel{{"thermal_memory"}, {{"r_A", 1.1}}}}) {
        const std::vector<std::size_t> resample{9, 2, 9, 14, 2, 9, 0};
        const std::vector<ErrorParts> together = engine.errors(m, resample);
        const Eigen::VectorXd signedTogether = engine.signedResiduals(m, resample);
        ASSERT_EQ(together.size(), resample.size());
        ASSERT_EQ(signedTogether.size(), 4 * static_cast<Eigen::Index>(resample.size()));
        for (std::size_t k = 0; k < resample.size(); ++k) {
            const ErrorParts alone = engine.errors(m, {resample[k]}).front();
            EXPECT_EQ(together[k].firstSlip, alone.firstSlip) << m.name() << " position " << k;
            EXPECT_EQ(together[k].forceBeforeSlip, alone.forceBeforeSlip) << m.name() << " position " << k;
            EXPECT_EQ(together[k].jump, alone.jump) << m.name() << " position " << k;
            EXPECT_EQ(together[k].transient, alone.transient) << m.name() << " position " << k;
            EXPECT_EQ(together[k].waveform, alone.waveform) << m.name() << " position " << k;
            const Eigen::VectorXd signedAlone = engine.signedResiduals(m, {resample[k]});
            for (Eigen::Index j = 0; j < 4; ++j) EXPECT_EQ(signedTogether[static_cast<Eigen::Index>(4 * k) + j], signedAlone[j]);
        }
        // the strokes differ, so a score put in the wrong place would show
        EXPECT_NE(together[0].total(), together[1].total()) << m.name();
        EXPECT_NE(together[1].total(), together[3].total()) << m.name();
    }
}

// The metric's weights are an option (DiagnoseOptions::metricWeights): the engine scores every
// part as before and weighs them with the weights it was given, the signed parts a linearised
// fit sees scale with them, and weights that would make the metric say nothing are refused.
TEST(DiagnoseSystematic, TheMetricWeighsItsPartsWithTheWeightsItIsGiven)
{
    diag::StringInfo info;
    Diagnosis d;
    std::vector<diag::Prepared> strokes = preparedModelSet({"thermal_memory"}, 31, info, d);
    const DiagnoseOptions o;
    const std::array<double, 5> noTransient{0.3, 0.3, 0.25, 0.0, 0.15};
    const diag::Engine usual(strokes, info, o.simRate, std::nullopt, false);
    const diag::Engine other(strokes, info, o.simRate, std::nullopt, false, noTransient);
    const EffectModel m; // the friction-curve baseline on a thermal set: every part disagrees somewhere
    std::vector<std::size_t> all(strokes.size());
    std::iota(all.begin(), all.end(), std::size_t(0));
    const std::vector<ErrorParts> a = usual.errors(m, all), b = other.errors(m, all);
    const Eigen::VectorXd sa = usual.signedResiduals(m, all), sb = other.signedResiduals(m, all);
    double transientShare = 0;
    for (std::size_t k = 0; k < all.size(); ++k) {
        EXPECT_EQ(a[k].transient, b[k].transient) << "the parts do not depend on the weights";
        EXPECT_EQ(a[k].waveform, b[k].waveform);
        EXPECT_DOUBLE_EQ(a[k].total(), 0.25 * (a[k].firstSlip + a[k].forceBeforeSlip + a[k].jump) + 0.1 * a[k].transient + 0.15 * a[k].waveform);
        EXPECT_DOUBLE_EQ(b[k].total(), 0.3 * (b[k].firstSlip + b[k].forceBeforeSlip) + 0.25 * b[k].jump + 0.15 * b[k].waveform);
        transientShare += 0.1 * a[k].transient;
        const auto row = static_cast<Eigen::Index>(4 * k);
        EXPECT_NEAR(sb[row], 1.2 * sa[row], 1e-12);
        EXPECT_NEAR(sb[row + 1], 1.2 * sa[row + 1], 1e-12);
        EXPECT_NEAR(sb[row + 2], sa[row + 2], 1e-12);
        EXPECT_EQ(sb[row + 3], 0.0) << "a part weighted 0 gives a fit nothing to take up";
    }
    EXPECT_GT(transientShare, 0.0) << "the strokes' transients differ, so dropping the part must show";

    EXPECT_NO_THROW(checkMetricWeights(ErrorParts::kWeights, "w"));
    EXPECT_NO_THROW(checkMetricWeights(noTransient, "w"));
    EXPECT_TRUE(defaultMetricWeights(o.metricWeights));
    EXPECT_FALSE(defaultMetricWeights(noTransient));
    const auto refusal = [](const std::array<double, 5>& w) {
        try {
            checkMetricWeights(w, "--metric-weights");
        } catch (const LabError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(refusal({0.3, 0.3, 0.3, 0.1, 0.1}).find("--metric-weights: the five weights must sum to 1 (they sum to 1.1"), std::string::npos);
    EXPECT_NE(refusal({0.5, 0.5, 0.2, -0.2, 0.0}).find("finite number of 0 or more"), std::string::npos);
    EXPECT_NE(refusal({0.5, 0.5, std::nan(""), 0.0, 0.0}).find("finite number of 0 or more"), std::string::npos);
    EXPECT_NE(refusal({0.0, 0.0, 0.0, 0.5, 0.5}).find("the first slip's three parts cannot all weigh 0"), std::string::npos);

    // A diagnosis records the weights, its metric says them, and other weights are flagged as
    // uncalibrated in the report (the naming threshold was measured with the default).
    DiagnoseOptions reweighted;
    reweighted.metricWeights = noTransient;
    const fs::path dir = fs::temp_directory_path() / ("rosin-weights-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    writeDiagnosis(dir, Diagnosis{}, reweighted);
    nlohmann::json doc;
    std::ifstream(dir / "diagnosis.json") >> doc;
    EXPECT_EQ(doc["metric_weights"], nlohmann::json(noTransient));
    EXPECT_NE(doc["gain"]["metric"].get<std::string>().find("transient length (per 25 periods, failures as 30; 0)"), std::string::npos);
    std::ifstream in(dir / "report.md");
    const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(md.find("The metric ran with other weights than its own (0.3, 0.3, 0.25, 0, 0.15"), std::string::npos) << md;
    writeDiagnosis(dir, Diagnosis{}, DiagnoseOptions{});
    std::ifstream in2(dir / "report.md");
    const std::string usualMd((std::istreambuf_iterator<char>(in2)), std::istreambuf_iterator<char>());
    EXPECT_EQ(usualMd.find("other weights than its own"), std::string::npos);
    fs::remove_all(dir);
}

namespace {
constexpr double kRampRate = 48000.0;
constexpr double kCelloBeta = 0.0899; // the cello D bow position of the reference tests

/// A slow Guettler stroke's first 60 ms (2 N, 0.3 m/s^2): the pre-slip ramp, at bow position beta.
std::vector<double> slowRamp(const rosin::dsp::BowedStringConfig& c, double beta)
{
    rosin::dsp::BowedString<double> s;
    s.prepare(kRampRate, c);
    std::vector<double> out(static_cast<std::size_t>(0.06 * kRampRate));
    for (std::size_t n = 0; n < out.size(); ++n) out[n] = s.processSample(2.0, 0.3 * static_cast<double>(n) / kRampRate, beta);
    return out;
}

/// Least-squares factor of ramp over reference, from two periods to the end.
double rampRatio(const std::vector<double>& ramp, const std::vector<double>& reference)
{
    const double f0 = rosin::dsp::StringParams::celloD().fundamental();
    double ab = 0, bb = 0;
    for (auto j = static_cast<std::size_t>(2.0 / f0 * kRampRate); j < ramp.size(); ++j) {
        ab += ramp[j] * reference[j];
        bb += reference[j] * reference[j];
    }
    return ab / bb;
}
} // namespace

// A rolling string's quasi-static softening, as the diagnosis takes it (the bow point's transverse
// stiffness in series with the torsional one), against the waveguide's own pre-slip ramps: a
// slow Guettler stroke with torsion at Z_t/Z_0 = 2 and 4 and without, compared by least squares
// over the ramp (from two periods to well before the first slip).
TEST(DiagnoseScale, ARollingStringsRampsAreSofterByTheSeriesStiffness)
{
    const std::vector<double> still = slowRamp(modelWithEffects({}, {}), kCelloBeta);
    EXPECT_EQ(diag::rollingSoftening(modelWithEffects({}, {})), 1.0);
    for (const double zt : {2.0, 4.0}) {
        const rosin::dsp::BowedStringConfig c = modelWithEffects({"torsional_compliance"}, {{"zt_ratio", zt}});
        const double ratio = rampRatio(slowRamp(c, kCelloBeta), still);
        const double expected = 1.0 / (1.0 + 1.0 / (zt * c.string.torsionSpeedRatio));
        EXPECT_NEAR(diag::rollingSoftening(c), expected, 1e-12);
        // The formula says 8.8 % softer at Z_t/Z_0 = 2 and 4.6 % at 4; the waveguide's ramps are
        // about a fifth softer again (10.4 %, 5.5 %), the torsional losses letting the roll creep
        // over the 60 ms: within 2 % of the force, where no torsion at all would be 9 % off.
        EXPECT_NEAR(ratio, expected, 0.02) << "Z_t/Z_0 " << zt << " ratio " << ratio;
    }
}

// The ramps' scale is read with the manifest's string; the rig's tension and bow position are
// known only within priors, and the scale's interval spans the ramp slopes they allow
// (relativeRampSlope). The slope's factor against the waveguide's own ramps: a string tuned to
// the same pitch at 4 % more tension, one bowed 3 % further from the bridge, and both moved.
TEST(DiagnoseScale, AFittedTensionOrBowPositionMovesTheRampsByTheirSlope)
{
    auto ramp = [](double tensionScale, double betaScale) {
        rosin::dsp::BowedStringConfig c = modelWithEffects({}, {});
        const double f0 = c.string.fundamental();
        c.string.tension *= tensionScale;
        c.string.massPerLength = c.string.tension / std::pow(2.0 * c.string.length * f0, 2.0); // tuned to pitch
        return slowRamp(c, kCelloBeta * betaScale);
    };
    const std::vector<double> manifest = ramp(1.0, 1.0);
    EXPECT_EQ(diag::relativeRampSlope(1.0, 1.0), 1.0);
    for (const auto& [tension, position] : {std::pair{1.04, 1.0}, std::pair{1.0, 1.03}, std::pair{0.96, 1.03}}) {
        // T / (beta L): the waveguide's ramps move by it to 1e-4. The static stiffness at the bow,
        // T / (beta (1 - beta) L), would be 0.3 % off at 3 % in bow position.
        EXPECT_NEAR(rampRatio(ramp(tension, position), manifest), diag::relativeRampSlope(tension, position), 1e-3)
            << "tension x" << tension << ", beta x" << position;
        EXPECT_GT(std::abs(diag::relativeRampSlope(tension, position) - 1.0), 0.025);
    }
}

// Consistency check on a model-made set: a manifest that states the tension 3 % low. Within the
// default prior (+-5 %) the calibration finds the string's tension; a lab that says it knows
// its tension to +-1 % bounds it there, and the data then hold it at that end.
TEST(DiagnoseCalibration, AManifestsStatedPriorBoundsTheTensionAndBowPosition)
{
    diag::StringInfo info;
    Diagnosis d;
    std::vector<diag::Prepared> strokes = preparedModelSet({}, 17, info, d);
    const DiagnoseOptions o;
    info.tension /= 1.03;
    info.z0 /= 1.03;
    std::vector<std::size_t> all(strokes.size());
    std::iota(all.begin(), all.end(), std::size_t(0));
    auto calibrate = [&](const diag::StringInfo& stated) {
        const diag::Engine engine(strokes, stated, o.simRate, std::nullopt, false);
        diag::Candidate cal = diag::candidate("calibration", {"tension_scale", "beta_scale"}, {1.0, 1.0});
        cal.adds.clear();
        return diag::fit(engine, EffectModel{}, cal, all, cal.start, o.maxEvaluations, 0.2);
    };
    const std::vector<double> free = calibrate(info);
    // Within 1.5 %: the simulations carry the set's 10 mN noise as its rests show it (before
    // 2026-11-29, each stroke's own estimate), which moved this 16-stroke fit from 1.03 to 1.04;
    // a fit held at the manifest's 1.0 still fails by twice the tolerance.
    EXPECT_NEAR(free[0], 1.03, 0.015) << "the default prior leaves room for the string's own tension";
    EXPECT_NEAR(free[1], 1.0, 0.01);
    diag::StringInfo known = info;
    known.tensionPrior = 0.01;
    known.betaPrior = 0.005;
    EXPECT_EQ(diag::boundsOf("tension_scale", known), (std::pair{0.99, 1.01}));
    EXPECT_EQ(diag::boundsOf("beta_scale", known), (std::pair{0.995, 1.005}));
    EXPECT_EQ(diag::boundsOf("tension_scale", info), diag::parameterBounds().at("tension_scale"));
    const std::vector<double> bounded = calibrate(known);
    EXPECT_LE(bounded[0], 1.01);
    EXPECT_GT(bounded[0], 1.005) << "pulled to the prior's end the data point to";
    EXPECT_GE(bounded[1], 0.995);
    EXPECT_LE(bounded[1], 1.005);
}

// Consistency check on a model-made set (the model's Q, 500 at f0 and 150 at 5 kHz): a manifest
// that states that Q simulates exactly what the unstated one does, and one that states a Q off
// the string's (twice or half as lossy) reaches every stroke's simulation. It hardly moves the
// set's error (+4 % and -1.5 % on this 4x4 set): Guettler strokes barely see the string's
// losses, which is why no fit can find them and a lab must state them.
TEST(DiagnoseCalibration, AStatedStringQIsTheQTheModelPlays)
{
    diag::StringInfo info;
    Diagnosis d;
    std::vector<diag::Prepared> strokes = preparedModelSet({}, 19, info, d);
    const DiagnoseOptions o;
    std::vector<std::size_t> all(strokes.size());
    std::iota(all.begin(), all.end(), std::size_t(0));
    auto errorWith = [&](std::optional<double> q0, std::optional<double> q5) {
        diag::StringInfo stated = info;
        stated.qAtF0 = q0;
        stated.qAt5kHz = q5;
        const diag::Engine engine(strokes, stated, o.simRate, std::nullopt, false);
        const rosin::dsp::BowedStringConfig c = engine.config(EffectModel{});
        if (q0) {
            EXPECT_EQ(c.string.qLow, *q0);
            EXPECT_EQ(c.string.qHigh, *q5);
        }
        std::vector<double> e;
        for (const auto& x : engine.errors(EffectModel{}, all)) e.push_back(x.total());
        return e;
    };
    const rosin::dsp::StringParams own;
    const std::vector<double> unstated = errorWith(std::nullopt, std::nullopt);
    EXPECT_EQ(errorWith(own.qLow, own.qHigh), unstated);
    for (const double k : {0.5, 2.0}) {
        const std::vector<double> off = errorWith(k * own.qLow, k * own.qHigh);
        std::size_t moved = 0;
        for (std::size_t i = 0; i < off.size(); ++i) moved += std::abs(off[i] - unstated[i]) > 1e-6;
        EXPECT_GE(moved, off.size() - 2) << "Q x" << k << " left most strokes' simulations as they were";
    }
}

// Consistency check on a model-made set whose string rolls (the model's c_t = 5.2 c, Q_t 30): a
// manifest that states those constants simulates exactly what the unstated one does; stated
// constants off the string's reach every simulation of a rolling model and none of a model that
// does not roll, and the rolling model then fits the set worse than at the string's own. The
// softening a roll is read at follows the stated c_t / c.
TEST(DiagnoseCalibration, StatedTorsionalConstantsAreTheOnesARollPlays)
{
    diag::StringInfo info;
    Diagnosis d;
    SynthTruth truth;
    SynthSpec spec;
    spec.effects = {"torsional_compliance"};
    spec.params = {{"zt_ratio", 1.6}};
    spec.seed = 23;
    spec.grid = 4;
    const MeasurementSet set = modelSetFromDisk(spec, truth);
    info = diag::stringInfoOf(set);
    std::vector<diag::Prepared> strokes = diag::prepareStrokes(set, info, DiagnoseOptions{}, d);
    const DiagnoseOptions o;
    std::vector<std::size_t> all(strokes.size());
    std::iota(all.begin(), all.end(), std::size_t(0));
    const EffectModel rolling{{"torsional_compliance"}, {{"zt_ratio", 1.6}}}, still{};
    auto errorsWith = [&](std::optional<double> speed, std::optional<double> q, const EffectModel& m) {
        diag::StringInfo stated = info;
        stated.torsionSpeedRatio = speed;
        stated.qTorsion = q;
        const diag::Engine engine(strokes, stated, o.simRate, std::nullopt, false);
        const rosin::dsp::BowedStringConfig c = engine.config(m);
        if (speed) {
            EXPECT_EQ(c.string.torsionSpeedRatio, *speed);
            EXPECT_EQ(c.string.qTorsion, *q);
            if (c.waveguide.torsion) {
                EXPECT_NEAR(diag::rollingSoftening(c), diag::softeningAt(1.6, speed), 1e-12);
            }
        }
        std::vector<double> e;
        for (const auto& x : engine.errors(m, all)) e.push_back(x.total());
        return e;
    };
    const rosin::dsp::StringParams own;
    const std::vector<double> unstated = errorsWith(std::nullopt, std::nullopt, rolling);
    EXPECT_EQ(errorsWith(own.torsionSpeedRatio, own.qTorsion, rolling), unstated);
    const std::vector<double> slow = errorsWith(3.0, 12.0, rolling);
    std::size_t moved = 0;
    for (std::size_t i = 0; i < slow.size(); ++i) moved += std::abs(slow[i] - unstated[i]) > 1e-6;
    EXPECT_GE(moved, slow.size() - 2) << "c_t = 3 c left most strokes of a rolling model as they were";
    const double meanOf = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }(slow);
    EXPECT_GT(meanOf, 1.2 * std::accumulate(unstated.begin(), unstated.end(), 0.0) / static_cast<double>(unstated.size()))
        << "the string's own torsion fits its strokes better than one 40 % slower";
    EXPECT_EQ(errorsWith(3.0, 12.0, still), errorsWith(std::nullopt, std::nullopt, still)) << "torsional constants reached a string that does not roll";
    // s = 1 / (1 + 1 / (Z_t/Z_0 c_t/c)): slower torsional waves, a softer bow point at the same Z_t.
    EXPECT_NEAR(diag::softeningAt(1.6, 3.0), 1.0 / (1.0 + 1.0 / (1.6 * 3.0)), 1e-12);
    EXPECT_LT(diag::softeningAt(1.6, 3.0), diag::softeningAt(1.6));
}

// The one parameter table: each physical parameter belongs to a finding, each nuisance to the
// calibration, and no name is both (the study's columns and the findings read the same table).
TEST(DiagnoseParameters, PhysicalParametersBelongToFindingsAndNuisancesToTheCalibration)
{
    const auto& names = physicalParameterNames();
    ASSERT_EQ(names.size(), 6u);
    std::set<std::string> effects;
    for (const auto& n : names) {
        EXPECT_NE(effectOfParameter(n), "calibration") << n;
        effects.insert(effectOfParameter(n));
    }
    EXPECT_EQ(effects, (std::set<std::string>{"thermal_memory", "rate_dependence", "hertzian_contact", "rosin_temperature_shift", "torsional_compliance"}));
    ASSERT_FALSE(diag::nuisances().empty());
    for (const auto& k : diag::nuisances()) {
        EXPECT_EQ(effectOfParameter(k.name), "calibration") << k.name;
        EXPECT_EQ(std::count(names.begin(), names.end(), k.name), 0) << k.name;
    }
}

// A thermal diagnosis without a named shift says which shift its calibrated effusivity could
// equally be (the two trade on Guettler data); with a shift named, or no effusivity fitted, it
// says nothing of the kind.
TEST(DiagnoseParameters, TheReportSaysWhichShiftTheCalibratedEffusivityCouldBe)
{
    Diagnosis d;
    d.final.effects = {"thermal_memory"};
    EXPECT_EQ(diag::shiftOrEffusivityNote(d), "") << "no effusivity in the calibration";
    d.calibration.push_back({"rod_effusivity_scale", "bow-side effusivity", 1.31, 1.24, 1.35});
    const std::string note = diag::shiftOrEffusivityNote(d);
    EXPECT_NE(note.find("came out 1.31"), std::string::npos) << note;
    EXPECT_NE(note.find("shift of +6 K"), std::string::npos) << note; // 18 K x 0.31
    EXPECT_NE(note.find("0.65-1.35"), std::string::npos) << note;
    d.calibration.back().value = 0.86;
    EXPECT_NE(diag::shiftOrEffusivityNote(d).find("shift of -3 K"), std::string::npos) << diag::shiftOrEffusivityNote(d);
    d.final.effects.push_back("rosin_temperature_shift");
    EXPECT_EQ(diag::shiftOrEffusivityNote(d), "") << "a named shift is a finding, not an alternative";
}

TEST(DiagnoseConsistency, ReportsNoneWhenTheBaselineMadeTheData) { check({{}, 21}); }

TEST(DiagnoseConsistency, FindsHertzianContactAtAnotherRateWithAnotherReflectionDesign) { check({{"hertzian_contact"}, 27, 44100, true}); }

// A shift comes with thermal memory as one candidate (it bends the thermal law), so one round
// names both; each finding says what it added, told apart by the round's fit of thermal memory
// alone, whose validation error the trials table holds (the round's start less its fall).
TEST(DiagnoseConsistency, FindsThermalMemoryWithARosinTemperatureShift)
{
    Diagnosis d;
    check({{"rosin_temperature_shift"}, 25}, &d);
    ASSERT_EQ(d.findings.size(), 2u);
    const auto named = [&](const std::string& e) { return *std::find_if(d.findings.begin(), d.findings.end(), [&](const Finding& f) { return f.effect == e; }); };
    const Finding thermal = named("thermal_memory"), shift = named("rosin_temperature_shift");
    const auto aloneTrial = std::find_if(d.trials.begin(), d.trials.end(), [](const Trial& t) { return t.round == 1 && t.effect == "thermal_memory"; });
    ASSERT_NE(aloneTrial, d.trials.end());
    EXPECT_NEAR(thermal.heldoutAfter, thermal.heldoutBefore - aloneTrial->gain, 1e-9 * thermal.heldoutBefore);
    EXPECT_DOUBLE_EQ(shift.heldoutBefore, thermal.heldoutAfter);
    EXPECT_LT(thermal.heldoutAfter, thermal.heldoutBefore);
    // rule 2: the shift fell below thermal memory alone by the naming threshold
    EXPECT_LT(shift.heldoutAfter, (1.0 - DiagnoseOptions{}.namingThreshold) * shift.heldoutBefore);
    EXPECT_EQ(shift.evidence.rfind("With the thermal model ", 0), 0u) << shift.evidence;
    EXPECT_NE(shift.evidence.find("beyond thermal memory alone, fitted in the same round"), std::string::npos) << shift.evidence;
    EXPECT_EQ(thermal.evidence.rfind("With the friction_curve model ", 0), 0u) << thermal.evidence;
    EXPECT_NE(thermal.evidence.find("rosin_temperature_shift came with it as one candidate"), std::string::npos) << thermal.evidence;
}

// Effects named alone or as a pair keep the round's start and end; a pair also says what each
// did alone, and a missing single fit is said, not invented.
TEST(DiagnoseParameters, EachEffectARoundNamesSaysWhatItAdded)
{
    const auto parts = [](double jump, std::size_t n) {
        ErrorParts e;
        e.jump = jump;
        return std::vector<ErrorParts>(n, e);
    };
    const std::vector<std::size_t> ids{0, 1, 2, 3};
    const std::vector<ErrorParts> start = parts(0.8, 4), end = parts(0.2, 4);
    EffectModel baseline;
    const auto single = diag::roundEvidence("hertzian_contact", {"hertzian_contact"}, {}, start, end, ids, baseline);
    EXPECT_DOUBLE_EQ(single.before, 0.2);
    EXPECT_DOUBLE_EQ(single.after, 0.05);
    EXPECT_EQ(single.text.find("alone"), std::string::npos) << single.text;
    EXPECT_NE(single.text.find("first-slip jumps of the 4 held-out strokes were off by 80.0 % of the bow force on average; they are off by 20.0 %"),
              std::string::npos)
        << single.text;

    EffectModel thermalOnly;
    thermalOnly.effects = {"thermal_memory"};
    const std::map<std::string, diag::AloneFit> alone{{"thermal_memory", {thermalOnly, parts(0.5, 4)}}};
    const std::vector<std::string> both{"rate_dependence", "thermal_memory"};
    const auto thermal = diag::roundEvidence("thermal_memory", both, alone, start, end, ids, baseline);
    const auto rate = diag::roundEvidence("rate_dependence", both, alone, start, end, ids, baseline);
    EXPECT_DOUBLE_EQ(thermal.before, 0.2);
    EXPECT_DOUBLE_EQ(thermal.after, 0.125);
    EXPECT_DOUBLE_EQ(rate.before, 0.125);
    EXPECT_DOUBLE_EQ(rate.after, 0.05);
    EXPECT_NE(thermal.text.find("off by 80.0 % of the bow force on average; they are off by 50.0 %"), std::string::npos) << thermal.text;
    EXPECT_NE(rate.text.find("With the thermal model the first-slip jumps of the 4 held-out strokes were off by 50.0 %"), std::string::npos) << rate.text;
    EXPECT_NE(rate.text.find("beyond thermal memory alone, fitted in the same round; the two came as one candidate."), std::string::npos) << rate.text;
    EXPECT_NE(thermal.text.find("rate_dependence came with it as one candidate"), std::string::npos) << thermal.text;

    const std::vector<std::string> pair{"hertzian_contact", "torsional_compliance"};
    const std::map<std::string, diag::AloneFit> oneAlone{{"hertzian_contact", {baseline, parts(0.6, 4)}}};
    const auto contact = diag::roundEvidence("hertzian_contact", pair, oneAlone, start, end, ids, baseline);
    EXPECT_DOUBLE_EQ(contact.before, 0.2);
    EXPECT_DOUBLE_EQ(contact.after, 0.05);
    EXPECT_NE(contact.text.find("Named together with torsional_compliance as one candidate: hertzian_contact alone, fitted in the same round, left it "
                                "at 0.150. torsional_compliance alone was not fitted this round."),
              std::string::npos)
        << contact.text;
}

// Rule 4 asks the interval the report prints, model discrepancy included, to exclude no effect.
// The seed-25 set above hides a -19.9 K shift, named with the default discrepancy (8 K, a
// half-width of about 16 K) and fitted at -23.7 K. Told that the model misses shifts by 15 K
// (half-width 29 K), the same fit cannot prove the shift: it is not named, the trial says why
// with its fitted value, and nothing else takes its place (FindsThermalMemoryWithARosin-
// TemperatureShift names it on the same set with the default). Asked of split seeds 1-3: a
// single seed's split decides which strokes speak, and with the stratified split seed 5 (this
// test's one seed until 2026-12-05) names a roll in the refused shift's place
// (docs/diagnosis-study.md, thirty-ninth session).
TEST(DiagnoseConsistency, AShiftWhosePrintedIntervalReachesZeroIsNotNamed)
{
    SynthSpec spec;
    spec.effects = {"rosin_temperature_shift"};
    spec.seed = 25;
    spec.grid = 8;
    SynthTruth truth;
    const MeasurementSet set = modelSetFromDisk(spec, truth);
    ASSERT_NEAR(truth.params.at("shift_k"), -19.9, 0.1);
    for (const std::uint64_t split : {1, 2, 3}) {
        SCOPED_TRACE("split seed " + std::to_string(split));
        DiagnoseOptions o;
        o.seed = split;
        o.modelDiscrepancy["shift_k"] = 15.0;
        const Diagnosis d = diagnose(set, o);
        std::vector<std::string> found;
        for (const auto& f : d.findings) found.push_back(f.effect);
        EXPECT_EQ(found, std::vector<std::string>{"thermal_memory"});
        const auto refused = std::find_if(d.trials.begin(), d.trials.end(), [](const Trial& t) {
            return t.effect == "rosin_temperature_shift" && t.verdict == "interval reaches the no-effect value once the model discrepancy is counted";
        });
        ASSERT_NE(refused, d.trials.end());
        EXPECT_NEAR(refused->parameters.at("shift_k"), truth.params.at("shift_k"), 5.0);
        // the shift's own scatter would have let it through: the discrepancy is what refused it
        EXPECT_LT(std::abs(refused->parameters.at("shift_k")), diag::discrepancyHalfWidth(o, "shift_k", refused->parameters.at("shift_k")));
        EXPECT_GT(std::abs(refused->parameters.at("shift_k")), diag::discrepancyHalfWidth(DiagnoseOptions{}, "shift_k", 0.0));
    }
}

// The half-width rule 4 and the report add: 1.96 standard deviations, a share of the value for
// r_A and Z_t/Z_0, absolute for the others, none where the options give 0.
TEST(DiagnoseParameters, TheModelDiscrepancysHalfWidthIsRelativeOnlyForRAAndZt)
{
    DiagnoseOptions o;
    o.modelDiscrepancy = {{"shift_k", 8.0}, {"zt_ratio", 0.5}, {"r_A", 0.1}, {"p", 0.0}};
    EXPECT_NEAR(diag::discrepancyHalfWidth(o, "shift_k", -3.0), 15.68, 1e-9);
    EXPECT_NEAR(diag::discrepancyHalfWidth(o, "shift_k", 30.0), 15.68, 1e-9);
    EXPECT_NEAR(diag::discrepancyHalfWidth(o, "zt_ratio", 4.0), 3.92, 1e-9);
    EXPECT_NEAR(diag::discrepancyHalfWidth(o, "r_A", -2.0), 0.392, 1e-9);
    EXPECT_EQ(diag::discrepancyHalfWidth(o, "p", 0.4), 0.0);
    EXPECT_EQ(diag::discrepancyHalfWidth(o, "load_exponent", 0.7), 0.0);
}

// The weakest values rule 4 can name with the shipped discrepancy and no scatter: |shift| 1.96 x
// 8 K, Z_t/Z_0 where v (1 + 1.96 x 0.53) reaches 7.5, p 0.03 + 1.96 x 0.073, the load exponent
// 1 - 1.96 x 0.018; r_A has no no-effect value. A smaller discrepancy lets weaker effects through.
TEST(DiagnoseParameters, RuleFoursWeakestNameableValuesFollowTheModelDiscrepancy)
{
    const DiagnoseOptions shipped;
    EXPECT_NEAR(*diag::nameableEdge(shipped, "shift_k"), 1.96 * 8.0, 0.01);
    EXPECT_NEAR(*diag::nameableEdge(shipped, "zt_ratio"), 7.5 / (1.0 + 1.96 * 0.53), 0.01);
    EXPECT_NEAR(*diag::nameableEdge(shipped, "p"), 0.03 + 1.96 * 0.073, 0.001);
    EXPECT_NEAR(*diag::nameableEdge(shipped, "load_exponent"), 1.0 - 1.96 * 0.018, 0.001);
    EXPECT_FALSE(diag::nameableEdge(shipped, "r_A").has_value());
    DiagnoseOptions half = shipped;
    for (auto& [name, sd] : half.modelDiscrepancy) sd *= 0.5;
    EXPECT_NEAR(*diag::nameableEdge(half, "shift_k"), 1.96 * 4.0, 0.01);
    EXPECT_NEAR(*diag::nameableEdge(half, "zt_ratio"), 7.5 / (1.0 + 1.96 * 0.265), 0.01);
}

// The rules diagnosis.json prints are the ones the rounds apply: they carry the options' naming
// threshold and margins, the manifest's stated priors, and the pair rule only when pairs are tried.
TEST(DiagnoseRules, TheRulesTextCarriesTheOptionsThresholdsAndTheManifestsPriors)
{
    const auto holds = [](const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; };
    diag::StringInfo silent;
    const DiagnoseOptions shipped;
    const auto rules = diag::NamingRounds::rules(shipped, silent);
    ASSERT_EQ(rules.size(), 5u); // calibration, rules 1-5, after a finding, the gain, rule 6
    EXPECT_TRUE(holds(rules[0], "tension within +-5 % and bow position within +-4 % of the manifest")) << rules[0];
    EXPECT_FALSE(holds(rules[0], "stated prior"));
    EXPECT_TRUE(holds(rules[1], "the fall is at least 5 % of the validation error")) << rules[1];
    EXPECT_TRUE(holds(rules[1], "a rosin shift below the rate dependence by 30 %"));
    EXPECT_TRUE(holds(rules[1], "no shift under 15.7 K"));
    EXPECT_TRUE(holds(rules[2], "the round is undone"));
    EXPECT_FALSE(std::any_of(rules.begin(), rules.end(), [&](const std::string& r) { return holds(r, "tried together as one candidate"); }));

    diag::StringInfo stated;
    stated.tensionPrior = 0.01;
    DiagnoseOptions other = shipped;
    other.namingThreshold = 0.08;
    other.shiftOverRateMargin = 0.05; // under the threshold: no margin of its own
    other.tryPairs = true;
    other.usualResidualRatio = 0.0;
    const auto changed = diag::NamingRounds::rules(other, stated);
    ASSERT_EQ(changed.size(), 5u); // the pair rule in, rule 6 out
    EXPECT_TRUE(holds(changed[0], "tension within +-1 % (the manifest's stated prior) and bow position within +-4 %")) << changed[0];
    EXPECT_TRUE(holds(changed[1], "the fall is at least 8 % of the validation error"));
    EXPECT_FALSE(holds(changed[1], "a rosin shift below the rate dependence by"));
    EXPECT_TRUE(holds(changed[4], "tried together as one candidate"));
}

// A rosin shift and the bow side's effusivity (a nuisance within 300-600 W s^1/2 m^-2 K^-1) both
// move the contact's temperature against the rosin's softening: on this set a -16.8 K shift is
// matched within 4 % of the validation error by an effusivity of 0.8 x 450, below the naming
// threshold. The diagnosis may name the shift (at its value), or name thermal memory alone; then
// the effusivity that took the shift up must show in the calibration, its interval away from the
// nominal value, and the shift must be in the trials: nothing hidden silently, nothing mislabelled.
TEST(DiagnoseConsistency, AShiftTheBowsEffusivityCanMimicIsNamedOrShownInTheCalibration)
{
    SynthTruth truth;
    const Diagnosis d = diagnoseModelSet({{"rosin_temperature_shift"}, 24}, truth);
    ASSERT_NEAR(truth.params.at("shift_k"), -16.8, 0.1);
    std::vector<std::string> found;
    for (const auto& f : d.findings) found.push_back(f.effect);
    std::sort(found.begin(), found.end());
    if (found == std::vector<std::string>{"rosin_temperature_shift", "thermal_memory"}) {
        for (const auto& f : d.findings) {
            if (f.parameters.count("shift_k")) {
                EXPECT_NEAR(f.parameters.at("shift_k")[0], truth.params.at("shift_k"), 5.0);
            }
        }
        return;
    }
    ASSERT_EQ(found, std::vector<std::string>{"thermal_memory"});
    const auto rod = std::find_if(d.calibration.begin(), d.calibration.end(), [](const CalibrationValue& c) { return c.name == "rod_effusivity_scale"; });
    ASSERT_NE(rod, d.calibration.end());
    EXPECT_LT(rod->high, 1.0) << "the effusivity that stood in for the shift keeps away from its nominal value";
    EXPECT_TRUE(std::any_of(d.trials.begin(), d.trials.end(), [](const Trial& t) { return t.effect == "rosin_temperature_shift" && t.round == 1; }));
}

// Several seeds, effects drawn at random by the test (including none and pairs). Minutes: `long`.
TEST(DiagnoseConsistencyLong, RandomHiddenEffectsOverSeveralSeeds)
{
    const std::vector<std::vector<std::string>> choices{{},
                                                        {"thermal_memory"},
                                                        {"rate_dependence"},
                                                        {"hertzian_contact"},
                                                        {"rosin_temperature_shift"},
                                                        {"torsional_compliance"},
                                                        {"hertzian_contact", "torsional_compliance"},
                                                        {"thermal_memory", "hertzian_contact"}};
    std::mt19937 pick(2026);
    for (std::uint64_t seed = 101; seed < 109; ++seed) {
        const auto& effects = choices[pick() % choices.size()];
        SCOPED_TRACE("seed " + std::to_string(seed));
        check({effects, seed, seed % 2 ? 44100.0 : 48000.0, seed % 3 == 0, true});
    }
}

// The reported interval counts the model discrepancy the studies measured. Where it reaches the
// no-effect value the report says the data favour the effect without ruling out its absence; a
// torsion's report gives the softening the data fix and the c_t/c its Z_t/Z_0 rests on, and a
// shift's the contact radius its kelvins rest on.
TEST(DiagnoseParameters, TheReportSaysWhenTheModelDiscrepancyReachesNoEffect)
{
    const auto npos = std::string::npos;
    Finding weak;
    weak.effect = "torsional_compliance";
    weak.parameters["zt_ratio"] = {4.3, 3.9, 4.7};
    weak.discrepancy["zt_ratio"] = 1.96 * 0.53 * 4.3; // reported top 4.3 + 4.5, past 7.5
    EXPECT_FALSE(diag::clearOfNoEffect(weak, "zt_ratio"));
    EXPECT_NE(diag::findingCaveats(weak).find("reaches its no-effect value, 7.5 or more"), npos) << diag::findingCaveats(weak);

    Finding strong = weak;
    strong.parameters["zt_ratio"] = {1.5, 1.4, 1.6};
    strong.discrepancy["zt_ratio"] = 1.96 * 0.53 * 1.5; // top 1.5 + 1.56
    EXPECT_TRUE(diag::clearOfNoEffect(strong, "zt_ratio"));
    const std::string text = diag::findingCaveats(strong);
    EXPECT_EQ(text.find("no-effect"), npos) << text;
    // s = 1 / (1 + 1 / (Z_t/Z_0 c_t/c)), with the model's c_t/c
    const double speed = diag::assumedTorsionSpeedRatio();
    EXPECT_NEAR(speed, modelWithEffects({"torsional_compliance"}, {}).string.torsionSpeedRatio, 1e-12);
    EXPECT_NEAR(diag::softeningAt(1.5), 1.0 / (1.0 + 1.0 / (1.5 * speed)), 1e-12);
    char expected[32];
    std::snprintf(expected, sizeof expected, "s = %.3f", diag::softeningAt(1.5));
    EXPECT_NE(text.find(expected), npos) << text;
    EXPECT_NE(text.find("c_t = 5.2 c, the model's own"), npos) << text;
    // A manifest that states c_t / c: the softening and the words are at the lab's value.
    const std::string measured = diag::findingCaveats(strong, 4.6);
    std::snprintf(expected, sizeof expected, "s = %.3f", diag::softeningAt(1.5, 4.6));
    EXPECT_NE(measured.find(expected), npos) << measured;
    EXPECT_NE(measured.find("as the manifest states it, c_t = 4.6 c"), npos) << measured;
    EXPECT_NE(diag::softeningAt(1.5, 4.6), diag::softeningAt(1.5));

    Finding contact;
    contact.effect = "hertzian_contact";
    contact.parameters["load_exponent"] = {0.93, 0.91, 0.95};
    contact.discrepancy["load_exponent"] = 1.96 * 0.018; // top 0.93 + 0.04
    EXPECT_TRUE(diag::clearOfNoEffect(contact, "load_exponent"));
    EXPECT_EQ(diag::findingCaveats(contact), "");
    contact.parameters["load_exponent"] = {0.97, 0.95, 0.99}; // top 1.01
    EXPECT_FALSE(diag::clearOfNoEffect(contact, "load_exponent"));
    EXPECT_NE(diag::findingCaveats(contact).find("1 (Amontons)"), npos);

    // A named shift says its kelvins rest on the model's contact radius, with the studies' numbers
    Finding shift;
    shift.effect = "rosin_temperature_shift";
    shift.parameters["shift_k"] = {18.2, 17.2, 19.1};
    shift.discrepancy["shift_k"] = 1.96 * 8.0;
    const std::string shiftText = diag::findingCaveats(shift);
    EXPECT_EQ(shiftText.find("no-effect"), npos) << shiftText;
    EXPECT_NE(shiftText.find("on its 250 um contact"), npos) << shiftText;
    EXPECT_NE(shiftText.find("1.4 times as large with a 300 um contact"), npos) << shiftText;
    EXPECT_NE(shiftText.find("a named shift tends to read high"), npos) << shiftText;
    EXPECT_NE(shiftText.find("model discrepancy (+-15.7 K)"), npos) << shiftText;
    shift.discrepancy.clear(); // --model-discrepancy shift_k=0: nothing to point at
    EXPECT_EQ(diag::findingCaveats(shift).find("model discrepancy"), npos) << diag::findingCaveats(shift);

    Finding thermal; // r_A has no no-effect value: thermal memory is named by its fall, not its parameter
    thermal.effect = "thermal_memory";
    thermal.parameters["r_A"] = {1.0, 0.5, 1.5};
    EXPECT_TRUE(diag::clearOfNoEffect(thermal, "r_A"));
    EXPECT_EQ(diag::findingCaveats(thermal), "");
}
