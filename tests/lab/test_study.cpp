// The study harness (`rosin study`) scores the diagnosis: its plan, its refusal to mix two studies
// in one folder, and its counting, checked on hand-written truths and findings whose scores are
// known. (The study's own run is minutes per set: it is run by hand, see docs/diagnosis-study.md.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>

#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/Study.h"

using namespace rosin::lab;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
fs::path freshDir(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("rosin-study-test-" + name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

/// The folder a study keeps set `index` in (DIR/sets/NNN).
fs::path setDir(const fs::path& dir, int index)
{
    char name[16];
    std::snprintf(name, sizeof name, "%03d", index);
    return dir / "sets" / name;
}

/// Why pooling `studies` into `out` was refused ("pooled" when it was not).
std::string poolRefusal(const fs::path& out, const std::vector<fs::path>& studies)
{
    try {
        scoreStudies(out, studies);
    } catch (const LabError& e) {
        return e.what();
    }
    return "pooled";
}

/// Pools `study` with an empty 3x3 study of the whole population (seed `seed`, written into
/// `whole`) into `out`, and returns why that was refused ("pooled" when it was not).
std::string poolWithADrawnStudy(const fs::path& study, const fs::path& whole, const fs::path& out, int seed)
{
    std::ofstream(whole / "plan.json") << json{{"grid", 3}, {"seed", seed}, {"sets", json::array()}}.dump();
    fs::create_directories(whole / "sets");
    return poolRefusal(out, {study, whole});
}

/// A 3x3 study of `sets` sets (`nulls` of them null) from `seed` that only makes its sets.
StudyOptions madeOnly(int sets, int nulls, std::uint64_t seed)
{
    StudyOptions o;
    o.sets = sets;
    o.nulls = nulls;
    o.grid = 3;
    o.seed = seed;
    o.generateOnly = true;
    return o;
}

/// Runs study `o` into `first`; then, changed by `change`, checks that `first`'s folder refuses to
/// resume as the changed study (`why` says what that would have mixed) and runs it into `second`.
/// Returns both plans.
std::pair<json, json> studiesBeforeAndAfter(const fs::path& first, const fs::path& second, StudyOptions& o,
                                            const std::function<void(StudyOptions&)>& change, const char* why)
{
    runStudy(first, o);
    change(o);
    EXPECT_THROW(runStudy(first, o), LabError) << why;
    runStudy(second, o);
    json a, b;
    std::ifstream(first / "plan.json") >> a;
    std::ifstream(second / "plan.json") >> b;
    return {a, b};
}

void writeSet(const fs::path& dir, int index, const json& truth, const json& diagnosis)
{
    const fs::path here = setDir(dir, index);
    fs::create_directories(here / "diagnosis");
    std::ofstream(here / "truth.json") << truth.dump();
    std::ofstream(here / "diagnosis" / "diagnosis.json") << diagnosis.dump();
}

json finding(const std::string& effect, const std::string& parameter, double value, double low, double high)
{
    return {{"effect", effect}, {"parameters", {{parameter, {{"value", value}, {"ci95", {low, high}}}}}}};
}

json diagnosis(const json& findings) { return {{"findings", findings}, {"gain", {{"baseline", 0.3}, {"final", 0.08}}}}; }

/// A diagnosis naming thermal memory with r_A at value [low, high] and the further interval fields given.
json thermalDiagnosis(double value, double low, double high, const json& fields)
{
    json f = finding("thermal_memory", "r_A", value, low, high);
    f["parameters"]["r_A"].update(fields);
    return diagnosis(json::array({f}));
}
} // namespace

TEST(Study, PlanHasTheAskedNullsAndMixOfSinglesDoublesAndTriples)
{
    StudyOptions o;
    o.sets = 40;
    o.nulls = 10;
    o.seed = 77;
    const std::vector<StudySet> plan = planStudy(o);
    ASSERT_EQ(plan.size(), 40u);
    int bySize[4] = {0, 0, 0, 0};
    std::set<std::uint64_t> seeds;
    for (const StudySet& s : plan) {
        ASSERT_LE(s.effects.size(), 3u);
        ++bySize[s.effects.size()];
        seeds.insert(s.seed);
        std::set<std::string> distinct(s.effects.begin(), s.effects.end());
        EXPECT_EQ(distinct.size(), s.effects.size()) << "set " << s.index << " names an effect twice";
    }
    // 30 sets with effects: 45 % singles (13.5 -> 14), 35 % doubles (10.5 -> 11), the rest triples.
    EXPECT_EQ(bySize[0], 10);
    EXPECT_EQ(bySize[1], 14);
    EXPECT_EQ(bySize[2], 11);
    EXPECT_EQ(bySize[3], 5);
    EXPECT_EQ(seeds.size(), plan.size()) << "every set draws its own rig";
    // The plan follows from the seed alone, and another seed gives another order.
    const std::vector<StudySet> again = planStudy(o);
    for (std::size_t k = 0; k < plan.size(); ++k) EXPECT_EQ(again[k].effects, plan[k].effects);
    o.seed = 78;
    const std::vector<StudySet> other = planStudy(o);
    int differ = 0;
    for (std::size_t k = 0; k < plan.size(); ++k) differ += other[k].effects != plan[k].effects;
    EXPECT_GT(differ, 10);
}

TEST(Study, PlanVersionOneIsThePlanOfTheEarlierStudies)
{
    // Seed 2041's study (docs/diagnosis-study.md) was planned before versions existed: version 1
    // must plan it again set for set, or its kept sets no longer match their plan.
    StudyOptions o;
    o.sets = 40;
    o.nulls = 10;
    o.seed = 2041;
    o.plan = 1;
    const std::vector<StudySet> plan = planStudy(o);
    const std::vector<std::vector<std::string>> recorded{{"rate_dependence"}, {"rosin_temperature_shift"}, {"thermal_memory", "hertzian_contact"},
                                                         {},                  {"rosin_temperature_shift"}, {"hertzian_contact"}};
    for (std::size_t k = 0; k < recorded.size(); ++k) EXPECT_EQ(plan[k].effects, recorded[k]) << "set " << k;
    EXPECT_EQ(plan[0].seed, 2041001u);
}

TEST(Study, OnlyPlanVersionTwoHidesARateLawBesideAShift)
{
    auto pairs = [](const std::vector<StudySet>& plan) {
        int n = 0;
        for (const StudySet& s : plan) {
            const bool rate = std::find(s.effects.begin(), s.effects.end(), "rate_dependence") != s.effects.end();
            const bool shift = std::find(s.effects.begin(), s.effects.end(), "rosin_temperature_shift") != s.effects.end();
            n += rate && shift;
        }
        return n;
    };
    StudyOptions o;
    o.sets = 40;
    o.nulls = 10;
    for (std::uint64_t seed = 2030; seed < 2045; ++seed) {
        o.seed = seed;
        o.plan = 1;
        EXPECT_EQ(pairs(planStudy(o)), 0) << "seed " << seed;
        o.plan = 2;
        // 11 doubles dealt from 9 pairs: every pair once, two of them twice.
        const int n = pairs(planStudy(o));
        EXPECT_GE(n, 1) << "seed " << seed;
        EXPECT_LE(n, 2) << "seed " << seed;
    }
    o.plan = 3;
    EXPECT_THROW(planStudy(o), LabError);
}

TEST(Study, PlanRefusesMoreNullsThanSets)
{
    StudyOptions o;
    o.sets = 5;
    o.nulls = 6;
    EXPECT_THROW(planStudy(o), LabError);
}

TEST(Study, AFolderResumesOnlyTheStudyItHolds)
{
    const fs::path dir = freshDir("resume");
    StudyOptions o;
    o.sets = 4;
    o.nulls = 1;
    o.seed = 5;
    json plan = json::array();
    for (const StudySet& s : planStudy(o)) plan.push_back({{"index", s.index}, {"seed", s.seed}, {"effects", s.effects}});
    std::ofstream(dir / "plan.json") << json{{"grid", o.grid}, {"seed", o.seed}, {"sets", plan}}.dump(1);
    StudyOptions other = o;
    other.seed = 6; // another study: its sets must not be skipped as "already done"
    try {
        runStudy(dir, other);
        FAIL() << "a folder holding another study was resumed";
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("plan.json"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "sets")) << "nothing is started in a refused folder";
    // The same study under another plan version is another study too; the error says how to
    // resume a version-1 folder.
    StudyOptions version1 = o;
    version1.plan = 1;
    plan = json::array();
    for (const StudySet& s : planStudy(version1)) plan.push_back({{"index", s.index}, {"seed", s.seed}, {"effects", s.effects}});
    std::ofstream(dir / "plan.json") << json{{"grid", o.grid}, {"seed", o.seed}, {"sets", plan}}.dump(1);
    try {
        runStudy(dir, o);
        FAIL() << "a version-1 folder was resumed as version 2";
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("--plan 1"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "sets"));
    // A rig value fixed in every set makes another study too (a stiff-string study is not the
    // drawn-rig study of the same seed).
    StudyOptions stiff = o;
    stiff.rig = {{"inharmonicity", 1e-3}};
    plan = json::array();
    for (const StudySet& s : planStudy(o)) plan.push_back({{"index", s.index}, {"seed", s.seed}, {"effects", s.effects}});
    std::ofstream(dir / "plan.json") << json{{"grid", o.grid}, {"seed", o.seed}, {"plan", 2}, {"sets", plan}}.dump(1);
    try {
        runStudy(dir, stiff);
        FAIL() << "a drawn-rig folder was resumed with a fixed stiffness";
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("fixed rig values"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "sets"));
    fs::remove_all(dir);
}

// A study's hard cases can be run again alone: --only and --hiding pick sets of the whole plan
// (which stays the folder's plan, so a later full run resumes it).
TEST(Study, RunsOnlyThePickedSetsOfTheWholePlan)
{
    const fs::path dir = freshDir("only");
    StudyOptions o;
    o.sets = 4;
    o.nulls = 1;
    o.grid = 4;
    o.seed = 12;
    o.generateOnly = true; // simulating is enough to see which sets ran
    o.only = {2};
    runStudy(dir, o);
    for (int k = 0; k < o.sets; ++k) EXPECT_EQ(fs::exists(setDir(dir, k) / "truth.json"), k == 2) << k;
    // The folder's plan is the whole study, so the same folder accepts the rest later.
    json plan;
    std::ifstream(dir / "plan.json") >> plan;
    EXPECT_EQ(plan["sets"].size(), 4u);

    const std::vector<StudySet> whole = planStudy(o);
    const auto hider = std::find_if(whole.begin(), whole.end(), [](const StudySet& s) { return !s.effects.empty(); });
    ASSERT_NE(hider, whole.end());
    StudyOptions byEffect = o;
    byEffect.only.clear();
    byEffect.hiding = hider->effects.front();
    const fs::path dir2 = freshDir("hiding");
    runStudy(dir2, byEffect);
    int made = 0;
    for (const StudySet& s : whole) {
        const bool hides = std::find(s.effects.begin(), s.effects.end(), byEffect.hiding) != s.effects.end();
        EXPECT_EQ(fs::exists(setDir(dir2, s.index) / "truth.json"), hides) << s.index;
        made += hides;
    }
    EXPECT_GE(made, 1);
    EXPECT_LT(made, o.sets);

    StudyOptions outside = o;
    outside.only = {4};
    const fs::path dir3 = freshDir("outside");
    EXPECT_THROW(runStudy(dir3, outside), LabError);
    fs::remove_all(dir);
    fs::remove_all(dir3);
    fs::remove_all(dir2);
}

// Sets can be simulated on one occasion and diagnosed on another (a new diagnosis on the same
// data): the second run diagnoses the kept set as it is and simulates nothing again.
// `rosin study --rig-param`: the fixed value reaches every set's rig (its truth says so) and the
// plan, so the folder is known for what it holds; the other rig values are still drawn.
TEST(Study, AFixedRigValueReachesEverySetAndThePlan)
{
    const fs::path dir = freshDir("fixed-rig");
    StudyOptions o = madeOnly(2, 1, 12);
    o.rig = {{"inharmonicity", 1e-3}};
    runStudy(dir, o);
    json plan;
    std::ifstream(dir / "plan.json") >> plan;
    EXPECT_DOUBLE_EQ(plan["rig"]["inharmonicity"].get<double>(), 1e-3);
    std::set<double> bridges;
    for (int k = 0; k < 2; ++k) {
        json truth;
        std::ifstream(setDir(dir, k) / "truth.json") >> truth;
        EXPECT_DOUBLE_EQ(truth["rig"]["inharmonicity"].get<double>(), 1e-3) << "set " << k;
        bridges.insert(truth["rig"]["bridge_z0y"].get<double>());
    }
    EXPECT_EQ(bridges.size(), 2u) << "the values not fixed are drawn per set";
    fs::remove_all(dir);
}

// `rosin study --param-range`: every set that hides the effect draws its size from the range,
// the plan records it (a folder of the whole prior refuses to resume as a narrowed study), and
// scoring says so and will not pool it with a study of the whole prior.
TEST(Study, ANarrowedParameterRangeReachesEverySetThePlanAndThePool)
{
    const fs::path dir = freshDir("narrowed"), whole = freshDir("narrowed-whole"), out = freshDir("narrowed-pool");
    StudyOptions o = madeOnly(6, 0, 14);
    o.hiding = "torsional_compliance";
    o.paramRanges = {{"zt_ratio", {1.2, 2.0}}};
    runStudy(dir, o);
    json plan;
    std::ifstream(dir / "plan.json") >> plan;
    EXPECT_EQ(plan["param_ranges"]["zt_ratio"], json({1.2, 2.0}));
    int rolls = 0;
    for (int k = 0; k < o.sets; ++k) {
        if (!fs::exists(setDir(dir, k) / "truth.json")) continue;
        json truth;
        std::ifstream(setDir(dir, k) / "truth.json") >> truth;
        const double zt = truth["params"]["zt_ratio"].get<double>();
        EXPECT_GE(zt, 1.2) << "set " << k;
        EXPECT_LE(zt, 2.0) << "set " << k;
        ++rolls;
    }
    EXPECT_GE(rolls, 1) << "seed 14's plan of 6 hides no torsion: pick another seed";
    o.paramRanges.clear();
    EXPECT_THROW(runStudy(dir, o), LabError) << "a narrowed study resumed over the whole prior";
    // Pooled with a study of the whole prior: refused, naming what differs.
    const std::string refused = poolWithADrawnStudy(dir, whole, out, 15);
    EXPECT_NE(refused.find("parameter ranges"), std::string::npos) << refused;
    fs::remove_all(dir);
    fs::remove_all(whole);
    fs::remove_all(out);
}

// `rosin study --stated-uncertainty`: every set's manifest states what its lab measured and its
// rig's error lies within it; the plan records it, a folder of unmeasured rigs refuses it, and a
// pool with unmeasured rigs is refused naming what differs.
TEST(Study, StatedUncertaintiesReachEverySetThePlanAndThePool)
{
    const fs::path dir = freshDir("stated"), whole = freshDir("stated-whole"), out = freshDir("stated-pool");
    StudyOptions o = madeOnly(2, 1, 16);
    o.statedUncertainty = {{"tension", 0.01}, {"beta", 0.01}};
    runStudy(dir, o);
    json plan;
    std::ifstream(dir / "plan.json") >> plan;
    EXPECT_EQ(plan["stated_uncertainty"], json({{"beta", 0.01}, {"tension", 0.01}}));
    for (int k = 0; k < o.sets; ++k) {
        json truth, manifest;
        std::ifstream(setDir(dir, k) / "truth.json") >> truth;
        std::ifstream(setDir(dir, k) / "set" / "manifest.json") >> manifest;
        EXPECT_LE(std::abs(truth["rig"]["tension_error"].get<double>()), 0.01) << "set " << k;
        EXPECT_LE(std::abs(truth["rig"]["beta_error"].get<double>()), 0.01) << "set " << k;
        EXPECT_EQ(manifest["rig"]["string"]["tension_uncertainty"], 0.01) << "set " << k;
        EXPECT_EQ(manifest["rig"]["beta_uncertainty"], 0.01) << "set " << k;
    }
    o.statedUncertainty.clear();
    EXPECT_THROW(runStudy(dir, o), LabError) << "a study of measured rigs resumed as one of unmeasured rigs";
    const std::string refused = poolWithADrawnStudy(dir, whole, out, 17);
    EXPECT_NE(refused.find("stated uncertainties"), std::string::npos) << refused;
    fs::remove_all(dir);
    fs::remove_all(whole);
    fs::remove_all(out);
}

// --generator model-on-rig: the same plan and rigs, made by dsp/'s model; the plan says so, a
// reference study's folder refuses it, and a pool will not mix the two.
TEST(Study, AModelOnRigStudyDrawsTheReferenceStudysRigsAndItsPlanSaysSo)
{
    const fs::path reference = freshDir("gen-ref"), model = freshDir("gen-model"), out = freshDir("gen-pool");
    StudyOptions o = madeOnly(2, 0, 19);
    const auto [planR, planM] = studiesBeforeAndAfter(reference, model, o, [](StudyOptions& x) { x.generator = "model-on-rig"; },
                                                      "a reference study resumed with the model's sets");
    EXPECT_FALSE(planR.contains("generator")) << "reference plans stay as earlier studies wrote them";
    EXPECT_EQ(planM["generator"], "model-on-rig");
    EXPECT_EQ(planM["sets"], planR["sets"]) << "the same plan";
    for (int k = 0; k < o.sets; ++k) {
        json tr, tm;
        std::ifstream(setDir(reference, k) / "truth.json") >> tr;
        std::ifstream(setDir(model, k) / "truth.json") >> tm;
        EXPECT_EQ(tm["generator"], "model-on-rig");
        EXPECT_EQ(tm["params"], tr["params"]) << "set " << k;
        for (const char* key : {"tension_error", "beta_error", "rod_effusivity", "mu_level", "noise_n", "dc_n", "hum_hz"})
            EXPECT_EQ(tm["rig"][key], tr["rig"][key]) << key << ", set " << k;
    }
    const std::string refused = poolWithADrawnStudy(model, reference, out, 19);
    EXPECT_NE(refused.find("generator"), std::string::npos) << refused;
    o.generator = "finite-elements";
    EXPECT_THROW(runStudy(freshDir("gen-bad"), o), LabError);
    for (const auto& d : {reference, model, out, freshDir("gen-bad")}) fs::remove_all(d);
}

// --units N: every set is written in newtons through a sensor calibrated to within the rig's
// calibration error; the plan says so, and a volt study's folder refuses it.
TEST(Study, ANewtonStudyWritesItsSetsInNewtonsAndItsPlanSaysSo)
{
    const fs::path volts = freshDir("units-v"), newtons = freshDir("units-n");
    StudyOptions o = madeOnly(1, 1, 13);
    const auto [planV, planN] = studiesBeforeAndAfter(volts, newtons, o, [](StudyOptions& x) { x.units = std::string("N"); }, "a volt study resumed in newtons");
    EXPECT_FALSE(planV.contains("units")) << "volt plans stay as earlier studies wrote them";
    EXPECT_EQ(planN["units"], "N");
    json tv, tn;
    std::ifstream(setDir(volts, 0) / "truth.json") >> tv;
    std::ifstream(setDir(newtons, 0) / "truth.json") >> tn;
    EXPECT_EQ(readMeasurementSet(setDir(volts, 0) / "set").units, "V");
    EXPECT_EQ(readMeasurementSet(setDir(newtons, 0) / "set").units, "N");
    const double gain = tn["gain_units_per_N"].get<double>();
    EXPECT_NEAR(gain, 1.0 + tn["rig"]["calibration_error"].get<double>(), 1e-12);
    EXPECT_LE(std::abs(gain - 1.0), 0.02);
    EXPECT_GT(std::abs(tv["gain_units_per_N"].get<double>() - 1.0), 0.05) << "a volt set's gain comes from its headroom";
    EXPECT_EQ(tv["rig"]["bridge_z0y"], tn["rig"]["bridge_z0y"]) << "the same rig, read through another sensor";
    o.units = "A";
    EXPECT_THROW(runStudy(freshDir("units-a"), o), LabError);
    fs::remove_all(volts);
    fs::remove_all(newtons);
    fs::remove_all(freshDir("units-a"));
}

TEST(Study, GenerateOnlyKeepsTheSetsAndALaterRunDiagnosesThem)
{
    const fs::path dir = freshDir("generate");
    StudyOptions o;
    o.sets = 1;
    o.nulls = 1;
    o.grid = 4; // 16 strokes: the fewest a diagnosis splits
    o.seed = 11;
    o.generateOnly = true;
    runStudy(dir, o);
    const fs::path set = dir / "sets" / "000";
    ASSERT_TRUE(fs::exists(set / "truth.json"));
    ASSERT_TRUE(fs::exists(set / "set" / "manifest.json"));
    EXPECT_FALSE(fs::exists(set / "diagnosis"));
    const auto made = fs::last_write_time(set / "truth.json");
    const auto manifest = fs::last_write_time(set / "set" / "manifest.json");
    o.generateOnly = false;
    o.diagnose.maxEvaluations = 5;
    o.diagnose.parameterBootstrap = 2;
    o.diagnose.bootstrap = 200;
    runStudy(dir, o);
    EXPECT_TRUE(fs::exists(set / "diagnosis" / "diagnosis.json"));
    EXPECT_EQ(fs::last_write_time(set / "truth.json"), made) << "the kept set was simulated again";
    EXPECT_EQ(fs::last_write_time(set / "set" / "manifest.json"), manifest);
    EXPECT_TRUE(fs::exists(set / "set" / "manifest.json")) << "a kept set stays kept";
    fs::remove_all(dir);
}

// Sets of one grid diagnosed with one seed share one split, so such a study measures a single
// draw of fit, validation and test strokes; --split-per-set seeds each set's diagnosis from the
// set's own seed, reproducibly, and the summary says which it was.
TEST(Study, ASplitPerSetGivesEverySetItsOwnReproducibleSplit)
{
    EXPECT_EQ(perSetDiagnoseSeed(1, 2060), perSetDiagnoseSeed(1, 2060));
    EXPECT_NE(perSetDiagnoseSeed(1, 2060), perSetDiagnoseSeed(1, 2061));
    EXPECT_NE(perSetDiagnoseSeed(1, 2060), perSetDiagnoseSeed(2, 2060));
    EXPECT_LT(perSetDiagnoseSeed(7, ~0ull), 1ull << 53) << "split.json's seed must read back exactly as a JSON number";

    const fs::path dir = freshDir("split-per-set");
    StudyOptions o;
    o.sets = 2;
    o.nulls = 2;
    o.grid = 4;
    o.seed = 13;
    o.keepSets = true; // diagnosed twice below, simulated once
    o.diagnose.maxEvaluations = 5;
    o.diagnose.parameterBootstrap = 2;
    o.diagnose.bootstrap = 200;
    const auto splitOf = [&](int k) {
        json j;
        std::ifstream(setDir(dir, k) / "diagnosis" / "split.json") >> j;
        return j;
    };
    const std::vector<StudySet> plan = planStudy(o);
    o.splitPerSet = true;
    runStudy(dir, o);
    for (int k = 0; k < 2; ++k)
        EXPECT_EQ(splitOf(k)["seed"].get<std::uint64_t>(), perSetDiagnoseSeed(1, plan[static_cast<std::size_t>(k)].seed)) << k;
    EXPECT_NE(splitOf(0)["test"], splitOf(1)["test"]);
    EXPECT_NE(scoreStudy(dir).find("shuffled (split.json's method \"random\"), 2 split seeds over 2 sets."), std::string::npos);

    for (int k = 0; k < 2; ++k) fs::remove_all(setDir(dir, k) / "diagnosis");
    o.splitPerSet = false;
    runStudy(dir, o);
    EXPECT_EQ(splitOf(0)["seed"], 1);
    EXPECT_EQ(splitOf(0)["test"], splitOf(1)["test"]) << "one seed, one grid: one split";
    const std::string oneSplit = scoreStudy(dir);
    EXPECT_NE(oneSplit.find("one split for every set (seed 1)."), std::string::npos);
    EXPECT_NE(oneSplit.find("Search: contact_restart on, pairs off, second_start off.\n"), std::string::npos) << "diagnosis.json records the search";
    json study;
    std::ifstream(dir / "study.json") >> study;
    EXPECT_EQ(study["summary"]["split_seeds"], 1);

    // Resuming with another kind of split is refused before any set is touched, naming the file.
    const auto refusal = [&](const StudyOptions& resumed) {
        try {
            runStudy(dir, resumed);
        } catch (const LabError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const auto before = fs::last_write_time(setDir(dir, 0) / "diagnosis" / "diagnosis.json");
    o.splitPerSet = true;
    const std::string perSet = refusal(o);
    EXPECT_NE(perSet.find("000/diagnosis/split.json: this set was diagnosed with split seed 1 (method \"random\") where this run would use " +
                          std::to_string(perSetDiagnoseSeed(1, plan[0].seed))),
              std::string::npos)
        << perSet;
    o.splitPerSet = false;
    o.diagnose.stratifiedSplit = true;
    EXPECT_NE(refusal(o).find("where this run would use 1 (\"stratified\")"), std::string::npos);
    o.diagnose.stratifiedSplit = false;
    EXPECT_EQ(refusal(o), "") << "the same split resumes";
    // So is another search, named by the set's diagnosis.json.
    o.diagnose.secondStart = true;
    const std::string otherSearch = refusal(o);
    EXPECT_NE(otherSearch.find("000/diagnosis/diagnosis.json: this set was diagnosed with contact_restart on, pairs off, second_start off "
                               "where this run would search with contact_restart on, pairs off, second_start on"),
              std::string::npos)
        << otherSearch;
    o.diagnose.secondStart = false;
    o.diagnose.tryPairs = true;
    EXPECT_NE(refusal(o).find("pairs on"), std::string::npos);
    o.diagnose.tryPairs = false;
    // And other metric weights: every fit and every naming would be another experiment.
    EXPECT_NE(oneSplit.find("Metric weights (first-slip time, force before it, jump, transient length, waveform): 0.25/0.25/0.25/0.1/0.15 (the default).\n"),
              std::string::npos)
        << oneSplit;
    o.diagnose.metricWeights = {0.3, 0.3, 0.3, 0.0, 0.1};
    const std::string otherMetric = refusal(o);
    EXPECT_NE(otherMetric.find("000/diagnosis/diagnosis.json: this set was diagnosed with metric weights 0.25/0.25/0.25/0.1/0.15 (the default) where "
                               "this run has 0.3/0.3/0.3/0/0.1; a resumed study keeps its --metric-weights"),
              std::string::npos)
        << otherMetric;
    o.diagnose.metricWeights = ErrorParts::kWeights;
    EXPECT_EQ(fs::last_write_time(setDir(dir, 0) / "diagnosis" / "diagnosis.json"), before);
    fs::remove_all(dir);
}

TEST(Study, ScoresDetectionFalsePositivesErrorsAndCoverage)
{
    const fs::path dir = freshDir("score");
    // 0: a null set, nothing named. 1: a null set naming a spurious shift.
    writeSet(dir, 0, {{"effects", json::array()}, {"params", json::object()}}, diagnosis(json::array({{{"effect", "none"}}})));
    writeSet(dir, 1, {{"effects", json::array()}, {"params", json::object()}},
             diagnosis(json::array({finding("rosin_temperature_shift", "shift_k", -2.0, -3.5, -0.5)})));
    // 2: Hertzian contact named, 0.70 for a true 0.67 (within 0.05), interval holds the truth.
    writeSet(dir, 2, {{"effects", {"hertzian_contact"}}, {"params", {{"load_exponent", 0.67}}}},
             diagnosis(json::array({finding("hertzian_contact", "load_exponent", 0.70, 0.65, 0.75)})));
    // 3: Hertzian contact named, 0.80 for a true 0.67 (outside), interval misses the truth;
    //    torsion hidden beside it and missed.
    writeSet(dir, 3, {{"effects", {"hertzian_contact", "torsional_compliance"}}, {"params", {{"load_exponent", 0.67}, {"zt_ratio", 3.0}}}},
             diagnosis(json::array({finding("hertzian_contact", "load_exponent", 0.80, 0.76, 0.84)})));
    // 4: torsion named, Z_t/Z_0 3.3 for 3.0 (10 %, within 20 %), interval holds it.
    writeSet(dir, 4, {{"effects", {"torsional_compliance"}}, {"params", {{"zt_ratio", 3.0}}}},
             diagnosis(json::array({finding("torsional_compliance", "zt_ratio", 3.3, 2.5, 4.0)})));

    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    const json& s = study["summary"];
    EXPECT_EQ(s["sets"], 5);
    EXPECT_EQ(s["exact"], 3); // sets 0, 2 and 4
    EXPECT_EQ(s["null_sets"], 2);
    EXPECT_EQ(s["null_false_positives"], 1);
    EXPECT_EQ(s["detection"]["hertzian_contact"]["hidden"], 2);
    EXPECT_EQ(s["detection"]["hertzian_contact"]["named"], 2);
    EXPECT_EQ(s["detection"]["torsional_compliance"]["hidden"], 2);
    EXPECT_EQ(s["detection"]["torsional_compliance"]["named"], 1);
    EXPECT_EQ(s["detection"]["rosin_temperature_shift"]["false_positive"], 1);
    EXPECT_EQ(s["detection"]["rosin_temperature_shift"]["not_hidden"], 5);
    EXPECT_EQ(s["parameters"]["load_exponent"]["named"], 2);
    EXPECT_EQ(s["parameters"]["load_exponent"]["within_tolerance"], 1);
    EXPECT_NEAR(s["parameters"]["load_exponent"]["worst_error"].get<double>(), 0.13, 1e-9);
    EXPECT_EQ(s["parameters"]["zt_ratio"]["within_tolerance"], 1);
    // A shift named on a null set has no truth to score against: only hidden effects' parameters count.
    EXPECT_FALSE(s["parameters"].contains("shift_k"));
    // Intervals: 2 of the 3 scored parameters hold their truth.
    EXPECT_NEAR(s["coverage"].get<double>(), 2.0 / 3.0, 1e-12);
    EXPECT_NE(md.find("Null sets naming any effect: 1 of 2"), std::string::npos) << md;
    EXPECT_TRUE(fs::exists(dir / "study.csv"));
    EXPECT_TRUE(fs::exists(dir / "study.png"));
    fs::remove_all(dir);
}

// Round 1 reads every hidden effect's parameter, named or not; the study scores those first
// readings, signed toward a stronger effect, apart for named and missed effects, so a reader sees
// how much of a named parameter's error is the rules choosing strong readings.
TEST(Study, ScoresRoundOnesReadingOfEveryHiddenEffectNamedOrNot)
{
    const fs::path dir = freshDir("first-readings");
    const auto trial = [](int round, const std::string& effect, const json& parameters) {
        return json{{"round", round}, {"effect", effect}, {"parameters", parameters}};
    };
    const auto withTrials = [](json d, const json& trials) {
        d["trials"] = trials;
        return d;
    };
    // 0: a -10 K shift read -18 K in round 1 (8 K stronger) and named at -17 K.
    writeSet(dir, 0, {{"effects", {"thermal_memory", "rosin_temperature_shift"}}, {"params", {{"r_A", 1.0}, {"shift_k", -10.0}}}},
             withTrials(diagnosis(json::array({finding("thermal_memory", "r_A", 1.1, 0.9, 1.3), finding("rosin_temperature_shift", "shift_k", -17.0, -30.0, -2.0)})),
                        {trial(1, "thermal_memory", {{"r_A", 1.2}}), trial(1, "rosin_temperature_shift", {{"r_A", 1.05}, {"shift_k", -18.0}}),
                         trial(2, "rosin_temperature_shift", {{"shift_k", -25.0}})}));
    // 1: a +12 K shift read +9 K (3 K weaker) and a 0.7 load exponent read 0.6 (0.1 stronger), neither named.
    writeSet(dir, 1, {{"effects", {"rosin_temperature_shift", "hertzian_contact"}}, {"params", {{"shift_k", 12.0}, {"load_exponent", 0.7}}}},
             withTrials(diagnosis(json::array({{{"effect", "none"}}})),
                        {trial(1, "rosin_temperature_shift", {{"shift_k", 9.0}}), trial(1, "hertzian_contact", {{"load_exponent", 0.6}})}));
    // 2: a +15 K shift read +16 K (1 K stronger, within 3 K), not named; a round-1 roll on a set
    //    that hides none is not scored.
    writeSet(dir, 2, {{"effects", {"rosin_temperature_shift"}}, {"params", {{"shift_k", 15.0}}}},
             withTrials(diagnosis(json::array({{{"effect", "none"}}})),
                        {trial(1, "rosin_temperature_shift", {{"shift_k", 16.0}}), trial(1, "torsional_compliance", {{"zt_ratio", 2.0}})}));

    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    const json& first = study["summary"]["first_readings"];
    const json& shift = first["shift_k"];
    EXPECT_EQ(shift["read"], 3);
    EXPECT_DOUBLE_EQ(shift["median_error"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(shift["quartiles"][0].get<double>(), -3.0);
    EXPECT_DOUBLE_EQ(shift["quartiles"][1].get<double>(), 8.0);
    EXPECT_EQ(shift["within_tolerance"], 2);
    EXPECT_EQ(shift["named"], 1);
    EXPECT_DOUBLE_EQ(shift["median_error_named"].get<double>(), 8.0); // round 1's -18 K, not round 2's or the finding's
    EXPECT_EQ(shift["not_named"], 2);
    EXPECT_DOUBLE_EQ(shift["median_error_not_named"].get<double>(), 1.0);
    EXPECT_NEAR(first["load_exponent"]["median_error"].get<double>(), 0.1, 1e-12);
    EXPECT_EQ(first["load_exponent"]["within_tolerance"], 0);
    EXPECT_FALSE(first["load_exponent"].contains("median_error_named"));
    // r_A from thermal memory's own candidate (1.2), not from the shift's (1.05): +20 %
    EXPECT_NEAR(first["r_A"]["median_error"].get<double>(), 0.2, 1e-12);
    EXPECT_FALSE(first.contains("zt_ratio"));
    EXPECT_NE(md.find("| shift_k | 3 | +1 (-3 to +8) | 2 | 1, +8 | 2, +1 |"), std::string::npos) << md;
    fs::remove_all(dir);
}

// The calibrated nuisances are scored against the rig that made the set: tension_scale against
// 1 + tension_error, beta_scale against 1 + beta_error, rod_effusivity_scale against the rig's
// rod effusivity over 450 (only sets with a thermal model calibrate it), the sensor scale against
// the inverse of the generator's gain, with their intervals' coverage.
// The residual's line in the summary: on how many sets (and nulls) the diagnosis reported what
// no model on its list explains, the final error over each set's floor (median, range), and how
// many passed the usual residual and 1.3 times it (where the report makes its claim), nulls apart.
TEST(Study, CountsTheUnexplainedResidualsAndHowFarAboveTheirFloorsTheSetsAre)
{
    const fs::path dir = freshDir("residual");
    const auto withFloor = [](json d, double overFloor, bool unexplained) {
        d["floor"] = {{"final_over_floor", overFloor}, {"usual_ratio", 8.0}};
        if (unexplained) d["unexplained_residual"] = {{"ratio", overFloor}, {"usual_ratio", 8.0}, {"beyond_usual", overFloor > 8.0}};
        return d;
    };
    const json none = diagnosis(json::array({{{"effect", "none"}}}));
    writeSet(dir, 0, {{"effects", json::array()}, {"params", json::object()}}, withFloor(none, 1.5, false));
    writeSet(dir, 1, {{"effects", json::array()}, {"params", json::object()}}, withFloor(none, 9.0, true));
    writeSet(dir, 2, {{"effects", {"thermal_memory"}}, {"params", {{"r_A", 1.2}}}},
             withFloor(thermalDiagnosis(1.18, 1.1, 1.3, json::object()), 4.0, true));
    // A diagnosis.json from before the comparison with the usual residual counts as not beyond it.
    json older = withFloor(thermalDiagnosis(1.18, 1.1, 1.3, json::object()), 20.0, true);
    older["unexplained_residual"].erase("beyond_usual");
    writeSet(dir, 3, {{"effects", {"thermal_memory"}}, {"params", {{"r_A", 1.2}}}}, older);
    writeSet(dir, 4, {{"effects", {"thermal_memory"}}, {"params", {{"r_A", 1.2}}}},
             withFloor(thermalDiagnosis(1.18, 1.1, 1.3, json::object()), 12.0, true));
    std::ofstream(dir / "plan.json") << json{{"rig", {{"inharmonicity", 1e-3}}}}.dump();
    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    const json& r = study["summary"]["unexplained_residual"];
    EXPECT_EQ(r["sets"], 4);
    EXPECT_EQ(r["null_sets"], 1);
    EXPECT_EQ(r["beyond_usual"], 2); // set 1: 9 over a usual 8; set 4: 12
    EXPECT_EQ(r["null_beyond_usual"], 1);
    EXPECT_EQ(r["firmly_beyond_usual"], 1); // set 4 only: 12 > 1.3 x 8, 9 is not
    EXPECT_EQ(r["null_firmly_beyond_usual"], 0);
    EXPECT_DOUBLE_EQ(r["median_over_floor"].get<double>(), 9.0);
    EXPECT_NE(md.find("Unexplained residual reported on 4 of 5 sets (1 of the 2 null sets); final error over the set's floor: median 9.00, "
                      "from 1.50 to 20.00; more than the usual residual on 2 of 5 (1 null), and more than 1.3 times it, where the "
                      "report says the rig has something the model lacks, on 1 (0 null)."),
              std::string::npos)
        << md;
    // The usual residual this study measures: the largest ratio where nothing was hidden.
    EXPECT_DOUBLE_EQ(study["summary"]["usual_residual_measured"].get<double>(), 9.0);
    EXPECT_NE(md.find("`rosin diagnose --usual-residual 9.0` takes it"), std::string::npos) << md;
    EXPECT_TRUE(study["sets"][1]["beyond_usual"].get<bool>());
    EXPECT_FALSE(study["sets"][3]["beyond_usual"].get<bool>());
    EXPECT_NE(md.find("Rig values fixed in every set instead of drawn: inharmonicity = 0.001."), std::string::npos) << md;
    EXPECT_DOUBLE_EQ(study["sets"][1]["over_floor"].get<double>(), 9.0);
    fs::remove_all(dir);
}

// With twenty nulls or more the usual residual a study measures is their 95th percentile by
// nearest rank, not their largest: the largest of many nulls grows with their number, and a
// fresh null should pass the usual residual about one time in twenty whatever the study's size.
TEST(Study, TheUsualResidualOfTwentyNullsOrMoreIsTheir95thPercentile)
{
    const fs::path dir = freshDir("usual95");
    const json none = diagnosis(json::array({{{"effect", "none"}}}));
    const json nothing{{"effects", json::array()}, {"params", json::object()}};
    // Nulls at 1, 2, ..., 20 floors, written out of order: the 19th smallest is 19.
    for (int k = 0; k < 20; ++k) {
        json d = none;
        d["floor"] = {{"final_over_floor", double((k * 7) % 20 + 1)}};
        writeSet(dir, k, nothing, d);
    }
    // A set that hides an effect does not count, however large its residual.
    json hid = thermalDiagnosis(1.18, 1.1, 1.3, json::object());
    hid["floor"] = {{"final_over_floor", 50.0}};
    writeSet(dir, 20, {{"effects", {"thermal_memory"}}, {"params", {{"r_A", 1.2}}}}, hid);
    std::ofstream(dir / "plan.json") << json{{"grid", 12}}.dump();
    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    EXPECT_DOUBLE_EQ(study["summary"]["usual_residual_measured"].get<double>(), 19.0);
    EXPECT_EQ(study["summary"]["null_over_floor"]["nulls"], 20);
    EXPECT_DOUBLE_EQ(study["summary"]["null_over_floor"]["largest"].get<double>(), 20.0);
    EXPECT_DOUBLE_EQ(study["summary"]["null_over_floor"]["median"].get<double>(), 11.0);
    EXPECT_NE(md.find("The null sets' final error over floor: median 11.0, 95th percentile 19.0, largest 20.0 (1 of 20 nulls above the 95th "
                      "percentile); the 95th percentile is this rig population's usual residual (`rosin diagnose --usual-residual 19.0` takes it)."),
              std::string::npos)
        << md;
    fs::remove_all(dir);
}

// Rule 6's stand-ins are not named: they count neither as detections nor as false positives, and
// the summary says on how many sets they were set aside and whether each was hidden there (a miss)
// or not (a wrong label kept out).
TEST(Study, CountsTheStandInsSetAsideBesideAnUnusualResidualAndDoesNotScoreThemAsNamed)
{
    const fs::path dir = freshDir("standins");
    const auto beyond = [](json d, const json& standIns) {
        d["floor"] = {{"final_over_floor", 9.5}, {"usual_ratio", 8.6}};
        d["unexplained_residual"] = {{"ratio", 9.5}, {"usual_ratio", 8.6}, {"beyond_usual", true}, {"stand_ins", standIns}};
        return d;
    };
    // set 0 hides a rate law; the rounds fitted a shift in its place, set aside
    writeSet(dir, 0, {{"effects", {"thermal_memory", "rate_dependence"}}, {"params", {{"r_A", 1.08}, {"p", 0.54}}}},
             beyond(thermalDiagnosis(1.2, 1.0, 1.4, json::object()), json::array({finding("rosin_temperature_shift", "shift_k", 25.0, 5.0, 30.0)})));
    // set 1 hides a rolling string, and the torsion it found is set aside too
    writeSet(dir, 1, {{"effects", {"thermal_memory", "torsional_compliance"}}, {"params", {{"r_A", 1.0}, {"zt_ratio", 1.5}}}},
             beyond(thermalDiagnosis(1.02, 0.9, 1.1, json::object()), json::array({finding("torsional_compliance", "zt_ratio", 1.6, 1.2, 2.1)})));
    writeSet(dir, 2, {{"effects", json::array()}, {"params", json::object()}}, beyond(diagnosis(json::array({{{"effect", "none"}}})), json::array()));
    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    const json& st = study["summary"]["stand_ins"];
    EXPECT_EQ(st["sets"], 2);
    EXPECT_EQ(st["not_hidden"], 1);
    EXPECT_EQ(st["hidden"], 1);
    EXPECT_NE(md.find("Possible stand-ins set aside beside a residual beyond the usual one (rule 6), not named: on 2 of 3 sets; 1 of them not "
                      "hidden in their set (a wrong label kept out), 1 hidden (a miss)."),
              std::string::npos)
        << md;
    EXPECT_EQ(study["sets"][0]["found"], json({"thermal_memory"}));
    EXPECT_EQ(study["sets"][0]["stand_ins"], json({"rosin_temperature_shift"}));
    EXPECT_NE(md.find("(possible stand-in, not named: rosin_temperature_shift)"), std::string::npos) << md;
    // the shift set aside is no false positive, the torsion set aside no detection
    EXPECT_NE(md.find("| rosin_temperature_shift | 0 | 0 (0 %) | 0 of 3 (0 %)"), std::string::npos) << md;
    EXPECT_NE(md.find("| torsional_compliance | 1 | 0 (0 %) | 0 of 2 (0 %)"), std::string::npos) << md;
    fs::remove_all(dir);
}

// A plan.json that is not JSON is named with the file when a study is scored, as when it is run.
TEST(Study, ScoringRefusesAnUnreadablePlanNamingTheFile)
{
    const fs::path dir = freshDir("badplan");
    writeSet(dir, 0, {{"effects", json::array()}, {"params", json::object()}}, diagnosis(json::array({{{"effect", "none"}}})));
    std::ofstream(dir / "plan.json") << "{\"rig\": {\"inharmonicity\": ";
    try {
        scoreStudy(dir);
        ADD_FAILURE() << "a truncated plan.json was read";
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("plan.json: unreadable"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "summary.md")) << "no half-written output";
    fs::remove_all(dir);
}

TEST(Study, ScoresTheCalibratedNuisancesAgainstTheRig)
{
    const fs::path dir = freshDir("nuisances");
    auto withCalibration = [](double tension, double tLow, double tHigh, double beta, double bLow, double bHigh) {
        json d = diagnosis(json::array({{{"effect", "none"}}}));
        d["calibration"]["values"]["tension_scale"] = {{"value", tension}, {"ci95", {tLow, tHigh}}};
        d["calibration"]["values"]["beta_scale"] = {{"value", beta}, {"ci95", {bLow, bHigh}}};
        return d;
    };
    const json rigA{{"tension_error", 0.02}, {"beta_error", -0.01}, {"rod_effusivity", 540.0}},
        rigB{{"tension_error", -0.03}, {"beta_error", 0.02}, {"rod_effusivity", 360.0}};
    json thermalA = withCalibration(1.01, 1.0, 1.03, 0.99, 0.98, 1.0);
    thermalA["calibration"]["values"]["rod_effusivity_scale"] = {{"value", 1.1}, {"ci95", {1.0, 1.15}}}; // for 1.2: 8.3 % low, missed
    // The sensor: 4.1 N per unit for a gain of 0.25 units per N (2.5 % high, interval holds it).
    thermalA["calibration"]["values"]["scale_n_per_unit"] = {{"value", 4.1}, {"ci95", {3.8, 4.3}}};
    // A: tension 1.01 for 1.02 (1 %, interval holds it); bow position 0.99 for 0.99 exactly.
    writeSet(dir, 0, {{"effects", json::array()}, {"params", json::object()}, {"rig", rigA}, {"gain_units_per_N", 0.25}}, thermalA);
    // B: tension 1.0 for 0.97 (3.1 %, interval misses it); bow position 1.0 for 1.02, missed too;
    // the sensor 2.1 N per unit for 2 (5 % high, missed).
    json setB = withCalibration(1.0, 0.99, 1.01, 1.0, 0.99, 1.01);
    setB["calibration"]["values"]["scale_n_per_unit"] = {{"value", 2.1}, {"ci95", {2.05, 2.2}}};
    writeSet(dir, 1, {{"effects", json::array()}, {"params", json::object()}, {"rig", rigB}, {"gain_units_per_N", 0.5}}, setB);
    // The curvature intervals alone, which the reported ones widen: both miss their truths.
    for (int k : {0, 1}) {
        json d;
        std::ifstream(setDir(dir, k) / "diagnosis" / "diagnosis.json") >> d;
        const double v = d["calibration"]["values"]["tension_scale"]["value"].get<double>();
        d["calibration"]["values"]["tension_scale"]["ci95_curvature"] = {v - 0.005, v + 0.005};
        if (k == 1) d["calibration"]["values"]["beta_scale"]["ci95_curvature"] = {0.995, 1.005};
        std::ofstream(setDir(dir, k) / "diagnosis" / "diagnosis.json") << d.dump();
    }
    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    const json& c = study["summary"]["calibration"];
    EXPECT_EQ(c["tension_scale"]["covered_by_curvature"], 0);
    // The discrepancy beyond the curvature: misses of 0.01 and 0.03, each curvature SD 0.005 / 1.96.
    const double curvatureVariance = std::pow(0.005 / 1.96, 2);
    EXPECT_NEAR(study["summary"]["calibration_discrepancy"]["tension_scale"].get<double>(),
                std::sqrt((0.01 * 0.01 + 0.03 * 0.03) / 2.0 - curvatureVariance), 1e-9);
    // Set A's bow position carries no curvature interval: a diagnosis from before the widening,
    // whose reported interval was the curvature's; set B's was widened from 0.995-1.005. Misses
    // of 0 and 0.02 beyond curvature SDs of 0.02 / 3.92 (A's reported interval) and 0.01 / 3.92.
    EXPECT_NEAR(study["summary"]["calibration_discrepancy"]["beta_scale"].get<double>(),
                std::sqrt((0.02 * 0.02 - std::pow(0.02 / 3.92, 2) - std::pow(0.01 / 3.92, 2)) / 2.0), 1e-9);
    EXPECT_EQ(c["beta_scale"]["covered_by_curvature"], 1);
    EXPECT_EQ(c["beta_scale"]["not_widened"]["sets"], 1);
    EXPECT_EQ(c["beta_scale"]["not_widened"]["covered"], 1);
    EXPECT_FALSE(c["tension_scale"].contains("not_widened"));
    // Told apart in the table: B's widened interval misses, A's older one holds.
    EXPECT_NE(md.find("| 0 of 1 (and 1 of 1 diagnosed before the widening, the curvature interval) |"), std::string::npos) << md;
    EXPECT_NE(md.find("| 0 of 1 (diagnosed before the widening: the curvature interval) |"), std::string::npos) << md; // effusivity
    EXPECT_EQ(c["tension_scale"]["sets"], 2);
    EXPECT_EQ(c["tension_scale"]["covered"], 1);
    EXPECT_NEAR(c["tension_scale"]["worst_error"].get<double>(), 1.0 / 0.97 - 1.0, 1e-9);
    EXPECT_EQ(c["beta_scale"]["covered"], 1);
    EXPECT_NEAR(c["beta_scale"]["worst_error"].get<double>(), 1.0 - 1.0 / 1.02, 1e-9);
    EXPECT_EQ(c["rod_effusivity_scale"]["sets"], 1);
    EXPECT_EQ(c["rod_effusivity_scale"]["covered"], 0);
    EXPECT_EQ(c["rod_effusivity_scale"]["not_widened"]["sets"], 1);
    EXPECT_NEAR(c["rod_effusivity_scale"]["worst_error"].get<double>(), 1.0 - 1.1 / 1.2, 1e-9);
    EXPECT_EQ(c["scale_n_per_unit"]["sets"], 2);
    EXPECT_EQ(c["scale_n_per_unit"]["covered"], 1);
    EXPECT_NEAR(c["scale_n_per_unit"]["worst_error"].get<double>(), 0.05, 1e-9);
    EXPECT_NEAR(c["scale_n_per_unit"]["median_error"].get<double>(), 0.05, 1e-9); // the upper of two
    EXPECT_NE(md.find("| tension_scale | 2 |"), std::string::npos) << md;
    fs::remove_all(dir);
}

// A finding's reported interval spans its bootstrap refits, its curvature interval and its refits
// on the two drive halves; an estimate given without the last two is the bootstrap's alone.
TEST(Study, TheReportedIntervalSpansBootstrapCurvatureAndDriveHalves)
{
    Finding f;
    f.parameters["r_A"] = {1.0, 0.97, 1.03};
    EXPECT_EQ(reportedInterval(f, "r_A"), std::make_pair(0.97, 1.03));
    f.curvature["r_A"] = {0.95, 1.02};
    EXPECT_EQ(reportedInterval(f, "r_A"), std::make_pair(0.95, 1.03));
    f.halves["r_A"] = {1.08, 0.99}; // the high-drive half above both
    EXPECT_EQ(reportedInterval(f, "r_A"), std::make_pair(0.95, 1.08));
}

// What the rig may be beyond the data's reach, and the model's own error, are independent of the
// strokes' scatter: each side of the reported interval adds them in quadrature, inside the range.
TEST(Study, TheReportedIntervalAddsRigUnknownsAndModelDiscrepancyInQuadrature)
{
    Finding f;
    f.parameters["r_A"] = {1.0, 0.97, 1.03};
    f.systematic["r_A"] = {0.04, 0.0}; // a smaller contact radius would lower r_A only
    EXPECT_EQ(statisticalInterval(f, "r_A"), std::make_pair(0.97, 1.03));
    auto [lo, hi] = reportedInterval(f, "r_A");
    EXPECT_NEAR(lo, 0.95, 1e-12);
    EXPECT_NEAR(hi, 1.03, 1e-12);
    f.discrepancy["r_A"] = 0.03;
    std::tie(lo, hi) = reportedInterval(f, "r_A");
    EXPECT_NEAR(lo, 1.0 - std::sqrt(0.03 * 0.03 + 0.04 * 0.04 + 0.03 * 0.03), 1e-12);
    EXPECT_NEAR(hi, 1.0 + std::sqrt(0.03 * 0.03 + 0.03 * 0.03), 1e-12);
    Finding g; // near the top of the load exponent's search range (1.1)
    g.parameters["load_exponent"] = {1.05, 1.0, 1.09};
    g.discrepancy["load_exponent"] = 0.1;
    EXPECT_EQ(reportedInterval(g, "load_exponent").second, 1.1);
}

// Coverage is counted three ways (statistical part alone, with the rig unknowns, as reported),
// and the study measures the model discrepancy that the reported intervals should carry.
TEST(Study, CountsCoverageByPartAndMeasuresTheModelDiscrepancy)
{
    const fs::path dir = freshDir("parts");
    auto thermal = [](double value, double low, double high, double sLow, double sHigh, double down, double up) {
        return thermalDiagnosis(value, low, high, {{"ci95_statistical", {sLow, sHigh}}, {"systematic_moves", {down, up}}});
    };
    const json truth{{"effects", {"thermal_memory"}}, {"params", {{"r_A", 1.0}}}};
    // 0: the statistical part (0.88-0.98) misses; the rig's +0.07 reaches 0.9 + hypot(0.08, 0.07) = 1.006
    writeSet(dir, 0, truth, thermal(0.9, 0.8, 1.1, 0.88, 0.98, 0.0, 0.07));
    // 1: covered by the statistical part already
    writeSet(dir, 1, truth, thermal(1.02, 0.9, 1.14, 0.97, 1.07, 0.01, 0.01));
    // 2: missed by every part
    writeSet(dir, 2, truth, thermal(1.2, 1.1, 1.3, 1.15, 1.25, 0.0, 0.0));
    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    const json& s = study["summary"];
    EXPECT_NEAR(s["coverage"].get<double>(), 2.0 / 3.0, 1e-12);
    EXPECT_NEAR(s["coverage_statistical"].get<double>(), 1.0 / 3.0, 1e-12);
    EXPECT_NEAR(s["coverage_with_rig_unknowns"].get<double>(), 2.0 / 3.0, 1e-12);
    // misses of -0.1, +0.02 and +0.2 against standard deviations of (0.02 + hypot(0.08, 0.07)),
    // 2 hypot(0.05, 0.01) and 0.1, each over 2 x 1.96: sqrt(mean(miss^2 - sd^2)) = 0.1265
    EXPECT_NEAR(s["model_discrepancy"]["r_A"].get<double>(), 0.1265, 0.0005);
    EXPECT_EQ(s["model_discrepancy_moments"]["r_A"]["sets"].get<int>(), 3);
    EXPECT_NEAR(s["model_discrepancy_moments"]["r_A"]["excess_sum"].get<double>(), 3.0 * 0.1265 * 0.1265, 0.0002);
    EXPECT_NE(md.find("Model discrepancy this study measures"), std::string::npos) << md;
    EXPECT_NE(md.find("r_A 0.127 (3 sets)"), std::string::npos) << md;
    fs::remove_all(dir);
}

// The study counts coverage with the reported intervals and, beside it, with the bootstrap and
// curvature intervals alone (what was reported before the drive halves widened it).
TEST(Study, CountsCoverageWithAndWithoutTheDriveHalves)
{
    const fs::path dir = freshDir("halves");
    auto thermal = [](double value, double low, double high, double bLow, double bHigh, double cLow, double cHigh) {
        return thermalDiagnosis(value, low, high, {{"ci95_bootstrap", {bLow, bHigh}}, {"ci95_curvature", {cLow, cHigh}}});
    };
    const json truth{{"effects", {"thermal_memory"}}, {"params", {{"r_A", 1.1}}}};
    // Covered only thanks to the halves (bootstrap and curvature stop at 1.05).
    writeSet(dir, 0, truth, thermal(1.0, 0.95, 1.12, 0.97, 1.03, 0.95, 1.05));
    // Covered by the curvature interval already.
    writeSet(dir, 1, truth, thermal(1.05, 1.0, 1.15, 1.02, 1.08, 1.0, 1.15));
    // Missed by all.
    writeSet(dir, 2, truth, thermal(0.9, 0.85, 0.95, 0.87, 0.93, 0.85, 0.95));
    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    EXPECT_NEAR(study["summary"]["coverage"].get<double>(), 2.0 / 3.0, 1e-12);
    EXPECT_NEAR(study["summary"]["coverage_without_halves"].get<double>(), 1.0 / 3.0, 1e-12);
    EXPECT_NE(md.find("bootstrap and curvature only: 33 % (1)."), std::string::npos) << md;
    fs::remove_all(dir);
}

TEST(Study, ScoringAnEmptyFolderSaysSo)
{
    const fs::path dir = freshDir("empty");
    EXPECT_THROW(scoreStudy(dir), LabError);
    fs::create_directories(dir / "sets");
    EXPECT_THROW(scoreStudy(dir), LabError);
    fs::remove_all(dir);
}

// A parameter the diagnosis reports as not identified (its interval is its whole search range)
// holds any truth: it is counted apart and left out of the coverage, while its error still counts.
TEST(Study, LeavesParametersThatAreNotIdentifiedOutOfTheCoverage)
{
    const fs::path dir = freshDir("unidentified");
    json rate = {{"effect", "rate_dependence"},
                 {"parameters",
                  {{"h0", {{"value", 0.9}, {"ci95", {0.3, 1.2}}, {"identified", false}}},
                   {"p", {{"value", 0.45}, {"ci95", {0.35, 0.5}}, {"identified", true}}}}}};
    json thermal = finding("thermal_memory", "r_A", 1.0, 0.9, 1.02); // for 1.05: missed
    writeSet(dir, 0, {{"effects", {"thermal_memory", "rate_dependence"}}, {"params", {{"r_A", 1.05}, {"h0", 0.6}, {"p", 0.4}}}},
             diagnosis(json::array({thermal, rate})));
    const std::string md = scoreStudy(dir);
    json study;
    std::ifstream(dir / "study.json") >> study;
    const json& s = study["summary"];
    EXPECT_EQ(s["parameters"]["h0"]["named"], 1);
    EXPECT_EQ(s["parameters"]["h0"]["not_identified"], 1);
    EXPECT_EQ(s["parameters"]["h0"]["covered"], 0);
    EXPECT_NEAR(s["parameters"]["h0"]["worst_error"].get<double>(), 0.3, 1e-9);
    EXPECT_EQ(s["parameters"]["p"]["covered"], 1);
    // p covered, r_A missed, h0 not counted: 1 of 2.
    EXPECT_NEAR(s["coverage"].get<double>(), 0.5, 1e-12);
    EXPECT_NE(md.find("0 of 0 (1 not identified)"), std::string::npos) << md;
    fs::remove_all(dir);
}

// Studies of several seeds scored as one: the counts add up over both, the usual residual is the
// largest over all their null sets, each set is labelled with its study, and what would make the
// pool lie is refused: a set counted twice, studies of different strokes, or a pooled summary
// written over one of its sources.
TEST(Study, StudiesOfSeveralSeedsScoreAsOneAndRefuseWhatWouldMakeThePoolLie)
{
    const fs::path a = freshDir("pool-a"), b = freshDir("pool-b"), out = freshDir("pool-out");
    const auto residual = [](json d, double overFloor) {
        d["floor"] = {{"final_over_floor", overFloor}};
        d["unexplained_residual"] = {{"ratio", overFloor}, {"beyond_usual", false}};
        return d;
    };
    const json none = diagnosis(json::array({{{"effect", "none"}}}));
    const json nothing{{"effects", json::array()}, {"params", json::object()}};
    const auto truth = [](json t, std::uint64_t seed) { t["seed"] = seed; return t; };
    writeSet(a, 0, truth(nothing, 11), residual(none, 6.5));
    writeSet(a, 1, truth({{"effects", {"hertzian_contact"}}, {"params", {{"load_exponent", 0.67}}}}, 12),
             diagnosis(json::array({finding("hertzian_contact", "load_exponent", 0.70, 0.65, 0.75)})));
    writeSet(b, 0, truth(nothing, 21), residual(none, 9.25));
    writeSet(b, 1, truth({{"effects", {"hertzian_contact"}}, {"params", {{"load_exponent", 0.80}}}}, 22), none);
    writeSet(b, 2, truth({{"effects", {"hertzian_contact"}}, {"params", {{"load_exponent", 0.60}}}}, 23),
             diagnosis(json::array({finding("hertzian_contact", "load_exponent", 0.62, 0.61, 0.66)}))); // misses 0.60
    std::ofstream(a / "plan.json") << json{{"grid", 12}, {"seed", 1}, {"sets", json::array()}}.dump();
    std::ofstream(b / "plan.json") << json{{"grid", 12}, {"seed", 2}, {"plan", 2}, {"sets", json::array()}}.dump();

    const std::string md = scoreStudies(out, {a, b});
    json study;
    std::ifstream(out / "study.json") >> study;
    const json& s = study["summary"];
    EXPECT_EQ(s["sets"], 5);
    EXPECT_EQ(s["null_sets"], 2);
    EXPECT_EQ(s["detection"]["hertzian_contact"]["hidden"], 3);
    EXPECT_EQ(s["detection"]["hertzian_contact"]["named"], 2);
    EXPECT_EQ(s["parameters"]["load_exponent"]["named"], 2);
    // Coverage 1 of 2 pooled, and by study: a's interval holds its truth, b's misses.
    EXPECT_EQ(s["coverage_by_study"][a.filename().string()], json({{"covered", 1}, {"intervals", 1}}));
    EXPECT_EQ(s["coverage_by_study"][b.filename().string()], json({{"covered", 0}, {"intervals", 1}}));
    EXPECT_NE(md.find("By study: " + a.filename().string() + " 100 % (1 of 1), " + b.filename().string() + " 0 % (0 of 1)."), std::string::npos) << md;
    EXPECT_DOUBLE_EQ(s["usual_residual_measured"].get<double>(), 9.25); // study b's null, not a's 6.5
    EXPECT_EQ(s["pooled_from"], json({a.filename().string(), b.filename().string()}));
    EXPECT_EQ(study["sets"][3]["study"], b.filename().string());
    EXPECT_EQ(study["sets"][3]["set"], 1);
    EXPECT_NE(md.find("Scored together from 2 studies: " + a.filename().string() + " (seed 1, 2 sets), " + b.filename().string() + " (seed 2, 3 sets)."),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| " + b.filename().string() + "/2 | hertzian_contact"), std::string::npos) << md;
    EXPECT_FALSE(fs::exists(a / "study.json")) << "the sources stay as they were";

    // The pooled summary may not overwrite a source's, nor count a set twice.
    EXPECT_THROW(scoreStudies(a, {a, b}), LabError);
    EXPECT_THROW(scoreStudies(out, {a, a}), LabError);
    // Different strokes per set are a different population.
    std::ofstream(b / "plan.json") << json{{"grid", 8}, {"seed", 2}, {"sets", json::array()}}.dump();
    const std::string grids = poolRefusal(out, {a, b});
    EXPECT_NE(grids.find("must share the grid"), std::string::npos) << "studies of grids 12 and 8: " << grids;
    // A newton study whose plan.json does not say so (older ones did not) is still told apart
    // by its diagnoses' sensor scale.
    std::ofstream(b / "plan.json") << json{{"grid", 12}, {"seed", 2}, {"sets", json::array()}}.dump();
    const auto withScale = [](json d, const std::string& meaning) {
        d["calibration"]["values"]["scale_n_per_unit"] = {{"value", 1.0}, {"ci95", {1.0, 1.0}}, {"meaning", meaning}};
        return d;
    };
    writeSet(a, 0, truth(nothing, 11), withScale(residual(none, 6.5), "sensor scale (N per signal unit) from the pre-slip ramps"));
    writeSet(b, 0, truth(nothing, 21), withScale(residual(none, 9.25), "sensor scale: the set is calibrated in N"));
    const std::string units = poolRefusal(out, {a, b});
    EXPECT_NE(units.find("must share the sensor's units"), std::string::npos) << "a volt study and a newton study: " << units;
    writeSet(b, 0, truth(nothing, 21), withScale(residual(none, 9.25), "sensor scale (N per signal unit) from the pre-slip ramps"));
    EXPECT_NO_THROW(scoreStudies(out, {a, b}));
    // The split is part of the procedure whose rates are scored: a study whose strokes were dealt
    // over the plane is not pooled with a shuffled one. A diagnosis without a method (before the
    // stratified split existed) was shuffled.
    const auto writeSplit = [](const fs::path& folder, int index, const std::string& method) {
        std::ofstream(setDir(folder, index) / "diagnosis" / "split.json") << json{{"seed", 1}, {"method", method}}.dump();
    };
    writeSplit(a, 0, "random");
    EXPECT_NE(scoreStudies(out, {a, b}).find("Strokes split into fit, validation and test: shuffled"), std::string::npos);
    writeSplit(b, 2, "stratified");
    const std::string splits = poolRefusal(out, {a, b});
    EXPECT_NE(splits.find("must split their strokes the same way"), std::string::npos) << "a stratified set among shuffled ones: " << splits;
    EXPECT_NE(splits.find("split.json"), std::string::npos) << splits;
    for (int i : {0, 1}) writeSplit(a, i, "stratified");
    for (int i : {0, 1}) writeSplit(b, i, "stratified");
    EXPECT_NE(scoreStudies(out, {a, b}).find("Strokes split into fit, validation and test: stratified over the Guettler plane"), std::string::npos);
    std::ifstream(out / "study.json") >> study;
    EXPECT_EQ(study["summary"]["split_method"], "stratified");
    for (const auto& folder : {a, b})
        for (int i : {0, 1, 2})
            if (fs::exists(setDir(folder, i))) fs::remove(setDir(folder, i) / "diagnosis" / "split.json");
    // So is the search, where diagnosis.json records it (older diagnoses did not, and are taken as they are).
    const auto writeSearch = [](const fs::path& folder, int index, bool secondStart) {
        const fs::path file = setDir(folder, index) / "diagnosis" / "diagnosis.json";
        json d;
        std::ifstream(file) >> d;
        d["search"] = {{"pairs", false}, {"contact_restart", true}, {"second_start", secondStart}};
        std::ofstream(file) << d.dump();
    };
    writeSearch(a, 0, true);
    EXPECT_NE(scoreStudies(out, {a, b}).find("Search: contact_restart on, pairs off, second_start on ("), std::string::npos);
    writeSearch(b, 0, false);
    const std::string searches = poolRefusal(out, {a, b});
    EXPECT_NE(searches.find("/diagnosis/diagnosis.json: search contact_restart on, pairs off, second_start off where "), std::string::npos)
        << "a study searched with a second start and one without: " << searches;
    EXPECT_NE(searches.find("must search the same way"), std::string::npos) << searches;
    writeSearch(b, 0, true);
    scoreStudies(out, {a, b});
    std::ifstream(out / "study.json") >> study;
    EXPECT_EQ(study["summary"]["search"]["second_start"], true);
    // And so is the metric's weighting; a diagnosis that does not record it ran with the default.
    const auto writeWeights = [](const fs::path& folder, int index, const json& weights) {
        const fs::path file = setDir(folder, index) / "diagnosis" / "diagnosis.json";
        json d;
        std::ifstream(file) >> d;
        d["metric_weights"] = weights;
        std::ofstream(file) << d.dump();
    };
    writeWeights(a, 1, {0.25, 0.25, 0.25, 0.1, 0.15});
    EXPECT_NE(scoreStudies(out, {a, b}).find("Metric weights (first-slip time, force before it, jump, transient length, waveform): 0.25/0.25/0.25/0.1/0.15 (the default)."),
              std::string::npos);
    writeWeights(b, 1, {0.3, 0.3, 0.3, 0.0, 0.1});
    const std::string metrics = poolRefusal(out, {a, b});
    EXPECT_NE(metrics.find("/diagnosis/diagnosis.json: metric weights 0.3/0.3/0.3/0/0.1 where "), std::string::npos) << metrics;
    EXPECT_NE(metrics.find("must use one metric"), std::string::npos) << metrics;
    writeWeights(b, 1, {0.3, 0.3});
    EXPECT_NE(poolRefusal(out, {a, b}).find("\"metric_weights\" is not a list of five numbers"), std::string::npos);
    writeWeights(b, 1, {0.25, 0.25, 0.25, 0.1, 0.15});
    scoreStudies(out, {a, b});
    std::ifstream(out / "study.json") >> study;
    EXPECT_EQ(study["summary"]["metric_weights"][3], 0.1);
    // One study scored on its own keeps its plain labels and gains no "pooled_from".
    scoreStudy(a);
    json alone;
    std::ifstream(a / "study.json") >> alone;
    EXPECT_FALSE(alone["summary"].contains("pooled_from"));
    EXPECT_FALSE(alone["summary"].contains("coverage_by_study")) << "one study has no per-study line";
    EXPECT_EQ(alone["sets"][0]["study"], "");
    for (const auto& d : {a, b, out}) fs::remove_all(d);
}

// One plan's sets diagnosed under three splits, side by side (`study --compare-splits`): a set
// counts as alike only when every split names the same effects, an effect is counted as named
// under every split, some or none, a wrong label under any one split is counted, and each split's
// exact count and coverage are its own. What would make the comparison meaningless is refused.
TEST(Study, TheSameSetsUnderSeveralSplitsAreComparedSetBySet)
{
    const fs::path a = freshDir("splits-a"), b = freshDir("splits-b"), c = freshDir("splits-c"), out = freshDir("splits-out");
    const auto truth = [](json t, std::uint64_t seed) { t["seed"] = seed; return t; };
    const auto writeSplit = [](const fs::path& folder, int index, std::uint64_t seed) {
        std::ofstream(setDir(folder, index) / "diagnosis" / "split.json") << json{{"seed", seed}, {"method", "random"}}.dump();
    };
    const json nothing{{"effects", json::array()}, {"params", json::object()}};
    const json contactTruth{{"effects", {"hertzian_contact"}}, {"params", {{"load_exponent", 0.67}}}};
    const json thermalTruth{{"effects", {"thermal_memory"}}, {"params", {{"r_A", 1.0}}}};
    const json none = diagnosis(json::array({{{"effect", "none"}}}));
    const json contactHeld = diagnosis(json::array({finding("hertzian_contact", "load_exponent", 0.70, 0.65, 0.75)}));
    const json contactMissed = diagnosis(json::array({finding("hertzian_contact", "load_exponent", 0.70, 0.68, 0.72)}));
    const json thermal = diagnosis(json::array({finding("thermal_memory", "r_A", 1.02, 0.95, 1.1)}));
    // Set 0 is null: only c names a contact there. Set 1 hides a contact: a and b name it (a's
    // interval holds the truth, b's does not), c misses it. Set 2: all three name thermal memory.
    writeSet(a, 0, truth(nothing, 11), none);
    writeSet(b, 0, truth(nothing, 11), none);
    writeSet(c, 0, truth(nothing, 11), contactHeld);
    writeSet(a, 1, truth(contactTruth, 12), contactHeld);
    writeSet(b, 1, truth(contactTruth, 12), contactMissed);
    writeSet(c, 1, truth(contactTruth, 12), none);
    for (const auto& folder : {a, b, c}) writeSet(folder, 2, truth(thermalTruth, 13), thermal);
    writeSet(a, 3, truth(thermalTruth, 14), thermal); // diagnosed under one split only: left out
    for (int i : {0, 1, 2, 3}) writeSplit(a, i, 1);
    for (int i : {0, 1, 2}) writeSplit(b, i, 2);
    for (int i : {0, 1, 2}) writeSplit(c, i, 30 + static_cast<std::uint64_t>(i)); // a split per set
    for (const auto& folder : {a, b, c}) std::ofstream(folder / "plan.json") << json{{"grid", 12}, {"seed", 5}, {"sets", json::array()}}.dump();

    const std::string md = compareSplits(out, {a, b, c});
    json r;
    std::ifstream(out / "splits.json") >> r;
    EXPECT_EQ(r["sets_compared"], 3);
    EXPECT_EQ(r["sets_left_out"], 1);
    EXPECT_EQ(r["sets_alike"], 1) << "only set 2 is named alike under every split";
    EXPECT_EQ(r["null_sets"], 1);
    EXPECT_EQ(r["null_sets_naming_under_any"], 1);
    EXPECT_EQ(r["effects"]["hertzian_contact"],
              json({{"hidden", 1}, {"named_under_every_split", 0}, {"named_under_some", 1}, {"named_under_none", 0}, {"named_where_not_hidden_under_any", 1}}));
    EXPECT_EQ(r["effects"]["thermal_memory"]["named_under_every_split"], 1);
    EXPECT_EQ(r["effects"]["thermal_memory"]["named_where_not_hidden_under_any"], 0);
    ASSERT_EQ(r["studies"].size(), 3u);
    EXPECT_EQ(r["studies"][0]["exactly_right"], 3);
    EXPECT_EQ(r["studies"][2]["exactly_right"], 1);
    EXPECT_EQ(r["studies"][2]["labels_where_not_hidden"], 1);
    EXPECT_EQ(r["studies"][0]["covered"], 2);
    EXPECT_EQ(r["studies"][1]["covered"], 1) << "b's contact interval misses 0.67";
    EXPECT_EQ(r["studies"][1]["intervals"], 2);
    EXPECT_EQ(r["studies"][2]["intervals"], 1) << "a contact named on a null set has no truth to hold";
    EXPECT_EQ(r["coverage"], json({{"covered", 4}, {"intervals", 5}}));
    EXPECT_EQ(r["studies"][0]["split"], "one split for every set, seed 1");
    EXPECT_EQ(r["studies"][2]["split"], "a split per set, 3 seeds over 3 sets");
    EXPECT_NE(md.find("Sets named alike under every split: 1 of 3 (33 %)"), std::string::npos) << md;
    EXPECT_NE(md.find("| 1 | hertzian_contact | hertzian_contact | hertzian_contact | none |"), std::string::npos) << md;
    EXPECT_NE(md.find("(1 more diagnosed in some only, left out)"), std::string::npos) << md;

    const auto refusal = [&](const fs::path& into, const std::vector<fs::path>& studies) {
        try {
            compareSplits(into, studies);
        } catch (const LabError& e) {
            return std::string(e.what());
        }
        return std::string("compared");
    };
    EXPECT_NE(refusal(out, {a}).find("two or more"), std::string::npos);
    EXPECT_NE(refusal(a, {a, b}).find("would be written into a study it compares"), std::string::npos);
    // The same split under two names compares nothing.
    writeSplit(c, 2, 1);
    const std::string twice = refusal(out, {a, b, c});
    EXPECT_NE(twice.find("split seed 1, as in " + a.string()), std::string::npos) << twice;
    EXPECT_NE(twice.find(setDir(c, 2).string() + "/diagnosis/split.json"), std::string::npos) << twice;
    writeSplit(c, 2, 32);
    // Another plan's sets, or another metric, is not another split.
    std::ofstream(c / "plan.json") << json{{"grid", 12}, {"seed", 6}, {"sets", json::array()}}.dump();
    EXPECT_NE(refusal(out, {a, b, c}).find("splits are compared on one plan's sets"), std::string::npos);
    std::ofstream(c / "plan.json") << json{{"grid", 12}, {"seed", 5}, {"sets", json::array()}}.dump();
    json weighted = thermal;
    weighted["metric_weights"] = {0.3, 0.3, 0.3, 0.0, 0.1};
    writeSet(c, 2, truth(thermalTruth, 13), weighted);
    EXPECT_NE(refusal(out, {a, b, c}).find("splits compared must use one metric"), std::string::npos);
    writeSet(c, 2, truth(thermalTruth, 13), thermal);
    EXPECT_EQ(refusal(out, {a, b, c}), "compared");
    for (const auto& d : {a, b, c, out}) fs::remove_all(d);
}
