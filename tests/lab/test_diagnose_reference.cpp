// rosin diagnose on data it did not make: sets from the reference simulator (lab/reference: a
// finite-difference stiff string with bridge resonances and exact-kernel heat) on rigs drawn
// with every nuisance a lab never knows exactly, written to disk and diagnosed from the files.
//
// Rules for every assertion (issue 19): a tolerance is tighter than the prior the value is drawn
// from (so each effect's parameter is set well away from its prior's middle: a constant guess
// fails), every named parameter is checked, and nothing follows from another by construction.
#include <gtest/gtest.h>
#include <sndfile.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>

#include "DiagnoseEngine.h" // lab/src: the prepared strokes and the noise their simulations carry
#include "rosin/lab/Classifier.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/ReferenceData.h"
#include "rosin/lab/Study.h"

using namespace rosin::lab;
namespace fs = std::filesystem;

namespace {
struct Outcome {
    Diagnosis d;
    SynthTruth truth;
};

/// The set the spec makes, written to files and read back as a user's set is (in newtons a stroke
/// passes 1.0, a PCM file's full scale, so those are float files).
MeasurementSet throughFiles(const SynthSpec& spec, SynthTruth& truth)
{
    const fs::path dir = fs::temp_directory_path() / ("rosin-diagref-" + std::to_string(::getpid()) + "-" + std::to_string(spec.seed));
    fs::remove_all(dir);
    fs::create_directories(dir);
    writeMeasurementSet(dir / "set", synthesize(spec, truth), spec.units == "N" ? SF_FORMAT_FLOAT : SF_FORMAT_PCM_24);
    MeasurementSet set = readMeasurementSet(dir / "set");
    fs::remove_all(dir);
    return set;
}

/// A set as `rosin study` makes it (12x12 Guettler strokes from the reference simulator, the set's
/// own seed: the study's seed times 1000 plus its index plus one), through files.
MeasurementSet studySet(const std::vector<std::string>& effects, std::uint64_t seed, SynthTruth& truth,
                        const std::map<std::string, double>& rig = {}, const std::map<std::string, double>& statedUncertainty = {})
{
    SynthSpec spec;
    spec.generator = "reference";
    spec.effects = effects;
    spec.seed = seed;
    spec.grid = 12;
    spec.rig = rig;
    spec.statedUncertainty = statedUncertainty;
    return throughFiles(spec, truth);
}

/// The finding of this effect, or none.
const Finding* findingOf(const Diagnosis& d, const std::string& effect)
{
    const auto f = std::find_if(d.findings.begin(), d.findings.end(), [&](const Finding& x) { return x.effect == effect; });
    return f == d.findings.end() ? nullptr : &*f;
}

/// The set, diagnosed once per split seed (one simulation, several fit/validation/test splits).
std::vector<Outcome> runSplits(const std::vector<std::string>& effects, const std::map<std::string, double>& params, std::uint64_t seed,
                               const std::vector<std::uint64_t>& splitSeeds, int grid = 8, const std::string& gesture = "guettler",
                               const std::string& units = "V", const std::map<std::string, double>& rig = {})
{
    SynthSpec spec;
    spec.generator = "reference";
    spec.effects = effects;
    spec.params = params;
    spec.seed = seed;
    spec.grid = grid;
    spec.seconds = 0.3;
    spec.gesture = gesture;
    spec.units = units;
    spec.rig = rig;
    SynthTruth truth;
    const MeasurementSet set = throughFiles(spec, truth);
    std::vector<Outcome> out;
    for (const std::uint64_t split : splitSeeds) {
        DiagnoseOptions opt;
        opt.seed = split;
        out.push_back({diagnose(set, opt), truth});
    }
    return out;
}

Outcome run(const std::vector<std::string>& effects, const std::map<std::string, double>& params, std::uint64_t seed, int grid = 8,
            const std::string& gesture = "guettler", const std::string& units = "V", const std::map<std::string, double>& rig = {})
{
    return runSplits(effects, params, seed, {5}, grid, gesture, units, rig).front();
}

/// The absolute (or relative) tolerance of each named parameter: tighter than its prior.
struct Tolerance {
    double value;
    bool relative;
};
const std::map<std::string, Tolerance> kTolerance{{"load_exponent", {0.05, false}}, {"shift_k", {3.0, false}}, {"zt_ratio", {0.2, true}},
                                                  {"r_A", {0.1, true}},           {"p", {0.1, false}}};

void expectDiagnosis(const Outcome& o)
{
    std::vector<std::string> found, want = o.truth.effects;
    for (const auto& f : o.d.findings) found.push_back(f.effect);
    std::sort(found.begin(), found.end());
    std::sort(want.begin(), want.end());
    std::string tried;
    for (const auto& t : o.d.trials) {
        tried += "\n  [" + std::to_string(t.round) + " " + t.effect + " fall " + std::to_string(t.relativeGain) + " over thermal " + std::to_string(t.overThermal);
        for (const auto& [name, value] : t.parameters) tried += " " + name + "=" + std::to_string(value);
        tried += ": " + t.verdict + "]";
    }
    EXPECT_EQ(found, want) << "tried:" << tried;
    // The search ranges (docs/diagnosis.md): no interval reaches past them.
    const std::map<std::string, std::pair<double, double>> range{{"r_A", {0.5, 2.0}},          {"h0", {0.3, 1.2}},         {"p", {0.1, 0.8}},
                                                                 {"load_exponent", {0.4, 1.1}}, {"shift_k", {-30.0, 30.0}}, {"zt_ratio", {0.7, 8.0}}};
    for (const auto& f : o.d.findings)
        for (const auto& [name, v] : f.parameters) {
            ASSERT_TRUE(o.truth.params.count(name)) << name;
            const double t = o.truth.params.at(name);
            const auto [lo, hi] = reportedInterval(f, name);
            EXPECT_GE(lo, range.at(name).first) << name;
            EXPECT_LE(hi, range.at(name).second) << name;
            if (name == "h0") {
                // h0 cancels out of the enhanced law when y(theta) is the inversion of steady
                // sliding (y h = mu_ss(v_theta) h(x) / h(v_theta)): no data can fix it, so the
                // report must say so rather than claim a value (it once printed +-2e6).
                EXPECT_TRUE(f.unidentified.count("h0")) << "h0 interval " << lo << ".." << hi;
                EXPECT_NEAR(hi - lo, 0.9, 1e-9) << "not identified: the whole search range";
                continue;
            }
            EXPECT_FALSE(f.unidentified.count(name)) << name;
            const Tolerance tol = kTolerance.at(name);
            const double err = tol.relative ? std::abs(v[0] / t - 1.0) : std::abs(v[0] - t);
            EXPECT_LE(err, tol.value) << name << " found " << v[0] << " hidden " << t << "; tried:" << tried;
        }
}
} // namespace

