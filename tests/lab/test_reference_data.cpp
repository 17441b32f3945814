// `rosin synth-data --generator reference`: what goes into the set (only what a lab writes
// down) and what goes into the truth (everything the rig drew).
#include <gtest/gtest.h>
#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include "rosin/dsp/StringParams.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/ReferenceData.h"

using namespace rosin::lab;
namespace fs = std::filesystem;

namespace {
SynthSpec small(std::uint64_t seed)
{
    SynthSpec s;
    s.generator = "reference";
    s.seed = seed;
    s.grid = 2;
    s.seconds = 0.06;
    s.twoEnded = 1;
    return s;
}

/// What a command-line parser says when it refuses these arguments ("accepted" when it does not).
template <class Parse>
std::string refusalOf(Parse parse, const std::vector<std::string>& args)
{
    try {
        parse(args);
    } catch (const LabError& e) {
        return std::string(e.what());
    }
    return std::string("accepted");
}

fs::path fresh(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("rosin-refdata-" + std::to_string(::getpid()) + "-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}
} // namespace

TEST(ReferenceSynthData, ManifestCarriesOnlyWhatALabWritesDown)
{
    SynthSpec spec = small(7);
    spec.effects = {"hertzian_contact"};
    SynthTruth truth;
    const MeasurementSet set = synthesize(spec, truth);
    const fs::path dir = fresh("manifest");
    writeMeasurementSet(dir / "set", set, SF_FORMAT_FLOAT);
    const MeasurementSet back = readMeasurementSet(dir / "set");
    fs::remove_all(dir);
    // Nominal values, not the rig's: the tension and bow position are off by a few percent.
    EXPECT_DOUBLE_EQ(*back.tension, 102.6);
    EXPECT_DOUBLE_EQ(back.beta, 0.0899);
    EXPECT_NE(truth.rig.at("tension_n"), 102.6);
    EXPECT_NEAR(truth.rig.at("tension_n") / 102.6 - 1.0, truth.rig.at("tension_error"), 1e-12);
    EXPECT_NEAR(truth.rig.at("beta") / 0.0899 - 1.0, truth.rig.at("beta_error"), 1e-12);
    for (const auto& s : back.strokes) EXPECT_FALSE(s.trigger.has_value()) << "the rig does not know its trigger";
    // Every drawn rig value is in the truth, within its prior.
    for (const RigPrior& p : referenceRigPriors()) {
        ASSERT_TRUE(truth.rig.count(p.key)) << p.key;
        if (p.key != "hum_hz" && p.key != "headroom") {
            EXPECT_GE(truth.rig.at(p.key), p.lo) << p.key;
            EXPECT_LE(truth.rig.at(p.key), p.hi) << p.key;
        }
    }
    const auto [lo, hi] = referenceEffectPriors().at("load_exponent");
    EXPECT_GE(truth.params.at("load_exponent"), lo);
    EXPECT_LE(truth.params.at("load_exponent"), hi);
    EXPECT_EQ(truth.strokes.size(), 4u);
    // The lab's steady-sliding measurement comes back as written, and follows the rig's rosin.
    ASSERT_EQ(back.steady.size(), set.steady.size());
    for (std::size_t i = 0; i < back.steady.size(); ++i) EXPECT_NEAR(back.steady[i].mu, set.steady[i].mu, 1e-8);
    EXPECT_NEAR(back.steady.front().mu / (1.2 * truth.rig.at("mu_level")), 1.0, 0.06);
    ASSERT_EQ(back.twoEnded.size(), 1u);
}

TEST(ReferenceSynthData, FixedRigValuesAreKeptAndUnknownOnesRefused)
{
    SynthSpec spec = small(3);
    spec.rig = {{"noise_n", 0.0}, {"hum_hz", 0.0}, {"dc_n", 0.0}, {"headroom", 1.3}};
    SynthTruth truth;
    const MeasurementSet set = synthesize(spec, truth);
    EXPECT_EQ(truth.rig.at("noise_n"), 0.0);
    EXPECT_EQ(truth.rig.at("hum_hz"), 0.0);
    // Above full scale the recording clips at the converter's rails.
    EXPECT_GT(truth.clippedFraction, 0.0);
    double peak = 0;
    for (const auto& s : set.strokes)
        for (double v : s.signal) peak = std::max(peak, std::abs(v));
    EXPECT_LE(peak, 0.999);
    spec.rig = {{"noise", 0.01}};
    EXPECT_THROW(synthesize(spec, truth), LabError);
    spec = small(3);
    spec.oversampling = 2;
    EXPECT_THROW(synthesize(spec, truth), LabError);
}

// A set in newtons carries its sensor's calibration error, drawn apart from the rest of the rig:
// fixing or drawing it moves no other value, and a volt set does not use it at all.
TEST(ReferenceSynthData, ANewtonSetCarriesItsCalibrationErrorAndNothingElseMoves)
{
    auto make = [](const std::string& units, std::optional<double> error, SynthTruth& truth) {
        SynthSpec spec = small(5);
        spec.units = units;
        if (error) spec.rig = {{"calibration_error", *error}};
        return synthesize(spec, truth);
    };
    SynthTruth drawn, low, high, voltDrawn, voltFixed;
    make("N", std::nullopt, drawn);
    const MeasurementSet nLow = make("N", -0.02, low), nHigh = make("N", 0.015, high);
    const MeasurementSet v = make("V", std::nullopt, voltDrawn), vFixed = make("V", 0.015, voltFixed);
    const double e = drawn.rig.at("calibration_error");
    EXPECT_GE(e, -0.02);
    EXPECT_LE(e, 0.02);
    EXPECT_NE(e, 0.0);
    EXPECT_DOUBLE_EQ(drawn.gain, 1.0 + e);
    EXPECT_DOUBLE_EQ(high.gain, 1.015);
    for (const auto& [key, value] : drawn.rig) {
        if (key == "calibration_error") continue;
        EXPECT_EQ(high.rig.at(key), value) << key << " moved with the calibration error";
    }
    // Each newton file is the true force times its gain: the same rig read through two sensors.
    ASSERT_EQ(nLow.strokes.size(), nHigh.strokes.size());
    for (std::size_t k = 0; k < nLow.strokes.size(); ++k) {
        const auto& a = nLow.strokes[k].signal;
        const auto& b = nHigh.strokes[k].signal;
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t i = 0; i < a.size(); i += 97) EXPECT_NEAR(b[i] * 0.98, a[i] * 1.015, 1e-12 * (1.0 + std::abs(a[i]))) << "stroke " << k;
    }
    // A volt set's gain comes from its headroom, whatever the calibration error.
    EXPECT_DOUBLE_EQ(voltDrawn.gain, voltFixed.gain);
    for (std::size_t k = 0; k < v.strokes.size(); ++k) EXPECT_EQ(v.strokes[k].signal, vFixed.strokes[k].signal);
}

// --generator model-on-rig: the reference generator's draws, played by dsp/'s model. What the model
// holds fixed is recorded at the model's values, and the rig's tension and bow position reach the
// strokes: a sticking bow's ramp is the bridge side's stiffness T / (beta L) times the bow's travel.
TEST(ReferenceSynthData, AModelOnRigSetIsTheReferenceRigPlayedByTheModel)
{
    auto make = [](const std::string& generator, double tensionError, double betaError, SynthTruth& truth) {
        SynthSpec spec = small(23);
        spec.generator = generator;
        spec.units = "N";
        spec.seconds = 0.03;
        spec.effects = {"torsional_compliance"};
        spec.rig = {{"noise_n", 0.0}, {"hum_hz", 0.0}, {"dc_n", 0.0}, {"calibration_error", 0.0}, {"tension_error", tensionError},
                    {"beta_error", betaError}};
        return synthesize(spec, truth);
    };
    SynthTruth ref, soft, stiff;
    const MeasurementSet r = make("reference", -0.03, 0.02, ref);
    const MeasurementSet low = make("model-on-rig", -0.03, 0.02, soft), high = make("model-on-rig", 0.04, -0.025, stiff);
    EXPECT_EQ(soft.generator, "model-on-rig");
    EXPECT_EQ(soft.params, ref.params);
    EXPECT_EQ(soft.triggers, ref.triggers);
    for (const char* drawn : {"mu_level", "rod_effusivity", "sensor_hz", "tension_n", "beta"}) EXPECT_EQ(soft.rig.at(drawn), ref.rig.at(drawn)) << drawn;
    // What the model holds is its own: the truth says what really made the strokes.
    EXPECT_EQ(soft.rig.at("contact_radius_um"), 250.0);
    EXPECT_EQ(soft.rig.at("torsion_speed_ratio"), 5.2);
    EXPECT_EQ(soft.rig.at("bridge_z0y"), 0.0);
    EXPECT_NE(ref.rig.at("contact_radius_um"), 250.0);
    EXPECT_NE(r.strokes[0].signal, low.strokes[0].signal) << "another string made them";
    EXPECT_NE(low.description.find("model-on-rig"), std::string::npos);
    // The slowest, heaviest stroke (a00_f01) sticks through its first 10 ms after the trigger:
    // mean force from 4 to 10 ms, the two rigs' ratio against their stiffness ratio.
    auto ramp = [](const MeasurementSet& set, const SynthTruth& t) {
        const auto& s = set.strokes[2];
        const double start = t.triggers.at(s.id);
        double sum = 0;
        int n = 0;
        for (std::size_t i = 0; i < s.signal.size(); ++i) {
            const double time = static_cast<double>(i) / set.sampleRate - start;
            if (time >= 0.004 && time < 0.010) sum += s.signal[i], ++n;
        }
        return sum / n;
    };
    ASSERT_EQ(low.strokes[2].id, "a00_f01");
    const double expected = (1.04 / 0.975) / (0.97 / 1.02); // T / beta of the two rigs (same jittered gesture)
    EXPECT_NEAR(ramp(high, stiff) / ramp(low, soft) / expected, 1.0, 0.005); // measured 1.00016
}

// --rig-param of synth-data and study: NAME=VALUE, each name one the generator draws and each
// value a finite number; anything else is refused naming the value, before a set is simulated.
TEST(ReferenceSynthData, RigValuesFromTheCommandLineAreParsedOrRefusedByName)
{
    const auto rig = parseRigValues({"inharmonicity=1e-3", "bridge_z0y=0.25"});
    ASSERT_EQ(rig.size(), 2u);
    EXPECT_DOUBLE_EQ(rig.at("inharmonicity"), 1e-3);
    EXPECT_DOUBLE_EQ(rig.at("bridge_z0y"), 0.25);
    const auto refusal = [](const std::vector<std::string>& args) { return refusalOf(parseRigValues, args); };
    EXPECT_NE(refusal({"stiffness=1e-3"}).find("unknown rig value 'stiffness'"), std::string::npos);
    EXPECT_NE(refusal({"inharmonicity"}).find("expected NAME=VALUE"), std::string::npos);
    EXPECT_NE(refusal({"inharmonicity=1e-3x"}).find("has no number"), std::string::npos);
    EXPECT_NE(refusal({"inharmonicity=nan"}).find("inharmonicity must be a finite number"), std::string::npos);
    EXPECT_NE(refusal({"bridge_z0y="}).find("has no number"), std::string::npos);
}

// --param-range of study: NAME=LO:HI narrows a hidden parameter's draw; a range outside the
// prior (where the generator was never meant to go), an empty one or a malformed one is refused.
TEST(ReferenceSynthData, ParameterRangesAreParsedOrRefusedByName)
{
    const auto ranges = parseParamRanges({"zt_ratio=1.2:3", "shift_k=10:20"});
    ASSERT_EQ(ranges.size(), 2u);
    EXPECT_EQ(ranges.at("zt_ratio"), std::make_pair(1.2, 3.0));
    EXPECT_EQ(ranges.at("shift_k"), std::make_pair(10.0, 20.0));
    const auto refusal = [](const std::vector<std::string>& args) { return refusalOf(parseParamRanges, args); };
    EXPECT_NE(refusal({"zt=1.2:3"}).find("unknown parameter 'zt'"), std::string::npos);
    EXPECT_NE(refusal({"zt_ratio=1.2"}).find("expected NAME=LO:HI"), std::string::npos);
    EXPECT_NE(refusal({"zt_ratio"}).find("expected NAME=LO:HI"), std::string::npos);
    EXPECT_NE(refusal({"zt_ratio=a:3"}).find("needs two numbers"), std::string::npos);
    EXPECT_NE(refusal({"zt_ratio=3:1.5"}).find("LO < HI"), std::string::npos);
    EXPECT_NE(refusal({"zt_ratio=nan:3"}).find("LO < HI"), std::string::npos);
    EXPECT_NE(refusal({"zt_ratio=0.5:3"}).find("within its prior, 1.2 to 8"), std::string::npos);
    EXPECT_NE(refusal({"load_exponent=0.6:1.2"}).find("within its prior"), std::string::npos);
}

// A narrowed draw lands in its range and moves nothing else: the rig and the other hidden
// parameters of a set are those the same seed draws without it (the draw takes one number
// from the stream either way).
TEST(ReferenceSynthData, ANarrowedRangeMovesOnlyItsOwnParameter)
{
    SynthSpec spec = small(31);
    spec.effects = {"thermal_memory", "torsional_compliance"};
    SynthTruth whole, narrowed;
    synthesize(spec, whole);
    spec.paramRanges = {{"zt_ratio", {1.2, 1.5}}};
    synthesize(spec, narrowed);
    const double zt = narrowed.params.at("zt_ratio");
    EXPECT_GE(zt, 1.2);
    EXPECT_LE(zt, 1.5);
    // The same uniform number, mapped onto the narrower range.
    const double u = (whole.params.at("zt_ratio") - 1.2) / (8.0 - 1.2);
    EXPECT_NEAR(zt, 1.2 + 0.3 * u, 1e-12);
    EXPECT_EQ(narrowed.params.at("r_A"), whole.params.at("r_A"));
    EXPECT_EQ(narrowed.rig, whole.rig);
    spec.paramRanges = {{"zt_ratio", {0.9, 1.5}}};
    EXPECT_THROW(synthesize(spec, narrowed), LabError) << "a range outside the prior reached the simulator";
}

// --stated-uncertainty: a lab's statement of what it measured names tension or beta and a
// fraction that a manifest accepts and that is no wider than the generator's own spread.
TEST(ReferenceSynthData, StatedUncertaintiesAreParsedOrRefusedByName)
{
    const auto stated = parseStatedUncertainties({"tension=0.01", "beta=0.005"});
    ASSERT_EQ(stated.size(), 2u);
    EXPECT_EQ(stated.at("tension"), 0.01);
    EXPECT_EQ(stated.at("beta"), 0.005);
    const auto refusal = [](const std::vector<std::string>& args) { return refusalOf(parseStatedUncertainties, args); };
    EXPECT_NE(refusal({"length=0.01"}).find("unknown rig value 'length' (tension, beta, q, torsion)"), std::string::npos);
    EXPECT_EQ(parseStatedUncertainties({"torsion=0.05"}).at("torsion"), 0.05);
    EXPECT_NE(refusal({"torsion=0.4"}).find("torsion must be a fraction from 0.001 to 0.3"), std::string::npos);
    EXPECT_EQ(parseStatedUncertainties({"q=0.1"}).at("q"), 0.1);
    EXPECT_NE(refusal({"q=0.5"}).find("q must be a fraction from 0.001 to 0.3"), std::string::npos);
    EXPECT_NE(refusal({"q=0"}).find("q must be a fraction"), std::string::npos);
    EXPECT_NE(refusal({"tension_error=0.01"}).find("unknown rig value"), std::string::npos);
    EXPECT_NE(refusal({"tension"}).find("expected NAME=FRACTION"), std::string::npos);
    EXPECT_NE(refusal({"tension=1%"}).find("has no number"), std::string::npos);
    EXPECT_NE(refusal({"tension=0.05"}).find("tension must be a fraction from 0.001 to 0.04"), std::string::npos);
    EXPECT_NE(refusal({"beta=0.035"}).find("beta must be a fraction from 0.001 to 0.03"), std::string::npos);
    EXPECT_NE(refusal({"beta=0.0005"}).find("from 0.001"), std::string::npos);
    EXPECT_NE(refusal({"beta=nan"}).find("beta must be"), std::string::npos);
}

// A lab that measured its tension to +-1 % and its bow position to +-0.5 %: the rig's errors
// fall within that, drawn from the same stream numbers as the unmeasured rig (every other rig
// value unchanged), and the manifest written and read back states both.
TEST(ReferenceSynthData, AStatedUncertaintyBoundsTheRigsErrorAndTheManifestSaysIt)
{
    SynthSpec spec = small(33);
    spec.effects = {"torsional_compliance"};
    SynthTruth unmeasured, measured;
    const MeasurementSet plain = synthesize(spec, unmeasured);
    EXPECT_FALSE(plain.tensionUncertainty.has_value());
    spec.statedUncertainty = {{"tension", 0.01}, {"beta", 0.005}};
    const MeasurementSet set = synthesize(spec, measured);
    EXPECT_NEAR(measured.rig.at("tension_error"), unmeasured.rig.at("tension_error") * 0.01 / 0.04, 1e-15);
    EXPECT_NEAR(measured.rig.at("beta_error"), unmeasured.rig.at("beta_error") * 0.005 / 0.03, 1e-15);
    EXPECT_LE(std::abs(measured.rig.at("tension_error")), 0.01);
    EXPECT_LE(std::abs(measured.rig.at("beta_error")), 0.005);
    EXPECT_NEAR(measured.rig.at("tension_n") / 102.6 - 1.0, measured.rig.at("tension_error"), 1e-12);
    for (const auto& [key, value] : unmeasured.rig) {
        const bool follows = key == "tension_error" || key == "beta_error" || key == "tension_n" || key == "beta" || key == "z0_kg_per_s" || key == "cells";
        if (!follows) {
            EXPECT_EQ(measured.rig.at(key), value) << key << " moved";
        }
    }
    EXPECT_EQ(measured.params, unmeasured.params);
    const fs::path dir = fresh("stated");
    writeMeasurementSet(dir / "set", set, SF_FORMAT_FLOAT);
    const MeasurementSet back = readMeasurementSet(dir / "set");
    fs::remove_all(dir);
    ASSERT_TRUE(back.tensionUncertainty.has_value());
    ASSERT_TRUE(back.betaUncertainty.has_value());
    EXPECT_DOUBLE_EQ(*back.tensionUncertainty, 0.01);
    EXPECT_DOUBLE_EQ(*back.betaUncertainty, 0.005);
    EXPECT_DOUBLE_EQ(*back.tension, 102.6) << "the manifest keeps the nominal tension";
    spec.generator = "model";
    EXPECT_THROW(synthesize(spec, measured), LabError) << "the model generator has no rig to measure";
}

// A lab that measured its string's Q (+-10 %) or its torsional constants (+-5 %): the manifest
// states each pair within that of the rig's own (each value its own error), and the rig, the
// hidden parameters and every recording are those of the same rig unmeasured. The model-on-rig
// generator states the values its string had (the model's own).
TEST(ReferenceSynthData, StatedStringConstantsAreTheRigsWithinTheirFractionAndMoveNothingElse)
{
    struct Pair {
        const char* name;
        double fraction;
        const char *rigA, *rigB, *statedA;
        std::function<std::pair<std::optional<double>, std::optional<double>>(const MeasurementSet&)> stated;
        double modelA, modelB;
    };
    const rosin::dsp::StringParams own;
    const Pair pairs[]{{"q", 0.1, "q_low", "q_high", "q_f0_stated", [](const MeasurementSet& m) { return std::pair{m.qAtF0, m.qAt5kHz}; },
                        own.qLow, own.qHigh},
                       {"torsion", 0.05, "torsion_speed_ratio", "q_torsion", "torsion_speed_ratio_stated",
                        [](const MeasurementSet& m) { return std::pair{m.torsionSpeedRatio, m.qTorsion}; }, own.torsionSpeedRatio, own.qTorsion}};
    SynthSpec base = small(34);
    base.effects = {"torsional_compliance"};
    SynthTruth unmeasured;
    const MeasurementSet plain = synthesize(base, unmeasured);
    for (const Pair& p : pairs) {
        SCOPED_TRACE(p.name);
        EXPECT_FALSE(p.stated(plain).first.has_value());
        SynthSpec spec = base;
        spec.statedUncertainty = {{p.name, p.fraction}};
        SynthTruth measured;
        const MeasurementSet set = synthesize(spec, measured);
        const auto [a, b] = p.stated(set);
        ASSERT_TRUE(a && b);
        const double ea = *a / unmeasured.rig.at(p.rigA) - 1.0, eb = *b / unmeasured.rig.at(p.rigB) - 1.0;
        EXPECT_LE(std::abs(ea), p.fraction);
        EXPECT_LE(std::abs(eb), p.fraction);
        EXPECT_NE(ea, eb) << "one error drawn for both";
        EXPECT_EQ(measured.rig.at(p.statedA), *a);
        for (const auto& [key, value] : unmeasured.rig) EXPECT_EQ(measured.rig.at(key), value) << key << " moved";
        EXPECT_EQ(measured.params, unmeasured.params);
        ASSERT_EQ(set.strokes.size(), plain.strokes.size());
        for (std::size_t i = 0; i < set.strokes.size(); ++i) EXPECT_EQ(set.strokes[i].signal, plain.strokes[i].signal) << "stroke " << i;
        // Another seed draws other errors.
        SynthSpec other = spec;
        other.seed = 35;
        SynthTruth otherTruth;
        const MeasurementSet otherSet = synthesize(other, otherTruth);
        EXPECT_NE(*p.stated(otherSet).first / otherTruth.rig.at(p.rigA) - 1.0, ea);
        spec.generator = "model-on-rig";
        SynthTruth modelTruth;
        const auto [ma, mb] = p.stated(synthesize(spec, modelTruth));
        EXPECT_LE(std::abs(*ma / p.modelA - 1.0), p.fraction);
        EXPECT_LE(std::abs(*mb / p.modelB - 1.0), p.fraction);
    }
    // Both stated at once: each pair's errors come from a stream of its own.
    SynthSpec both = base;
    both.statedUncertainty = {{"q", 0.1}, {"torsion", 0.05}};
    SynthTruth bothTruth, qTruth, torsionTruth;
    const MeasurementSet bothSet = synthesize(both, bothTruth);
    SynthSpec qOnly = base, torsionOnly = base;
    qOnly.statedUncertainty = {{"q", 0.1}};
    torsionOnly.statedUncertainty = {{"torsion", 0.05}};
    const MeasurementSet qSet = synthesize(qOnly, qTruth), torsionSet = synthesize(torsionOnly, torsionTruth);
    EXPECT_EQ(bothSet.qAtF0, qSet.qAtF0);
    EXPECT_EQ(bothSet.qAt5kHz, qSet.qAt5kHz);
    EXPECT_EQ(bothSet.torsionSpeedRatio, torsionSet.torsionSpeedRatio);
    EXPECT_EQ(bothSet.qTorsion, torsionSet.qTorsion);
}

// The one reading of "is this text a number" behind every command-line value and data field.
TEST(ReferenceSynthData, AWholeNumberIsAllOfTheTextAndNothingMore)
{
    EXPECT_EQ(wholeNumber("1e-3"), 1e-3);
    EXPECT_EQ(wholeNumber("-0.25"), -0.25);
    EXPECT_EQ(wholeNumber(" 4"), 4.0); // leading blanks, as std::stod reads them
    for (const char* no : {"", "abc", "1.2x", "1.2 ", "0x", "1e", "--1"}) EXPECT_FALSE(wholeNumber(no).has_value()) << "'" << no << "'";
    // NaN and infinity parse: each caller refuses them in its own words
    ASSERT_TRUE(wholeNumber("nan").has_value());
    EXPECT_TRUE(std::isnan(*wholeNumber("nan")));
    EXPECT_TRUE(std::isinf(*wholeNumber("inf")));
}

TEST(ReferenceSynthData, BrokenSteadySlidingFileIsNamedWithItsLine)
{
    SynthTruth truth;
    const MeasurementSet set = synthesize(small(5), truth);
    const fs::path dir = fresh("steady");
    writeMeasurementSet(dir / "set", set, SF_FORMAT_FLOAT);
    std::ofstream(dir / "set" / "steady_sliding.csv") << "speed_m_s,mu\n0.01,0.9\n0.1,oops\n";
    try {
        readMeasurementSet(dir / "set");
        ADD_FAILURE() << "a broken steady_sliding.csv was read";
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("steady_sliding.csv:3"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("'mu'"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}
