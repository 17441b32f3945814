// `rosin study`, scoring: each diagnosed set against its hidden truth (detection, false
// positives, parameter error, coverage, detection against size), for one study or several pooled.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "DiagnoseEngine.h"
#include "StudyPlan.h"
#include "StudyScored.h"
#include "rosin/dsp/FrictionLaws.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Study.h"
#include "rosin/lab/SynthData.h"

namespace rosin::lab {
namespace fs = std::filesystem;
using nlohmann::json;
using namespace scoring;

namespace {
std::string fmt(const char* f, double x)
{
    char b[256];
    std::snprintf(b, sizeof b, f, x);
    return b;
}

/// A plan's object as "key<text>, key<text>", each text written from its value by `entry`.
std::string joined(const json& items, const std::function<std::string(const json&)>& entry)
{
    std::string out;
    for (const auto& [k, v] : items.items()) out += (out.empty() ? "" : ", ") + k + entry(v);
    return out;
}
/// The named parameters against the truth (error, tolerance, coverage of the intervals and
/// their parts, per study when pooled) and the model discrepancy the sets measure.
void scoreParameters(std::ostringstream& md, json& summary, const std::vector<Scored>& sets)
{
    md << "\n| parameter | named sets | median error | worst error | within the issue's tolerance | truth inside the 95 % interval |\n|---|---|---|---|---|---|\n";
    int covered = 0, intervals = 0, coveredWithoutHalves = 0, coveredStatistical = 0, coveredWithRig = 0;
    // The model discrepancy this study measures: the spread of (found - true) beyond what the
    // statistical and rig-unknown intervals allow, by moments (relative for r_A and zt_ratio).
    std::map<std::string, std::pair<double, int>> excess;
    std::map<std::string, std::pair<int, int>> coverageByStudy; ///< pooled: study -> covered, intervals
    for (const std::string& p : physicalParameterNames()) {
        std::vector<double> err;
        int within = 0, inside = 0, unidentified = 0;
        const Tolerance tol = tolerances().at(p);
        for (const auto& s : sets) {
            if (!s.truth.count(p) || !s.estimate.count(p) || !has(s.found, effectOfParameter(p))) continue;
            const double t = s.truth.at(p), v = s.estimate.at(p)[0];
            const double e = tol.relative ? std::abs(v / t - 1.0) : std::abs(v - t);
            err.push_back(e);
            within += e <= tol.value;
            // A parameter not identified is counted apart, not as covered (truthInInterval).
            const auto covers = truthInInterval(s, p);
            if (!covers) {
                ++unidentified;
                continue;
            }
            const bool in = *covers;
            inside += in;
            covered += in;
            ++intervals;
            coverageByStudy[s.study].first += in;
            ++coverageByStudy[s.study].second;
            const auto narrow = s.withoutHalves.find(p);
            coveredWithoutHalves += narrow != s.withoutHalves.end() ? t >= narrow->second[0] && t <= narrow->second[1] : in;
            const auto stat = s.statistical.find(p);
            coveredStatistical += stat != s.statistical.end() ? t >= stat->second[0] && t <= stat->second[1] : in;
            const auto rig = s.withRig.find(p);
            coveredWithRig += rig != s.withRig.end() ? t >= rig->second[0] && t <= rig->second[1] : in;
            if (rig != s.withRig.end()) {
                const double unit = discrepancyIsRelative(p) ? std::abs(t) : 1.0;
                const double sd = (rig->second[1] - rig->second[0]) / (2.0 * 1.96) / unit, miss = (v - t) / unit;
                excess[p].first += miss * miss - sd * sd;
                ++excess[p].second;
            }
        }
        if (err.empty()) {
            md << "| " << p << " | 0 | - | - | - | - |\n";
            continue;
        }
        std::sort(err.begin(), err.end());
        const char* unit = tol.relative ? "%.1f %%" : "%.3g";
        const double k = tol.relative ? 100.0 : 1.0;
        md << "| " << p << " | " << err.size() << " | " << fmt(unit, k * err[err.size() / 2]) << " | " << fmt(unit, k * err.back()) << " | "
           << within << " (tolerance " << fmt(unit, k * tol.value) << ") | " << inside << " of " << err.size() - static_cast<std::size_t>(unidentified)
           << (unidentified ? " (" + std::to_string(unidentified) + " not identified)" : std::string()) << " |\n";
        summary["parameters"][p] = {{"named", err.size()}, {"median_error", err[err.size() / 2]}, {"worst_error", err.back()},
                                    {"within_tolerance", within}, {"covered", inside}, {"not_identified", unidentified}};
    }
    md << fmt("\nCoverage of the 95 %% intervals over all named parameters that the data identify: %.0f %%", intervals ? 100.0 * covered / intervals : 0.0)
       << " (" << covered << " of " << intervals << ")"
       << fmt("; statistical part only (bootstrap, curvature, drive halves): %.0f %%", intervals ? 100.0 * coveredStatistical / intervals : 0.0)
       << " (" << coveredStatistical << fmt("); with the rig unknowns, without the model discrepancy: %.0f %%", intervals ? 100.0 * coveredWithRig / intervals : 0.0)
       << " (" << coveredWithRig << fmt("); bootstrap and curvature only: %.0f %%", intervals ? 100.0 * coveredWithoutHalves / intervals : 0.0)
       << " (" << coveredWithoutHalves << ").\n";
    // Pooled: each seed's own coverage, since the issue asks it of every study, not of the pool.
    if (coverageByStudy.size() > 1) {
        md << "\nBy study:";
        const char* sep = " ";
        for (const auto& [name, c] : coverageByStudy) {
            md << sep << name << fmt(" %.0f %%", 100.0 * c.first / c.second) << " (" << c.first << " of " << c.second << ")";
            summary["coverage_by_study"][name] = {{"covered", c.first}, {"intervals", c.second}};
            sep = ", ";
        }
        md << ".\n";
    }
    md << "\nModel discrepancy this study measures (standard deviation of found - true beyond the statistical and rig-unknown intervals; "
          "relative for r_A and zt_ratio; `rosin diagnose --model-discrepancy NAME=SD` takes it):";
    for (const auto& [p, e] : excess) {
        const double sd = std::sqrt(std::max(0.0, e.first / e.second));
        md << " " << p << fmt(" %.3g", sd) << " (" << e.second << " sets);";
        summary["model_discrepancy"][p] = sd;
        // The raw moments too, so that studies of several seeds pool exactly:
        // sd = sqrt(sum of excess_sum / sum of sets), clipped at 0 only once.
        summary["model_discrepancy_moments"][p] = {{"excess_sum", e.first}, {"sets", e.second}};
    }
    md << "\n";
    summary["coverage_statistical"] = intervals ? static_cast<double>(coveredStatistical) / intervals : 0.0;
    summary["coverage_with_rig_unknowns"] = intervals ? static_cast<double>(coveredWithRig) / intervals : 0.0;
    summary["coverage"] = intervals ? static_cast<double>(covered) / intervals : 0.0;
    summary["coverage_without_halves"] = intervals ? static_cast<double>(coveredWithoutHalves) / intervals : 0.0;
}

/// A reading's error in its tolerance's unit, signed so that positive means the reading is
/// further from no effect than the truth (a stronger effect than hidden); r_A, which has no
/// no-effect value, is signed as read (positive: larger).
double strongerBy(const std::string& p, double reading, double truth)
{
    if (p == "shift_k") return truth < 0.0 ? truth - reading : reading - truth;
    if (p == "load_exponent") return truth - reading;
    if (p == "zt_ratio") return 1.0 - reading / truth;
    if (p == "p") return reading - truth;
    return reading / truth - 1.0;
}

/// Round 1's reading of every hidden effect's parameter, named or not, beside the named ones.
/// The parameter table above scores only what the rules named, and the rules name mostly the
/// readings far from no effect, so a weak effect that is named tends to read strong: this table
/// tells the estimate's own error from that choice.
void scoreFirstReadings(std::ostringstream& md, json& summary, const std::vector<Scored>& sets)
{
    struct Reading {
        double error;
        bool named;
    };
    std::map<std::string, std::vector<Reading>> byParameter;
    for (const auto& s : sets)
        for (const auto& [p, v] : s.firstReading)
            if (s.truth.count(p) && has(s.hidden, effectOfParameter(p)) && diag::identifiable(p))
                byParameter[p].push_back({strongerBy(p, v, s.truth.at(p)), has(s.found, effectOfParameter(p))});
    if (byParameter.empty()) return;
    md << "\nFirst readings: round 1 fits every effect's candidate, named or not. The error is signed, positive where the reading is "
          "further from no effect than the truth (r_A: larger); h0, which no data fix, is left out.\n\n"
          "| parameter | hidden sets read in round 1 | error: median (quartiles) | within the issue's tolerance | where named: sets, median first-reading error | "
          "where not named: sets, median first-reading error |\n|---|---|---|---|---|---|\n";
    // nearest-rank quantile of a sorted list
    auto at = [](const std::vector<double>& v, double q) { return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]; };
    for (const std::string& p : physicalParameterNames()) {
        const auto it = byParameter.find(p);
        if (it == byParameter.end()) continue;
        const Tolerance tol = tolerances().at(p);
        std::vector<double> all, named, notNamed;
        int within = 0;
        for (const Reading& r : it->second) {
            all.push_back(r.error);
            (r.named ? named : notNamed).push_back(r.error);
            within += std::abs(r.error) <= tol.value;
        }
        for (auto* v : {&all, &named, &notNamed}) std::sort(v->begin(), v->end());
        const char* unit = tol.relative ? "%+.1f %%" : "%+.3g";
        const double k = tol.relative ? 100.0 : 1.0;
        auto medianText = [&](const std::vector<double>& v) { return v.empty() ? std::string("-") : fmt(unit, k * at(v, 0.5)); };
        md << "| " << p << " | " << all.size() << " | " << fmt(unit, k * at(all, 0.5)) << " (" << fmt(unit, k * at(all, 0.25)) << " to "
           << fmt(unit, k * at(all, 0.75)) << ") | " << within << " | " << named.size() << ", " << medianText(named) << " | " << notNamed.size()
           << ", " << medianText(notNamed) << " |\n";
        json entry{{"read", all.size()},       {"median_error", at(all, 0.5)}, {"quartiles", {at(all, 0.25), at(all, 0.75)}},
                   {"within_tolerance", within}, {"named", named.size()},      {"not_named", notNamed.size()}};
        if (!named.empty()) entry["median_error_named"] = at(named, 0.5);
        if (!notNamed.empty()) entry["median_error_not_named"] = at(notNamed, 0.5);
        summary["first_readings"][p] = entry;
    }
}

void scoreCalibration(std::ostringstream& md, json& summary, const std::vector<Scored>& sets)
{
    // Nuisances: what the rig really was against what the diagnosis calibrated (not findings,
    // so not in the coverage above, but their intervals should mean what they say too).
    // Tension and bow position are 1 + the rig's relative error of the same quantity; the rod's
    // effusivity is the rig's value over the model's nominal, which the diagnosis scales.
    struct RigSide {
        const char* nuisance;
        const char* rigKey;
        double offset, divisor;
    };
    const RigSide nuisanceOfRig[]{{"tension_scale", "tension_error", 1.0, 1.0},
                                  {"beta_scale", "beta_error", 1.0, 1.0},
                                  {"rod_effusivity_scale", "rod_effusivity", 0.0, dsp::ThermalParams{}.rodEffusivity},
                                  {"scale_n_per_unit", "scale_n_per_unit", 0.0, 1.0}};
    // Each fitted nuisance's discrepancy: the spread of (value - truth) beyond its curvature
    // interval, as for the findings' parameters (what `--model-discrepancy NAME=SD` takes).
    md << "\n| calibrated nuisance | sets | median error | worst error | truth inside the 95 % interval | inside the curvature interval alone | "
          "discrepancy beyond the curvature (SD) |\n|---|---|---|---|---|---|---|\n";
    for (const auto& [name, rigKey, offset, divisor] : nuisanceOfRig) {
        std::vector<double> err;
        int inside = 0, insideCurvature = 0, withCurvature = 0, notWidened = 0, insideNotWidened = 0;
        double excessSum = 0.0;
        for (const auto& s : sets) {
            if (!s.calibration.count(name) || !s.rig.count(rigKey)) continue;
            const double t = offset + s.rig.at(rigKey) / divisor;
            const auto& c = s.calibration.at(name);
            err.push_back(std::abs(c[0] / t - 1.0));
            inside += t >= c[1] && t <= c[2];
            if (s.calibrationNotWidened.count(name)) {
                ++notWidened;
                insideNotWidened += t >= c[1] && t <= c[2];
            }
            if (const auto k = s.calibrationCurvature.find(name); k != s.calibrationCurvature.end()) {
                ++withCurvature;
                insideCurvature += t >= k->second[0] && t <= k->second[1];
                const double sd = (k->second[1] - k->second[0]) / (2.0 * 1.96);
                excessSum += (c[0] - t) * (c[0] - t) - sd * sd;
            }
        }
        if (err.empty()) continue;
        std::sort(err.begin(), err.end());
        md << "| " << name << " | " << err.size() << " | " << fmt("%.1f %%", 100.0 * err[err.size() / 2]) << " | " << fmt("%.1f %%", 100.0 * err.back())
           << " | ";
        // Studies diagnosed before the widening report the curvature interval as the 95 % one:
        // pooled with later ones, their coverage is told apart rather than mixed in.
        const int widened = static_cast<int>(err.size()) - notWidened;
        if (notWidened == 0)
            md << inside << " of " << err.size();
        else if (widened == 0)
            md << inside << " of " << err.size() << " (diagnosed before the widening: the curvature interval)";
        else
            md << inside - insideNotWidened << " of " << widened << " (and " << insideNotWidened << " of " << notWidened
               << " diagnosed before the widening, the curvature interval)";
        md << " | ";
        summary["calibration"][name] = {{"sets", err.size()}, {"median_error", err[err.size() / 2]}, {"worst_error", err.back()}, {"covered", inside}};
        if (notWidened > 0) summary["calibration"][name]["not_widened"] = {{"sets", notWidened}, {"covered", insideNotWidened}};
        if (withCurvature > 0) {
            const double sd = std::sqrt(std::max(0.0, excessSum / withCurvature));
            md << insideCurvature << " of " << withCurvature << " | " << fmt("%.3g", sd) << " |\n";
            summary["calibration"][name]["covered_by_curvature"] = insideCurvature;
            summary["calibration_discrepancy"][name] = sd;
        } else {
            md << "- | - |\n";
        }
    }
}

/// study.csv and the summary's per-set table; returns study.json's "sets".
json scorePerSet(const fs::path& dir, std::ostringstream& md, const std::vector<Scored>& sets)
{
    std::ofstream csv(dir / "study.csv");
    csv << "set,seed,hidden,found,exact,baseline_error,final_error,unexplained,over_floor";
    for (const auto& p : physicalParameterNames()) csv << "," << p << "_true," << p << "_found," << p << "_ci_low," << p << "_ci_high";
    const std::vector<std::string> rigCols{"noise_n", "inharmonicity", "bridge_z0y", "headroom", "tension_error", "beta_error", "mu_level", "rod_effusivity"};
    for (const auto& r : rigCols) csv << "," << r;
    csv << ",study\n";
    json perSet = json::array();
    md << "\n| set | hidden | found | held-out error baseline -> final |\n|---|---|---|---|\n";
    for (const auto& s : sets) {
        std::vector<std::string> h = s.hidden, f = s.found;
        std::sort(h.begin(), h.end());
        std::sort(f.begin(), f.end());
        csv << s.index << "," << s.seed << "," << effectsLabel(s.hidden) << "," << effectsLabel(s.found) << "," << (h == f) << "," << s.baseline << ","
            << s.final << "," << s.unexplained << "," << s.overFloor;
        for (const auto& p : physicalParameterNames()) {
            csv << "," << (s.truth.count(p) ? fmt("%.6g", s.truth.at(p)) : "");
            for (int k = 0; k < 3; ++k) csv << "," << (s.estimate.count(p) ? fmt("%.6g", s.estimate.at(p)[static_cast<std::size_t>(k)]) : "");
        }
        for (const auto& r : rigCols) csv << "," << (s.rig.count(r) ? fmt("%.6g", s.rig.at(r)) : "");
        csv << "," << s.study << "\n";
        std::string found = effectsLabel(s.found);
        for (const auto& [p, v] : s.estimate) found += " " + p + fmt("=%.3g", v[0]);
        std::string hidden = effectsLabel(s.hidden);
        for (const auto& [p, v] : s.truth) hidden += " " + p + fmt("=%.3g", v);
        md << "| " << (s.study.empty() ? "" : s.study + "/") << s.index << " | " << hidden << " | " << found
           << (s.unexplained ? (s.beyondUsual ? " (+ unexplained residual, more than usual)" : " (+ unexplained residual)") : "")
           << (s.standIns.empty() ? "" : " (possible stand-in, not named: " + effectsLabel(s.standIns) + ")") << " | "
           << fmt("%.3f", s.baseline) << fmt(" -> %.3f", s.final) << " |\n";
        perSet.push_back({{"set", s.index}, {"study", s.study}, {"seed", s.seed}, {"hidden", s.hidden}, {"found", s.found}, {"truth", s.truth},
                          {"baseline_error", s.baseline}, {"final_error", s.final}, {"unexplained", s.unexplained},
                          {"beyond_usual", s.beyondUsual}, {"stand_ins", s.standIns}, {"over_floor", s.overFloor}});
    }
    return perSet;
}
} // namespace