// Rate dependence on a thermal rig: named with its exponent p, and h0 reported as not identified.
// On an 8x8 set p depends on which strokes the split gives the fit: since the simulations carry
// the rig's own noise (2026-11-29) one split of three put it at 0.65 for 0.45 (its interval from
// 0.49), the others within 0.1. So the set is diagnosed with three splits: each names the rate
// law and thermal memory (nothing else), r_A within 10 % and h0 not identified; the median p is
// within 0.1 and p's reported interval holds the truth on at least two of the three.
TEST(DiagnoseReference, FindsRateDependenceAndSaysH0IsNotIdentified)
{
    std::vector<double> ps;
    int covered = 0;
    for (const Outcome& o : runSplits({"rate_dependence"}, {{"r_A", 1.0}, {"h0", 0.6}, {"p", 0.45}}, 61, {5, 6, 7})) {
        std::vector<std::string> found;
        for (const auto& f : o.d.findings) found.push_back(f.effect);
        std::vector<std::string> want = o.truth.effects;
        std::sort(found.begin(), found.end());
        std::sort(want.begin(), want.end());
        EXPECT_EQ(found, want);
        const Finding* rate = findingOf(o.d, "rate_dependence");
        ASSERT_NE(rate, nullptr);
        const auto [lo, hi] = reportedInterval(*rate, "p");
        covered += lo <= 0.45 && hi >= 0.45;
        EXPECT_TRUE(rate->unidentified.count("h0"));
        ps.push_back(rate->parameters.at("p")[0]);
        const Finding* thermal = findingOf(o.d, "thermal_memory");
        ASSERT_NE(thermal, nullptr);
        EXPECT_NEAR(thermal->parameters.at("r_A")[0], 1.0, 0.1);
        // A rosin shift can stand in for a rate law: a shift was fitted in the round that named the
        // rate dependence, and the rate dependence beat it by the naming threshold.
        const auto named = std::find_if(o.d.trials.begin(), o.d.trials.end(), [](const Trial& t) { return t.effect == "rate_dependence" && t.verdict == "named"; });
        ASSERT_NE(named, o.d.trials.end());
        EXPECT_TRUE(std::any_of(o.d.trials.begin(), o.d.trials.end(),
                                [&](const Trial& t) { return t.effect == "rosin_temperature_shift" && t.round == named->round; }));
        EXPECT_GE(named->overRival, DiagnoseOptions{}.namingThreshold);
    }
    ASSERT_EQ(ps.size(), 3u);
    std::sort(ps.begin(), ps.end());
    EXPECT_NEAR(ps[1], 0.45, 0.1) << "p from three splits: " << ps[0] << ", " << ps[1] << ", " << ps[2];
    EXPECT_GE(covered, 2) << "95 % intervals: two misses in three would be rare";
}

TEST(DiagnoseReference, NamesNothingOnANullRig)
{
    const Outcome o = run({}, {}, 41);
    expectDiagnosis(o);
    // Calibration, not findings: the rig's static friction from its steady_sliding.csv, within
    // 3 % (its prior spans +-7 %).
    double mu = 0;
    for (const auto& c : o.d.calibration) {
        if (c.name == "mu_static") mu = c.value;
        EXPECT_NE(c.name, "rod_effusivity_scale") << "the rod's heat matters only to a thermal model";
    }
    EXPECT_NEAR(mu / (1.2 * o.truth.rig.at("mu_level") * (0.85 + 0.35 * o.truth.rig.at("mu_floor_scale")) / 1.2), 1.0, 0.03);
    // The tension and bow position a fit needs are the model's: their curvature intervals held
    // the rig's truth on 18 and 20 of 80 study sets. The reported interval adds the calibration
    // discrepancy in quadrature (clipped to the prior) and holds the truth here; the curvature
    // interval alone is kept beside it.
    const DiagnoseOptions defaults;
    const std::map<std::string, double> truth{{"tension_scale", 1.0 + o.truth.rig.at("tension_error")},
                                              {"beta_scale", 1.0 + o.truth.rig.at("beta_error")}};
    int checked = 0;
    for (const auto& c : o.d.calibration) {
        if (!truth.count(c.name)) continue;
        ++checked;
        ASSERT_EQ(c.curvature.size(), 2u) << c.name;
        const auto [bottom, top] = diag::parameterBounds().at(c.name);
        const double curvatureHalf = std::max(c.value - c.curvature[0], c.curvature[1] - c.value);
        const double wide = std::hypot(curvatureHalf, 1.96 * defaults.calibrationDiscrepancy.at(c.name));
        EXPECT_NEAR(c.low, std::max(bottom, c.value - wide), 1e-3 * (top - bottom)) << c.name;
        EXPECT_NEAR(c.high, std::min(top, c.value + wide), 1e-3 * (top - bottom)) << c.name;
        EXPECT_LT(c.curvature[1] - c.curvature[0], c.high - c.low) << c.name;
        EXPECT_GE(truth.at(c.name), c.low) << c.name;
        EXPECT_LE(truth.at(c.name), c.high) << c.name;
    }
    EXPECT_EQ(checked, 2);
}

