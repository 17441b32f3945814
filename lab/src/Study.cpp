// `rosin study`, planning and running: which effects each set hides, and each set simulated by
// the reference simulator (or, as a ceiling, by dsp/'s model on the same rigs) and diagnosed
// from its files; and the plan.json both halves read (StudyPlan.h). Scoring is in StudyScore.cpp.
#include "rosin/lab/Study.h"

#include <sndfile.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "rosin/lab/Distributed.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/SynthData.h"
#include "StudyPlan.h"

namespace rosin::lab {
namespace fs = std::filesystem;
using nlohmann::json;

std::string effectsLabel(const std::vector<std::string>& effects)
{
    if (effects.empty()) return "none";
    std::string s;
    for (const auto& x : effects) s += (s.empty() ? "" : "+") + x;
    return s;
}

std::vector<StudySet> planStudy(const StudyOptions& o)
{
    if (o.sets < 1 || o.nulls < 0 || o.nulls > o.sets) throw LabError("study: need 0 <= nulls <= sets and at least one set");
    if (o.plan != 1 && o.plan != 2) throw LabError("study --plan: " + std::to_string(o.plan) + " is not a plan version (1 or 2)");
    std::mt19937_64 rng(o.seed);
    const std::vector<std::vector<std::string>> singles{{"thermal_memory"}, {"rate_dependence"}, {"hertzian_contact"},
                                                        {"rosin_temperature_shift"}, {"torsional_compliance"}};
    std::vector<std::vector<std::string>> doubles{{"thermal_memory", "hertzian_contact"},       {"hertzian_contact", "torsional_compliance"},
                                                  {"thermal_memory", "torsional_compliance"},   {"rosin_temperature_shift", "hertzian_contact"},
                                                  {"rate_dependence", "torsional_compliance"},  {"rosin_temperature_shift", "torsional_compliance"},
                                                  {"rate_dependence", "hertzian_contact"}};
    // Version 2: a shift beside a rate law, the pair the diagnosis finds hardest to tell apart.
    if (o.plan >= 2) doubles.push_back({"rate_dependence", "rosin_temperature_shift"});
    const std::vector<std::vector<std::string>> triples{{"thermal_memory", "hertzian_contact", "torsional_compliance"},
                                                        {"rosin_temperature_shift", "hertzian_contact", "torsional_compliance"},
                                                        {"rate_dependence", "hertzian_contact", "torsional_compliance"}};
    const int rest = o.sets - o.nulls;
    const int nSingle = static_cast<int>(std::lround(0.45 * rest)), nDouble = static_cast<int>(std::lround(0.35 * rest));
    const int nTriple = rest - nSingle - nDouble;
    std::vector<std::vector<std::string>> effects(static_cast<std::size_t>(o.nulls));
    auto take = [&](auto list, int count) {
        std::shuffle(list.begin(), list.end(), rng);
        for (int k = 0; k < count; ++k) effects.push_back(list[static_cast<std::size_t>(k) % list.size()]);
    };
    take(singles, nSingle);
    take(doubles, nDouble);
    take(triples, nTriple);
    std::shuffle(effects.begin(), effects.end(), rng);
    std::vector<StudySet> plan;
    for (std::size_t k = 0; k < effects.size(); ++k)
        plan.push_back({static_cast<int>(k), o.seed * 1000 + k + 1, effects[k]});
    return plan;
}

namespace {
json readJsonFile(const fs::path& file)
{
    json j;
    try {
        std::ifstream(file) >> j;
    } catch (const json::exception& e) {
        throw LabError(file.string() + ": unreadable (" + e.what() + ")");
    }
    return j;
}

} // namespace

fs::path setFolder(const fs::path& dir, int index)
{
    char name[16];
    std::snprintf(name, sizeof name, "%03d", index);
    return dir / "sets" / name;
}

json readPlan(const fs::path& dir) { return fs::exists(dir / "plan.json") ? readJsonFile(dir / "plan.json") : json(); }

SplitRecord readSplitRecord(const fs::path& file)
{
    const json j = readJsonFile(file);
    SplitRecord r;
    r.seed = j.value("seed", r.seed);
    r.method = j.value("method", r.method);
    return r;
}

std::map<std::string, bool> searchRecordOf(const json& diagnosis, const fs::path& file)
{
    if (!diagnosis.contains("search")) return {};
    try {
        return diagnosis["search"].get<std::map<std::string, bool>>();
    } catch (const json::exception&) {
        throw LabError(file.string() + ": \"search\" is not an object of on/off switches");
    }
}

std::string describeSearch(const std::map<std::string, bool>& search)
{
    if (search.empty()) return "not recorded";
    std::string text;
    for (const auto& [name, on] : search) text += (text.empty() ? "" : ", ") + name + (on ? " on" : " off");
    return text;
}

std::array<double, 5> metricWeightsOf(const json& diagnosis, const fs::path& file)
{
    if (!diagnosis.contains("metric_weights")) return ErrorParts::kWeights;
    const json& w = diagnosis["metric_weights"];
    if (!w.is_array() || w.size() != 5 || !std::all_of(w.begin(), w.end(), [](const json& x) { return x.is_number(); }))
        throw LabError(file.string() + ": \"metric_weights\" is not a list of five numbers");
    std::array<double, 5> weights{};
    for (std::size_t k = 0; k < 5; ++k) weights[k] = w[k].get<double>();
    return weights;
}

std::string describeMetricWeights(const std::array<double, 5>& weights)
{
    std::string text;
    char buf[32];
    for (double x : weights) {
        std::snprintf(buf, sizeof buf, "%g", x);
        if (!text.empty()) text += '/';
        text += buf;
    }
    return text + (defaultMetricWeights(weights) ? " (the default)" : "");
}

json populationOf(const json& plan)
{
    json p;
    for (const char* key : {"grid", "gesture", "units", "generator", "rig", "param_ranges", "stated_uncertainty"})
        if (plan.contains(key)) p[key] = plan[key];
    return p;
}

void runStudy(const fs::path& dir, const StudyOptions& o, const std::function<void(const std::string&, double)>& progress)
{
    const std::vector<StudySet> plan = planStudy(o);
    if (o.units != "V" && o.units != "N") throw LabError("study --units: '" + o.units + "' is neither V nor N");
    if (o.generator != "reference" && o.generator != "model-on-rig")
        throw LabError("study --generator: '" + o.generator + "' is neither reference nor model-on-rig");
    for (const int k : o.only)
        if (k < 0 || k >= static_cast<int>(plan.size()))
            throw LabError("study --only: set " + std::to_string(k) + " is not in a plan of " + std::to_string(plan.size()) + " sets");
    const Distributed& mpi = Distributed::instance();
    json planJson = json::array();
    for (const auto& p : plan) planJson.push_back({{"index", p.index}, {"seed", p.seed}, {"effects", p.effects}});
    planJson = json{{"grid", o.grid}, {"seed", o.seed}, {"sets", planJson}};
    if (o.gesture != "guettler") planJson["gesture"] = o.gesture; // Guettler studies' plans stay as they were
    if (o.plan != 1) planJson["plan"] = o.plan;                    // and so do version-1 plans
    if (o.units == "N" && o.gesture != "exp_force") planJson["units"] = "N"; // and volt studies
    if (o.generator != "reference") planJson["generator"] = o.generator;     // and reference ones
    if (!o.rig.empty()) planJson["rig"] = o.rig;                   // fixed rig values: part of the study
    for (const auto& [key, range] : o.paramRanges) planJson["param_ranges"][key] = {range.first, range.second}; // and narrowed draws
    if (!o.statedUncertainty.empty()) planJson["stated_uncertainty"] = o.statedUncertainty;      // and what the labs state
    // A folder resumes only the study it holds: sets are skipped by folder name, so a different
    // seed, size or grid would silently mix two studies.
    if (fs::exists(dir / "plan.json")) {
        if (readPlan(dir) != planJson)
            throw LabError((dir / "plan.json").string() + ": this folder holds a different study (seed, sets, nulls, grid, gesture, units, generator, fixed rig values, narrowed parameter ranges, stated uncertainties or plan version: "
                                                          "a plan.json without \"plan\" is version 1, --plan 1); use a new folder");
    }
    fs::create_directories(dir / "sets");
    if (mpi.isRoot() && !fs::exists(dir / "plan.json")) std::ofstream(dir / "plan.json") << planJson.dump(1) << "\n";
    mpi.barrier();
    // The sets to run now are picked before they are dealt to ranks, so a few picked sets spread
    // over the ranks rather than falling to whichever ranks their plan indices name.
    std::vector<StudySet> picked;
    for (const StudySet& p : plan)
        if ((o.only.empty() || std::find(o.only.begin(), o.only.end(), p.index) != o.only.end()) &&
            (o.hiding.empty() || std::find(p.effects.begin(), p.effects.end(), o.hiding) != p.effects.end()))
            picked.push_back(p);
    // The split is part of what a study measures, so a resumed study may not change it either:
    // sets already diagnosed are checked before any work, or a study would score two kinds of
    // split (or one shared split and forty) as one.
    const auto diagnoseSeedOf = [&](const StudySet& p) { return o.splitPerSet ? perSetDiagnoseSeed(o.diagnose.seed, p.seed) : o.diagnose.seed; };
    const std::string method = splitMethodName(o.diagnose);
    // The search is part of the procedure too (--pairs, --contact-restart, --second-start);
    // diagnoses from before diagnosis.json recorded it cannot be checked and are kept.
    const std::map<std::string, bool> search = searchSwitches(o.diagnose);
    for (const StudySet& p : picked) {
        const fs::path diagnosed = setFolder(dir, p.index) / "diagnosis";
        if (const fs::path split = diagnosed / "split.json"; fs::exists(split)) {
            const SplitRecord was = readSplitRecord(split);
            if (was.seed != diagnoseSeedOf(p) || was.method != method)
                throw LabError(split.string() + ": this set was diagnosed with split seed " + std::to_string(was.seed) + " (method \"" + was.method +
                               "\") where this run would use " + std::to_string(diagnoseSeedOf(p)) + " (\"" + method +
                               "\"); a resumed study keeps its --split-per-set, --stratified-split and --diagnose-seed: use a new folder, or remove the sets' diagnosis folders");
        }
        if (const fs::path diagnosis = diagnosed / "diagnosis.json"; fs::exists(diagnosis)) {
            const json record = readJsonFile(diagnosis);
            const std::map<std::string, bool> was = searchRecordOf(record, diagnosis);
            if (!was.empty() && was != search)
                throw LabError(diagnosis.string() + ": this set was diagnosed with " + describeSearch(was) + " where this run would search with " +
                               describeSearch(search) + "; a resumed study keeps its --pairs, --contact-restart and --second-start: use a new folder, or remove the sets' diagnosis folders");
            // The metric's weights decide every fit and every naming, as the search does.
            if (const auto weights = metricWeightsOf(record, diagnosis); weights != o.diagnose.metricWeights)
                throw LabError(diagnosis.string() + ": this set was diagnosed with metric weights " + describeMetricWeights(weights) + " where this run has " +
                               describeMetricWeights(o.diagnose.metricWeights) + "; a resumed study keeps its --metric-weights: use a new folder, or remove the sets' diagnosis folders");
        }
    }
    std::size_t done = 0;
    for (const StudySet& p : picked) {
        ++done;
        if (static_cast<int>((done - 1) % static_cast<std::size_t>(mpi.size())) != mpi.rank()) continue;
        const fs::path here = setFolder(dir, p.index);
        const std::string name = here.filename().string();
        if (fs::exists(here / "diagnosis" / "diagnosis.json")) continue; // resumed study: already done
        // A set kept by an earlier run (--keep-sets, --generate-only) is diagnosed as it is: the
        // reference simulation is most of a set's time.
        const bool kept = fs::exists(here / "truth.json") && fs::exists(here / "set" / "manifest.json");
        if (kept && o.generateOnly) continue;
        if (!kept) {
            fs::remove_all(here);
            fs::create_directories(here);
        }
        auto say = [&](const std::string& what, double x) {
            if (progress) progress("set " + name + " (" + effectsLabel(p.effects) + "): " + what, (static_cast<double>(done - 1) + x) / static_cast<double>(picked.size()));
        };
        SynthSpec spec;
        spec.generator = o.generator;
        spec.seed = p.seed;
        spec.effects = p.effects;
        spec.grid = o.grid;
        spec.oversampling = o.oversampling;
        spec.gesture = o.gesture;
        spec.rig = o.rig;
        spec.paramRanges = o.paramRanges;
        spec.statedUncertainty = o.statedUncertainty;
        spec.units = o.gesture == "exp_force" ? "N" : o.units;
        if (!kept) {
            SynthTruth truth;
            say("simulating", 0.0);
            const MeasurementSet made = synthesize(spec, truth, [&](double x) { say("simulating", (o.generateOnly ? 1.0 : 0.5) * x); });
            // the truth last, so a set with a truth.json is whole
            writeMeasurementSet(here / "set", made, spec.units == "N" ? SF_FORMAT_FLOAT : SF_FORMAT_PCM_24); // newtons pass PCM's full scale
            writeTruth(here / "truth.json", truth, p.seed);
        }
        if (o.generateOnly) continue;
        const MeasurementSet set = readMeasurementSet(here / "set");
        DiagnoseOptions d = o.diagnose;
        d.quiet = true;
        d.seed = diagnoseSeedOf(p);
        const Diagnosis result = diagnose(set, d, [&](const std::string&, double x) { say("diagnosing", 0.5 + 0.5 * x); });
        const fs::path tmp = here / ".diagnosis.partial";
        writeDiagnosis(tmp, result, d);
        fs::rename(tmp, here / "diagnosis");
        if (!o.keepSets && !kept) fs::remove_all(here / "set");
    }
    mpi.barrier();
}

std::uint64_t perSetDiagnoseSeed(std::uint64_t diagnoseSeed, std::uint64_t setSeed)
{
    // splitmix64's finaliser over the pair: neighbouring set seeds get unrelated splits, and the
    // result stays under 2^53 so that split.json's number reads back exactly anywhere.
    std::uint64_t z = diagnoseSeed * 0x9E3779B97F4A7C15ull + setSeed;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (z ^ (z >> 31)) >> 11;
}

} // namespace rosin::lab