std::string scoreStudy(const fs::path& dir) { return scoreStudies(dir, {dir}); }

std::string scoreStudies(const fs::path& dir, const std::vector<fs::path>& studies)
{
    if (studies.empty()) throw LabError("study --pool: no study folders given");
    const bool pooled = studies.size() > 1 || (fs::exists(dir) && !fs::equivalent(dir, studies.front()));
    json plan = readPlan(studies.front());
    std::map<std::uint64_t, std::string> seenSeeds; // set seed -> where it was first met
    std::pair<std::string, std::string> unitsSeen; // the first set's units (Scored::units) and where it was met
    std::pair<std::string, std::string> splitSeen; // the first set's split method and where it was met
    std::pair<std::map<std::string, bool>, std::string> searchSeen; // the first recorded search switches and where they were met
    std::optional<std::pair<std::array<double, 5>, std::string>> weightsSeen; // the first set's metric weights and where they were met
    std::string sources;
    std::vector<Scored> sets;
    for (const fs::path& study : studies) {
        const std::vector<fs::path> folders = diagnosedSetFolders(study);
        if (pooled && fs::exists(dir) && fs::equivalent(dir, study))
            throw LabError(dir.string() + ": the pooled summary would overwrite the summary of a study it pools; write it to another folder");
        const json here = readPlan(study);
        if (populationOf(here) != populationOf(plan))
            throw LabError(study.string() + "/plan.json: " + populationOf(here).dump() + " where " + studies.front().string() + " has " +
                           populationOf(plan).dump() + ": studies scored together must share the grid, gesture, units, generator, fixed rig values, parameter ranges and stated uncertainties");
        const std::size_t before = sets.size();
        for (const fs::path& f : folders) {
            Scored s = readScored(f);
            if (pooled) s.study = study.filename().string();
            if (!s.units.empty()) {
                if (unitsSeen.first.empty()) unitsSeen = {s.units, f.string()};
                else if (s.units != unitsSeen.first)
                    throw LabError(f.string() + ": a set in " + s.units + " where " + unitsSeen.second + " is in " + unitsSeen.first +
                                   ": studies scored together must share the sensor's units");
            }
            // A false-positive rate or a detection rate is a property of the whole procedure, and the
            // split is part of it: two procedures scored together would describe neither.
            if (splitSeen.first.empty()) splitSeen = {s.splitMethod, f.string()};
            else if (s.splitMethod != splitSeen.first)
                throw LabError(f.string() + "/diagnosis/split.json: method \"" + s.splitMethod + "\" where " + splitSeen.second +
                               " has \"" + splitSeen.first + "\": studies scored together must split their strokes the same way");
            // So is the search; a diagnosis that did not record it is taken as it is.
            if (!s.search.empty()) {
                if (searchSeen.first.empty()) searchSeen = {s.search, f.string()};
                else if (s.search != searchSeen.first)
                    throw LabError(f.string() + "/diagnosis/diagnosis.json: search " + describeSearch(s.search) + " where " + searchSeen.second +
                                   " has " + describeSearch(searchSeen.first) + ": studies scored together must search the same way");
            }
            // And so is the metric: the same sets read with other weights are another experiment.
            if (!weightsSeen) weightsSeen = {{s.metricWeights, f.string()}};
            else if (s.metricWeights != weightsSeen->first)
                throw LabError(f.string() + "/diagnosis/diagnosis.json: metric weights " + describeMetricWeights(s.metricWeights) + " where " +
                               weightsSeen->second + " has " + describeMetricWeights(weightsSeen->first) + ": studies scored together must use one metric");
            // The same set counted twice (one study pooled twice, or two folders of one seed) would
            // pass for a larger study.
            if (const auto [at, fresh] = seenSeeds.emplace(s.seed, f.string()); !fresh && s.seed != 0)
                throw LabError(f.string() + ": set seed " + std::to_string(s.seed) + " was already scored from " + at->second);
            sets.push_back(std::move(s));
        }
        if (pooled)
            sources += (sources.empty() ? "" : ", ") + study.filename().string() +
                       (here.contains("seed") ? " (seed " + std::to_string(here["seed"].get<std::uint64_t>()) + ", " : " (") +
                       std::to_string(sets.size() - before) + " sets)";
    }
    if (sets.empty()) throw LabError(dir.string() + ": no diagnosed sets to score");
    fs::create_directories(dir);

    std::ostringstream md;
    int nNull = 0, nullFp = 0, exact = 0;
    for (const auto& s : sets) {
        std::vector<std::string> h = s.hidden, f = s.found;
        std::sort(h.begin(), h.end());
        std::sort(f.begin(), f.end());
        exact += h == f;
        if (s.hidden.empty()) {
            ++nNull;
            nullFp += !s.found.empty();
        }
    }
    json summary;
    md << "# Diagnosis study: " << sets.size() << " reference sets\n\n";
    if (pooled) md << "Scored together from " << studies.size() << " studies: " << sources << ".\n\n";
    // Sets of one grid diagnosed with one seed share one split: the rates below are then those
    // of a single draw of the strokes that fit, validate and test (study --split-per-set).
    std::set<std::uint64_t> splitSeeds;
    for (const auto& s : sets) splitSeeds.insert(s.splitSeed);
    md << "Strokes split into fit, validation and test: " << (splitSeen.first == "stratified" ? "stratified over the Guettler plane" : "shuffled")
       << " (split.json's method \"" << splitSeen.first << "\"), "
       << (splitSeeds.size() == 1 ? "one split for every set (seed " + std::to_string(*splitSeeds.begin()) + ")"
                                  : std::to_string(splitSeeds.size()) + " split seeds over " + std::to_string(sets.size()) + " sets")
       << ".\n";
    const auto unrecorded = std::count_if(sets.begin(), sets.end(), [](const Scored& s) { return s.search.empty(); });
    md << "Search: " << describeSearch(searchSeen.first)
       << (unrecorded > 0 && !searchSeen.first.empty() ? " (" + std::to_string(unrecorded) + " sets diagnosed before diagnosis.json recorded it)" : "")
       << ".\n";
    md << "Metric weights (first-slip time, force before it, jump, transient length, waveform): " << describeMetricWeights(weightsSeen->first) << ".\n";
    md << "Sets named exactly right (every hidden effect and nothing else): " << exact << " of " << sets.size() << ".\n";
    md << "Null sets naming any effect: " << nullFp << " of " << nNull << fmt(" (%.0f %%).\n", nNull ? 100.0 * nullFp / nNull : 0.0);
    // What the models on the list could not explain, and how far above the sets' own floors.
    int residuals = 0, nullResiduals = 0, beyondUsual = 0, nullBeyondUsual = 0, firmlyBeyond = 0, nullFirmlyBeyond = 0;
    std::vector<double> overFloor, nullOverFloor;
    for (const auto& s : sets) {
        residuals += s.unexplained;
        beyondUsual += s.beyondUsual;
        nullBeyondUsual += s.beyondUsual && s.hidden.empty();
        firmlyBeyond += s.firmlyBeyondUsual;
        nullFirmlyBeyond += s.firmlyBeyondUsual && s.hidden.empty();
        nullResiduals += s.unexplained && s.hidden.empty();
        overFloor.push_back(s.overFloor);
        if (s.hidden.empty() && s.overFloor > 0) nullOverFloor.push_back(s.overFloor);
    }
    std::sort(overFloor.begin(), overFloor.end());
    md << "Unexplained residual reported on " << residuals << " of " << sets.size() << " sets (" << nullResiduals << " of the " << nNull
       << " null sets); final error over the set's floor: median " << fmt("%.2f", overFloor[overFloor.size() / 2])
       << fmt(", from %.2f", overFloor.front()) << fmt(" to %.2f", overFloor.back()) << "; more than the usual residual on " << beyondUsual
       << " of " << sets.size() << " (" << nullBeyondUsual << " null), and more than " << fmt("%.2g", kFirmlyBeyondUsual)
       << " times it, where the report says the rig has something the model lacks, on " << firmlyBeyond << " (" << nullFirmlyBeyond
       << " null).\n";
    // The usual residual: what the model leaves where nothing is hidden, on this rig population.
    // The nulls' 95th percentile by nearest rank: a fresh null passes it about one time in
    // twenty. Under twenty nulls that rank is the largest, the value studies took before.
    if (!nullOverFloor.empty()) {
        std::sort(nullOverFloor.begin(), nullOverFloor.end());
        const std::size_t n = nullOverFloor.size();
        const double usual = usualResidualOf(nullOverFloor);
        const auto past = std::count_if(nullOverFloor.begin(), nullOverFloor.end(), [&](double r) { return r > usual; });
        if (n < kNullsForPercentile)
            md << fmt("The null sets' largest final error over floor, %.1f, is this rig population's usual residual (`rosin diagnose ", usual)
               << fmt("--usual-residual %.1f` takes it; with ", usual) << kNullsForPercentile << " or more nulls it is their 95th percentile).\n";
        else
            md << fmt("The null sets' final error over floor: median %.1f", nullOverFloor[n / 2]) << fmt(", 95th percentile %.1f", usual)
               << fmt(", largest %.1f", nullOverFloor.back()) << " (" << past << " of " << n << " nulls above the 95th percentile)"
               << fmt("; the 95th percentile is this rig population's usual residual (`rosin diagnose --usual-residual %.1f` takes it).\n", usual);
        summary["usual_residual_measured"] = usual;
        summary["null_over_floor"] = {{"nulls", n}, {"median", nullOverFloor[n / 2]}, {"percentile_95", usual}, {"largest", nullOverFloor.back()}};
    }
    // Stand-ins: what rule 6 kept from being named, and whether the set hid it (a miss) or not
    // (a wrong label it kept out).
    int standInSets = 0, standInsHidden = 0, standInsNotHidden = 0;
    for (const auto& s : sets) {
        standInSets += !s.standIns.empty();
        for (const auto& e : s.standIns) {
            if (has(s.hidden, e)) ++standInsHidden;
            else ++standInsNotHidden;
        }
    }
    if (standInSets > 0)
        md << "Possible stand-ins set aside beside a residual beyond the usual one (rule 6), not named: on " << standInSets << " of " << sets.size()
           << " sets; " << standInsNotHidden << " of them not hidden in their set (a wrong label kept out), " << standInsHidden << " hidden (a miss).\n";
    if (plan.is_object() && plan.value("generator", "reference") == "model-on-rig") {
        md << "Sets made by dsp/'s own model on the drawn rigs (`--generator model-on-rig`), not by the reference simulator: "
              "what the diagnosis does when its model is the rig's physics and only its nuisances and the recording differ. "
              "A ceiling and a consistency check, not a verdict on data the model did not make.\n";
        summary["generator"] = "model-on-rig";
    }
    if (plan.contains("rig")) {
        md << "Rig values fixed in every set instead of drawn: " << joined(plan["rig"], [](const json& v) { return fmt(" = %.3g", v.get<double>()); })
           << ".\n";
        summary["fixed_rig"] = plan["rig"];
    }
    if (plan.contains("param_ranges")) {
        md << "Hidden parameters drawn from narrowed ranges, not their whole priors: "
           << joined(plan["param_ranges"], [](const json& v) { return fmt(" %.3g", v[0].get<double>()) + fmt(" to %.3g", v[1].get<double>()); })
           << ". Detection rates here describe those sizes only, not the study population.\n";
        summary["param_ranges"] = plan["param_ranges"];
    }
    if (plan.contains("stated_uncertainty")) {
        md << "Rigs of a lab that states what it measured: "
           << joined(plan["stated_uncertainty"], [](const json& v) { return fmt(" +-%.3g %%", 100.0 * v.get<double>()); })
           << " in every manifest, each rig's error drawn within it (the generator's own spread: tension +-4 %, bow position +-3 %; "
              "q: the string's Q at f0 and 5 kHz stated within that of the rig's; torsion: its c_t / c and torsional Q likewise).\n";
        summary["stated_uncertainty"] = plan["stated_uncertainty"];
    }
    md << "\n";
    summary["unexplained_residual"] = {
        {"sets", residuals},
        {"null_sets", nullResiduals},
        {"beyond_usual", beyondUsual},
        {"null_beyond_usual", nullBeyondUsual},
        {"firmly_beyond_usual", firmlyBeyond},
        {"null_firmly_beyond_usual", nullFirmlyBeyond},
        {"median_over_floor", overFloor[overFloor.size() / 2]}};
    summary["stand_ins"] = {{"sets", standInSets}, {"not_hidden", standInsNotHidden}, {"hidden", standInsHidden}};
    summary["sets"] = sets.size();
    summary["split_method"] = splitSeen.first;
    summary["split_seeds"] = splitSeeds.size();
    if (!searchSeen.first.empty()) summary["search"] = searchSeen.first;
    summary["metric_weights"] = weightsSeen->first;
    summary["exact"] = exact;
    summary["null_sets"] = nNull;
    summary["null_false_positives"] = nullFp;
    md << "| effect | hidden in | named (detection) | named where not hidden (false positives) | minimum detectable size |\n|---|---|---|---|---|\n";
    for (const std::string& e : effectIds()) {
        int hid = 0, det = 0, other = 0, fp = 0;
        std::vector<std::pair<double, bool>> bySize;
        for (const auto& s : sets) {
            if (has(s.hidden, e)) {
                ++hid;
                det += has(s.found, e);
                const double size = effectSize(e, s.truth);
                if (std::isfinite(size)) bySize.push_back({size, has(s.found, e)});
            } else {
                ++other;
                fp += has(s.found, e);
            }
        }
        // Minimum detectable size: the smallest size above which at least 90 % are named.
        std::string mde = std::string("n/a");
        if (!bySize.empty()) {
            std::sort(bySize.begin(), bySize.end());
            mde = "not reached";
            for (std::size_t k = 0; k + 1 < bySize.size(); ++k) {
                int n = 0, named = 0;
                for (std::size_t j = k; j < bySize.size(); ++j) { ++n; named += bySize[j].second; }
                if (n >= 2 && named >= 0.9 * n && bySize[k].second) {
                    mde = fmt("%.3g ", bySize[k].first) + sizeName(e);
                    summary["minimum_detectable"][e] = bySize[k].first;
                    break;
                }
            }
        }
        md << "| " << e << " | " << hid << " | " << det << fmt(" (%.0f %%)", hid ? 100.0 * det / hid : 0.0) << " | " << fp
           << " of " << other << fmt(" (%.0f %%)", other ? 100.0 * fp / other : 0.0) << " | " << mde << " |\n";
        summary["detection"][e] = {{"hidden", hid}, {"named", det}, {"false_positive", fp}, {"not_hidden", other}};
    }
    scoreParameters(md, summary, sets);
    scoreFirstReadings(md, summary, sets);
    scoreCalibration(md, summary, sets);
    // Held-out error where nothing was hidden: what a good fit reaches on this rig population.
    std::vector<double> nullBase;
    for (const auto& s : sets)
        if (s.hidden.empty()) nullBase.push_back(s.final);
    if (!nullBase.empty()) {
        std::sort(nullBase.begin(), nullBase.end());
        md << fmt("Null sets' final held-out error: median %.3f", nullBase[nullBase.size() / 2]) << fmt(", worst %.3f.\n", nullBase.back());
    }
    const json perSet = scorePerSet(dir, md, sets);
    if (pooled) {
        json from = json::array();
        for (const fs::path& study : studies) from.push_back(study.filename().string());
        summary["pooled_from"] = from;
    }
    std::ofstream(dir / "study.json") << json{{"summary", summary}, {"sets", perSet}}.dump(1) << "\n";
    std::ofstream(dir / "summary.md") << md.str();
    drawFigure(dir / "study.png", sets);
    return md.str();
}

} // namespace rosin::lab