// A difference no candidate names: the same null rig with a string far stiffer than any the
// model's waveguide makes (B = 1e-3, against 5e-6) names nothing and reports an unexplained
// residual beyond the usual one (what the study's null rigs leave), carried by the waveform after
// the first slip and the first-slip jump; with the ordinary stiffness the residual stays within
// the usual one and under 0.6 of the stiff string's (measured: 7.2 and 16.9 times the floor).
TEST(DiagnoseReference, AFarStifferStringIsAnUnexplainedResidualBeyondTheUsualAndNoLabel)
{
    std::map<double, Residual> residual;
    for (const double stiffness : {5e-6, 1e-3}) {
        const Outcome o = run({}, {}, 5101, 8, "guettler", "V", {{"inharmonicity", stiffness}});
        SCOPED_TRACE("B " + std::to_string(stiffness));
        expectDiagnosis(o);
        residual[stiffness] = o.d.residual;
    }
    const Residual& stiff = residual.at(1e-3);
    const Residual& usual = residual.at(5e-6);
    const double usualRatio = DiagnoseOptions{}.usualResidualRatio;
    EXPECT_TRUE(stiff.present);
    EXPECT_TRUE(stiff.beyondUsual) << stiff.ratio << " times the floor against a usual " << usualRatio;
    EXPECT_GT(stiff.parts.count("waveform after the first slip"), 0u);
    EXPECT_GT(stiff.parts.count("first-slip jump"), 0u);
    EXPECT_NE(stiff.looksLike.find("so does the first slip's jump"), std::string::npos) << stiff.looksLike;
    EXPECT_NE(stiff.looksLike.find("string stiffness"), std::string::npos) << stiff.looksLike;
    EXPECT_FALSE(usual.beyondUsual) << usual.ratio << " times the floor against a usual " << usualRatio;
    EXPECT_LT(usual.ratio, 0.6 * stiff.ratio);
}

// The bow side's thermal effusivity is calibration once the model is thermal: reported with its
// meaning and an interval inside its literature range (300-600 for the model's 450), never a finding.
TEST(DiagnoseReference, FindsThermalMemoryAndItsFootprint)
{
    const Outcome o = run({"thermal_memory"}, {{"r_A", 0.8}}, 42);
    expectDiagnosis(o);
    int rods = 0;
    for (const auto& c : o.d.calibration)
        if (c.name == "rod_effusivity_scale") {
            ++rods;
            EXPECT_NE(c.meaning.find("effusivity"), std::string::npos);
            EXPECT_TRUE(c.low <= c.value && c.value <= c.high) << c.low << " " << c.value << " " << c.high;
            EXPECT_TRUE(c.value >= 0.65 && c.value <= 1.35) << c.value;
        }
    EXPECT_EQ(rods, 1);
}

TEST(DiagnoseReference, FindsAHertzianContact) { expectDiagnosis(run({"hertzian_contact"}, {{"load_exponent", 0.65}}, 43)); }

// A contact on a thermal rig: thermal memory without the contact reaches for a rosin shift
// (on a 12x12 set of this kind, +30 K, the end of its range, was named first and stayed beside
// the contact named next, 0.75 for 0.6). A parameter pinned at its range's end is not named,
// the contact's search spans r_A once thermal memory is named, and an earlier finding that a
// later one makes redundant is dropped: thermal memory and the contact, nothing else, each
// within tolerance. (On an 8x8 set of this kind a 7 K shift is still named beside the
// contact: without it the validation error is 14 % higher. See docs/diagnosis-study.md.)
TEST(DiagnoseReferenceLong, FindsAContactOnAThermalRigAndNoStandInShift)
{
    expectDiagnosis(run({"thermal_memory", "hertzian_contact"}, {{"r_A", 0.92}, {"load_exponent", 0.6}}, 8101, 12));
}

// Other gestures (MEASUREMENT_FORMAT: exp_speed, exp_force, and sets that mix them). A mixed
// set in volts takes its scale from the pre-slip ramps of its guettler and exp_speed strokes
// (a rising-force stroke slides from the start: its ramp carries the friction level too), and
// thermal memory is found with its footprint across all three gestures.
TEST(DiagnoseReference, DiagnosesAMixedSetOfThreeGestures)
{
    const Outcome o = run({"thermal_memory"}, {{"r_A", 0.8}}, 47, 8, "mixed");
    std::map<std::string, int> kinds;
    for (const auto& g : o.d.gestures) ++kinds[g];
    EXPECT_EQ(kinds, (std::map<std::string, int>{{"exp_force", 21}, {"exp_speed", 22}, {"guettler", 21}}));
    // A ramp measures the sensor's scale times the string's slope T / (beta L);
    // the rig's tension and bow position are off the manifest (here by -3.0 % and +2.4 %), which
    // nothing in these data tells apart from the gain. The scale's prior spans a factor of several
    // (the recordist's gain): the product comes back within 3 %, and the reported interval, which
    // carries the priors of tension and bow position, holds the true scale.
    const double tension = 1.0 + o.truth.rig.at("tension_error"), position = 1.0 + o.truth.rig.at("beta_error");
    EXPECT_NEAR(o.d.scale * o.truth.gain * tension / position, 1.0, 0.03);
    int reported = 0;
    for (const auto& c : o.d.calibration)
        if (c.name == "scale_n_per_unit") {
            ++reported;
            EXPECT_EQ(c.value, o.d.scale);
            EXPECT_LE(c.low, 1.0 / o.truth.gain);
            EXPECT_GE(c.high, 1.0 / o.truth.gain);
            // Its low end also leaves room for a roll no model named (Z_t/Z_0 = 2); the part the
            // ramps and the two priors give stays narrow.
            const double roll = diag::softeningAt(diag::kReadilyRollingZt);
            EXPECT_NE(c.meaning.find("a roll of Z_t/Z_0 = 2 that no model named"), std::string::npos) << c.meaning;
            EXPECT_LT(c.high / (c.low / roll), 1.25) << "an interval as wide as the prior says nothing";
        }
    EXPECT_EQ(reported, 1);
    // Thermal memory and nothing else. Its r_A is not checked on this one set: with the bow side's
    // effusivity free it comes back at 1.00 for 0.8 (the rig's contact, 156 um, is 0.62 of the
    // model's radius, and the study finds r_A high on such rigs), which no tolerance can tell
    // from the search's starting point. r_A on mixed sets is measured over six seeds below.
    std::vector<std::string> found;
    for (const auto& f : o.d.findings) found.push_back(f.effect);
    EXPECT_EQ(found, std::vector<std::string>{"thermal_memory"});
}

// r_A on mixed-gesture sets, over six rigs: thermal memory is named on every one, and r_A is within
// the 10 % on at least four (docs/diagnosis-study.md: 4 of 6 through the CLI).
TEST(DiagnoseReferenceLong, MixedSetsFindThermalMemoryAndMostOfTheirFootprints)
{
    int within = 0;
    for (const std::uint64_t seed : {47u, 9121u, 9122u, 9123u, 9124u, 9125u}) {
        const Outcome o = run({"thermal_memory"}, {{"r_A", 0.8}}, seed, 8, "mixed");
        const Finding* thermal = findingOf(o.d, "thermal_memory");
        ASSERT_NE(thermal, nullptr) << "seed " << seed;
        within += std::abs(thermal->parameters.at("r_A")[0] / 0.8 - 1.0) <= kTolerance.at("r_A").value;
    }
    EXPECT_GE(within, 4);
}

// Rising-force strokes of a rig without any hidden effect, calibrated in newtons: nothing is
// named, and the offset comes out as the rig's (its prior spans -0.2..0.2 N). The short
// pre-slip windows of these strokes once let a fitted 50 Hz wave of +-40 N into the data.
TEST(DiagnoseReference, RisingForceStrokesOfANullRigNameNothing)
{
    const Outcome o = run({}, {}, 48, 8, "exp_force", "N");
    EXPECT_TRUE(o.d.findings.empty()) << o.d.findings.front().effect;
    double dc = 1e9;
    for (const auto& c : o.d.calibration)
        if (c.name == "dc_n") dc = c.value;
    EXPECT_NEAR(dc, o.truth.rig.at("dc_n"), 0.01);
    // The manifest states no Q, so the report says the model played its own string losses.
    int losses = 0;
    for (const auto& c : o.d.calibration)
        if (c.name == "string_q_f0" || c.name == "string_q_5khz") {
            ++losses;
            EXPECT_EQ(c.value, c.name == "string_q_f0" ? rosin::dsp::StringParams{}.qLow : rosin::dsp::StringParams{}.qHigh);
            EXPECT_NE(c.meaning.find("the manifest does not state it"), std::string::npos) << c.meaning;
        }
    EXPECT_EQ(losses, 2);
    for (const char* name : {"torsion_speed_ratio", "torsion_q"}) {
        const auto c = std::find_if(o.d.calibration.begin(), o.d.calibration.end(), [&](const auto& x) { return x.name == name; });
        ASSERT_NE(c, o.d.calibration.end()) << name;
        EXPECT_EQ(c->value, std::string(name) == "torsion_q" ? rosin::dsp::StringParams{}.qTorsion : rosin::dsp::StringParams{}.torsionSpeedRatio);
        EXPECT_NE(c->meaning.find("the manifest does not state it"), std::string::npos) << c->meaning;
    }
    EXPECT_FALSE(o.d.statedTorsionSpeedRatio.has_value());
    double peak = 0;
    for (const auto& f : o.d.measuredForce)
        for (double x : f) peak = std::max(peak, std::abs(x));
    EXPECT_LT(peak, 4.0) << "a bow force of at most 3 N cannot give this bridge force";
}

// Only rising-force strokes in volts: nothing sets the scale, and the set is refused saying why.
TEST(DiagnoseReference, RefusesAVoltSetOfOnlyRisingForceStrokes)
{
    SynthSpec spec;
    spec.generator = "reference";
    spec.gesture = "exp_force";
    spec.grid = 2;
    spec.seconds = 0.1;
    SynthTruth truth;
    const MeasurementSet set = synthesize(spec, truth);
    try {
        diagnose(set, DiagnoseOptions{});
        ADD_FAILURE() << "diagnosed";
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("rig.sensor.units"), std::string::npos) << e.what();
    }
}

/// A rig close to the waveguide: little stiffness, a stiff bridge and body, a fast sensor.
const std::map<std::string, double> kQuietRig{{"inharmonicity", 1e-8}, {"bridge_z0y", 1e-4}, {"body_z0y", 1e-4}, {"sensor_hz", 30000.0}, {"sensor_q", 0.7}, {"headroom", 0.8}};

// A string that rolls readily (Z_t/Z_0 = 1.5), on a rig whose string, bridge and sensor come close
// to the waveguide's (little stiffness, a stiff bridge, a fast sensor), in volts: the ramps' scale
// reads the rolling string as a stiffer one and inflates every force by about 15 % (this rig's
// c_t is 4.5 c), which a model with torsion is compared in (Engine::rampSoftening). Named, and the
// reported scale within 3 % of the rig's gain once the named torsion's softening is taken out. Compared unscaled, nothing was named and the scale 12 % high.
// The scale and the label, on one split: Z_t/Z_0 itself is the long test below (since the
// simulations carry the rig's own noise, 2026-11-29, this split puts it at 1.82, 22 % high).
TEST(DiagnoseReference, FindsAStronglyRollingStringAndTakesItsSofteningOutOfTheScale)
{
    const Outcome o = run({"torsional_compliance"}, {{"zt_ratio", 1.5}}, 7101, 12, "guettler", "V", kQuietRig);
    ASSERT_EQ(o.d.findings.size(), 1u);
    EXPECT_EQ(o.d.findings.front().effect, "torsional_compliance");
    double scale = 0;
    for (const auto& c : o.d.calibration)
        if (c.name == "scale_n_per_unit") scale = c.value;
    EXPECT_NEAR(scale * o.truth.gain, 1.0, 0.03);
}

// The same set diagnosed with three splits: torsion alone named and the scale within 3 % on each,
// the median Z_t/Z_0 within 20 % and its reported interval holding the truth on at least two.
// (Six minutes on 2 cores: `long`.)
TEST(DiagnoseReferenceLong, ARollingStringsZtIsWithinTwentyPercentOnTheMedianOfThreeSplits)
{
    std::vector<double> zt;
    int covered = 0;
    for (const Outcome& o : runSplits({"torsional_compliance"}, {{"zt_ratio", 1.5}}, 7101, {5, 6, 7}, 12, "guettler", "V", kQuietRig)) {
        ASSERT_EQ(o.d.findings.size(), 1u);
        const Finding& f = o.d.findings.front();
        ASSERT_EQ(f.effect, "torsional_compliance");
        zt.push_back(f.parameters.at("zt_ratio")[0]);
        const auto [lo, hi] = reportedInterval(f, "zt_ratio");
        covered += lo <= 1.5 && hi >= 1.5;
        double scale = 0;
        for (const auto& c : o.d.calibration)
            if (c.name == "scale_n_per_unit") scale = c.value;
        EXPECT_NEAR(scale * o.truth.gain, 1.0, 0.03);
    }
    std::sort(zt.begin(), zt.end());
    EXPECT_NEAR(zt[1] / 1.5, 1.0, 0.2) << "Z_t/Z_0 from three splits: " << zt[0] << ", " << zt[1] << ", " << zt[2];
    EXPECT_GE(covered, 2);
}

// Issue 20's open targets: these fail on today's diagnosis (torsion at Z_t/Z_0 = 1.6 is named
// but at 1.10, 31 % low; a -14 K rosin shift comes out near -20 K), so they run with the `long`
// label, not in CI.
TEST(DiagnoseReferenceLong, FindsTorsion) { expectDiagnosis(run({"torsional_compliance"}, {{"zt_ratio", 1.6}}, 44)); }

// The same quiet rig as the strongly rolling string above, with thermal memory beside the roll
// (Z_t/Z_0 = 1.3). Not met yet: the model at the rig's own values fits the fit strokes worse than
// thermal memory alone (0.117 against 0.104) while the simulations' noise is cleaner than the
// rig's, and better (0.074 against 0.105) only with the rig's noise shape (tried, not shipped)
// and only in a narrow valley of r_A, the bow side's effusivity and the tension, which the
// candidate's grid and COBYLA do not find: torsion came out at Z_t/Z_0 7.8, r_A 13-15 % high
// (docs/diagnosis-study.md, eighth session).
TEST(DiagnoseReferenceLong, FindsARollingStringBesideThermalMemory)
{
    expectDiagnosis(run({"thermal_memory", "torsional_compliance"}, {{"zt_ratio", 1.3}, {"r_A", 1.0}}, 7102, 12, "guettler", "V",
                        kQuietRig));
}

// Seed 2056's study set 36, made as the study made it: a contact (n 0.83) and a strong roll
// (Z_t/Z_0 1.52) on one rig. Rounds of single effects name nothing: the contact alone does not
// lower the test strokes' error and the roll alone fits worse than no effect. Tried together
// (`--pairs`) both are named, the exponent within 0.05 and the reported Z_t/Z_0 interval holding
// the truth (its value 2.6 is the torsion's usual miss). Three minutes on 2 cores: `long`.
TEST(DiagnoseReferenceLong, AContactAndAStrongRollThatOnlyFitTogetherAreNamedAsAPair)
{
    SynthTruth truth;
    const MeasurementSet set = studySet({"hertzian_contact", "torsional_compliance"}, 2056037, truth);
    ASSERT_NEAR(truth.params.at("zt_ratio"), 1.52, 0.01);
    ASSERT_NEAR(truth.params.at("load_exponent"), 0.826, 0.001);

    DiagnoseOptions singles;
    EXPECT_TRUE(diagnose(set, singles).findings.empty());
    DiagnoseOptions pairs;
    pairs.tryPairs = true;
    const Diagnosis d = diagnose(set, pairs);
    std::map<std::string, const Finding*> named;
    for (const auto& f : d.findings) named[f.effect] = &f;
    ASSERT_EQ(named.size(), 2u);
    ASSERT_TRUE(named.count("hertzian_contact") && named.count("torsional_compliance"));
    EXPECT_NEAR(named["hertzian_contact"]->parameters.at("load_exponent")[0], 0.826, 0.05);
    const auto [lo, hi] = reportedInterval(*named["torsional_compliance"], "zt_ratio");
    EXPECT_LE(lo, 1.52);
    EXPECT_GE(hi, 1.52);
    EXPECT_LT(hi, 7.5) << "the interval excludes no roll";
}

// Seed 2058's set 31 (thermal memory, a rate law, a contact of exponent 0.913 and a weak roll):
// round 1 names the rate law, and in round 2 the contact's first search, beside it, stalls at
// exponent 1.03 (no contact; validation fall 0.3 %, not significant). Searched again from there
// with a wider first step it falls 22 % and is named at 0.914. (The restart was judged on the
// fresh study of seed 2058, this set's: docs/diagnosis.md.)
TEST(DiagnoseReferenceLong, ALaterRoundsContactSearchedAgainIsNamedAtItsExponent)
{
    SynthTruth truth;
    const MeasurementSet set = studySet({"rate_dependence", "hertzian_contact", "torsional_compliance"}, 2058032, truth);
    ASSERT_NEAR(truth.params.at("load_exponent"), 0.913, 0.001);
    DiagnoseOptions once;
    once.restartContact = false;
    EXPECT_EQ(findingOf(diagnose(set, once), "hertzian_contact"), nullptr);
    const Diagnosis d = diagnose(set, DiagnoseOptions{});
    const Finding* contact = findingOf(d, "hertzian_contact");
    ASSERT_NE(contact, nullptr);
    const auto [lo, hi] = reportedInterval(*contact, "load_exponent");
    EXPECT_NEAR(contact->parameters.at("load_exponent")[0], 0.913, 0.03);
    EXPECT_LE(lo, 0.913);
    EXPECT_GE(hi, 0.913);
    EXPECT_LT(hi, 1.0) << "the interval excludes Amontons";
}

// Seed 2059's set 6 (thermal memory, a rate law, a contact, a roll of Z_t/Z_0 2.2, in volts), its
// tension and bow position stated to +-1 %: no roll is named and the roll's soft ramps read the
// sensor scale 7.8 % high. The priors' share of the interval no longer reaches the rig's scale
// (its low end 1.055 of it); the room for a roll no model named (x 0.912) is what holds it, and
// the interval stays narrow. Unstated (+-5 % and +-4 %), the priors alone held it (low end 0.984).
// One diagnosis of about a minute: `long`.
TEST(DiagnoseReferenceLong, AMissedRollsInflatedScaleIsHeldByTheRoomLeftForIt)
{
    SynthTruth truth;
    const Diagnosis d = diagnose(studySet({"rate_dependence", "hertzian_contact", "torsional_compliance"}, 2059007, truth, {},
                                          {{"tension", 0.01}, {"beta", 0.01}}),
                                 DiagnoseOptions{});
    ASSERT_NEAR(truth.params.at("zt_ratio"), 2.20, 0.01);
    ASSERT_EQ(findingOf(d, "torsional_compliance"), nullptr) << "the roll is named now: this test's premise is gone";
    const auto scale = std::find_if(d.calibration.begin(), d.calibration.end(), [](const auto& c) { return c.name == "scale_n_per_unit"; });
    ASSERT_NE(scale, d.calibration.end());
    const double value = scale->value * truth.gain, low = scale->low * truth.gain, high = scale->high * truth.gain;
    EXPECT_GT(value - 1.0, 0.06) << "the missed roll inflates the ramps' scale";
    EXPECT_LE(low, 1.0) << "the room for an unnamed roll holds the rig's scale";
    EXPECT_GE(high, 1.0);
    EXPECT_GT(low / diag::softeningAt(diag::kReadilyRollingZt), 1.0) << "without the room the interval would miss it";
    EXPECT_LT(high / low, 1.2) << "a measured rig's interval stays narrow";
    for (const auto& f : d.findings) EXPECT_NE(std::find(truth.effects.begin(), truth.effects.end(), f.effect), truth.effects.end()) << f.effect;
}

// Seed 2058's set 27 (thermal memory, a rate law of p 0.34, a contact of exponent 0.819 and a
// roll of Z_t/Z_0 2.57) is named exactly: the rate law in round 1, the contact in round 2, the
// roll in round 3. Each later winner is refitted without each earlier finding by the same search
// that found it, the roll from round 1's start and the contact restarted, so the model without
// the finding is searched as hard as the model with it. Refitted with the grid and one COBYLA
// search only, the models without the rate law and without the contact fitted worse, and the
// rises shown were 0.558 and 0.469 (round 3) and 0.442 (round 2); with the whole search they are
// 0.506, 0.410 and 0.359, and every finding still clears the 5 % threshold by far.
TEST(DiagnoseReferenceLong, AnEarlierFindingIsTestedAgainstAModelSearchedAsHard)
{
    SynthTruth truth;
    const MeasurementSet set = studySet({"rate_dependence", "hertzian_contact", "torsional_compliance"}, 2058028, truth);
    ASSERT_NEAR(truth.params.at("zt_ratio"), 2.57, 0.01);
    const Diagnosis d = diagnose(set, DiagnoseOptions{});
    for (const char* effect : {"thermal_memory", "rate_dependence", "hertzian_contact", "torsional_compliance"})
        EXPECT_NE(findingOf(d, effect), nullptr) << effect;
    EXPECT_EQ(d.findings.size(), 4u);
    auto keptShare = [&](int round, const std::string& effect) {
        for (const Trial& t : d.trials)
            if (t.round == round && t.effect == effect && t.verdict.rfind("kept beside", 0) == 0) return t.relativeGain;
        return -1.0;
    };
    EXPECT_NEAR(keptShare(3, "rate_dependence"), 0.506, 0.02);
    EXPECT_NEAR(keptShare(3, "hertzian_contact"), 0.410, 0.02);
    EXPECT_NEAR(keptShare(2, "rate_dependence"), 0.359, 0.02);
}

// Rule 4 asked of a round's own finding where the joint refit left it: seed 2079's set 6 (a 9.1 K
// shift) under its own split, as `rosin study --seed 2079 --split-per-set --diagnose-seed 2`
// diagnoses it. Round 1's shift passes rules 1-5 at 17.4 K; the joint refit moves it to 15.5 K,
// under the 15.7 K that rule 4 can name, so it is not named and not tried again. Before the
// rule, it was named there with a printed interval holding 0 K.
TEST(DiagnoseReferenceLong, ARoundsOwnFindingTheJointRefitMovesUnderRuleFourIsNotNamed)
{
    SynthTruth truth;
    const MeasurementSet set = studySet({"rosin_temperature_shift"}, 2079007, truth);
    ASSERT_NEAR(truth.params.at("shift_k"), 9.14, 0.01);
    DiagnoseOptions o;
    o.seed = perSetDiagnoseSeed(2, 2079007);
    const Diagnosis d = diagnose(set, o);
    EXPECT_NE(findingOf(d, "thermal_memory"), nullptr);
    EXPECT_EQ(findingOf(d, "rosin_temperature_shift"), nullptr);
    const auto unnamed = std::find_if(d.trials.begin(), d.trials.end(), [](const Trial& t) {
        return t.effect == "rosin_temperature_shift" && t.verdict.find("then the joint refit moved") != std::string::npos;
    });
    ASSERT_NE(unnamed, d.trials.end());
    EXPECT_EQ(unnamed->round, 1);
    EXPECT_FALSE(unnamed->kept);
    EXPECT_NEAR(unnamed->parameters.at("shift_k"), 17.4, 0.5);
    for (const Trial& t : d.trials) EXPECT_FALSE(t.round > 1 && t.effect == "rosin_temperature_shift") << "tried again in round " << t.round;
}

TEST(DiagnoseReferenceLong, FindsARosinShift) { expectDiagnosis(run({"rosin_temperature_shift"}, {{"r_A", 1.2}, {"shift_k", -14.0}}, 45)); }

// The set that made rule 6 and now meets rule 2's shift margin first: seed 2101's set 8, a rate law (p 0.54) on a string ten times
// stiffer than the rig prior's stiffest, built as `rosin study --seed 2101 --rig-param
// inharmonicity=1e-3` builds it. Before rule 6 it was named thermal memory and a +25 K rosin
// shift, which beat the rate law by 28.5 %; rule 6 then set it aside as a stand-in beside a
// residual beyond the usual one. Rule 2's 30 % margin for a shift over a rate law now refuses
// it before that. Thermal memory alone fits this stiff string worse than the baseline (-3.6 %)
// and the rate law does not beat the shift, so nothing is named: a miss, reported as a
// residual beyond the usual one, and no label the set does not hide.
TEST(DiagnoseReferenceLong, ARateLawOnAFarStifferStringIsNotNamedAsARosinShift)
{
    SynthTruth truth;
    const Diagnosis d = diagnose(studySet({"rate_dependence"}, 2101009, truth, {{"inharmonicity", 1e-3}}), DiagnoseOptions{});
    std::vector<std::string> found;
    for (const auto& f : d.findings) found.push_back(f.effect);
    for (const auto& e : found) EXPECT_NE(std::find(truth.effects.begin(), truth.effects.end(), e), truth.effects.end()) << e << " not hidden";
    EXPECT_TRUE(d.residual.beyondUsual) << d.residual.ratio << " floors";
    for (const auto& s : d.standIns) EXPECT_NE(s.effect, "rosin_temperature_shift");
    // the shift that stood in for the rate law: large, ahead of the rate law, and refused by the margin
    const auto refused = std::find_if(d.trials.begin(), d.trials.end(), [](const Trial& t) {
        return t.effect == "rosin_temperature_shift" && t.verdict.find("a rosin shift must clear") != std::string::npos;
    });
    ASSERT_NE(refused, d.trials.end());
    EXPECT_GT(refused->parameters.at("shift_k"), 15.0);
    EXPECT_GT(refused->overRival, 0.05);
    EXPECT_LT(refused->overRival, 0.3);
}

// Effects and rigs drawn truly at random from a seed printed here: run by hand or in `long`.
TEST(DiagnoseReferenceLong, RandomEffectsOnRandomRigs)
{
    const auto seed = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
    std::printf("DiagnoseReferenceLong seed %llu\n", static_cast<unsigned long long>(seed));
    std::mt19937_64 rng(seed);
    for (int k = 0; k < 6; ++k) {
        std::vector<std::string> effects;
        for (const auto& id : effectIds())
            if (rng() % 4 == 0) effects.push_back(id);
        SCOPED_TRACE("set " + std::to_string(k) + " of seed " + std::to_string(seed));
        expectDiagnosis(run(effects, {}, rng(), 10));
    }
}

// The noise a stroke's simulations carry is the rig's, read from the rests before the gestures:
// within 15 % of the white noise the rig added, on a quiet and a noisy rig and whether the string
// is as stiff as the model's or far stiffer. Read from the stroke itself (as until 2026-11-29), a
// quiet rig's "noise" is mostly the steps of the string's own waveform, 100 times the rig's
// and more again for a stiff string; the simulations then carried it, and the floor the
// unexplained residual is judged against rose with the very stiffness it should expose.
TEST(DiagnoseCalibration, TheSimulationsCarryTheRigsNoiseReadFromTheRestsWhateverTheStringsStiffness)
{
    struct Rig {
        double stiffness, noise;
    };
    for (const Rig rig : {Rig{5e-6, 1e-4}, Rig{1e-3, 1e-4}, Rig{1e-3, 5e-3}}) {
        SynthSpec spec;
        spec.generator = "reference";
        spec.seed = 5101;
        spec.grid = 4;
        spec.seconds = 0.3;
        spec.rig = {{"inharmonicity", rig.stiffness}, {"noise_n", rig.noise}};
        SynthTruth truth;
        const MeasurementSet set = synthesize(spec, truth);
        const diag::StringInfo info = diag::stringInfoOf(set);
        Diagnosis d;
        const std::vector<diag::Prepared> strokes = diag::prepareStrokes(set, info, DiagnoseOptions{}, d);
        const std::string where = "B " + std::to_string(rig.stiffness) + ", noise " + std::to_string(rig.noise) + " N";
        const auto reported = std::find_if(d.calibration.begin(), d.calibration.end(), [](const CalibrationValue& c) { return c.name == "noise_n"; });
        ASSERT_NE(reported, d.calibration.end()) << where;
        // In volts: the reported noise is in newtons through the calibrated scale, whose own error
        // (a few per cent) is part of the tolerance.
        EXPECT_NEAR(reported->value / rig.noise, 1.0, 0.15) << where;
        std::vector<double> fromStroke;
        for (const diag::Prepared& p : strokes) {
            EXPECT_DOUBLE_EQ(p.noise, reported->value) << where << ": one rig, one noise";
            fromStroke.push_back(diag::noiseLevel(p.force));
        }
        std::sort(fromStroke.begin(), fromStroke.end());
        if (rig.noise < 1e-3) {
            EXPECT_GT(fromStroke[fromStroke.size() / 2], 10.0 * rig.noise) << where << ": what the stroke itself reads";
        }
    }
}

// Cleaning takes out only what a recording shows: on a clean recording from the reference
// simulator (no DC, no hum) it removes less than the recording's own noise; where the rig adds
// a DC and 50 Hz hum, it finds them. (A ramp-intercept DC once took 0.03-0.14 N out of clean data.)
TEST(DiagnoseReference, CleaningLeavesACleanRecordingAlone)
{
    for (const bool dirty : {false, true}) {
        SynthSpec spec;
        spec.generator = "reference";
        spec.seed = 77;
        spec.grid = 4;
        spec.seconds = 0.3;
        spec.rig = {{"dc_n", dirty ? 0.2 : 0.0}, {"hum_hz", dirty ? 50.0 : 0.0}, {"hum_n", 0.02}, {"noise_n", 5e-4}, {"headroom", 0.8}};
        SynthTruth truth;
        const MeasurementSet set = synthesize(spec, truth);
        // As the diagnosis cleans: every recording chooses its hum (none, 50 or 60 Hz) and the set
        // takes what most chose; then, with the set's gain and hum fixed, each offset is found.
        auto input = [&](const MeasuredStroke& s) {
            ClassifierInput in = guettlerStrokeInput(s.signal, set.sampleRate, set.f0, set.beta, *set.z0, *set.tension, *set.length, s.accel);
            in.measured = true;
            return in;
        };
        std::map<double, int> votes;
        for (const auto& s : set.strokes)
            if (const Calibration c = calibrateRecording(input(s)); c.rampFitted) ++votes[c.hum];
        const double setHum = std::max_element(votes.begin(), votes.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
        EXPECT_EQ(setHum, dirty ? 50.0 : 0.0) << (dirty ? "dirty" : "clean");
        std::vector<double> dcs;
        for (const auto& s : set.strokes) {
            ClassifierInput in = input(s);
            in.knownGain = truth.gain;
            in.hum = setHum;
            if (const Calibration c = calibrateRecording(in); c.rampFitted) dcs.push_back(c.dc / truth.gain); // -> N
        }
        ASSERT_GE(dcs.size(), 10u);
        const double wanted = dirty ? 0.2 : 0.0, tolerance = dirty ? 0.005 : 3.0 * 5e-4;
        int close = 0;
        for (double dc : dcs) close += std::abs(dc - wanted) < tolerance;
        std::nth_element(dcs.begin(), dcs.begin() + static_cast<long>(dcs.size() / 2), dcs.end());
        EXPECT_NEAR(dcs[dcs.size() / 2], wanted, tolerance) << (dirty ? "dirty" : "clean") << " set's offset";
        EXPECT_GE(close, static_cast<int>(0.85 * static_cast<double>(dcs.size()))) << (dirty ? "dirty" : "clean");
    }
}
