// Reading a study's scored sets and drawing its figure (StudyScored.h).
#include "StudyScored.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "DiagnoseEngine.h"
#include "StudyPlan.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Plot.h"
#include "rosin/lab/Study.h"
#include "rosin/lab/SynthData.h"

namespace rosin::lab::scoring {
namespace fs = std::filesystem;
using nlohmann::json;

double effectSize(const std::string& effect, const std::map<std::string, double>& truth)
{
    if (effect == "hertzian_contact") return 1.0 - truth.at("load_exponent");
    if (effect == "rosin_temperature_shift") return std::abs(truth.at("shift_k"));
    if (effect == "torsional_compliance") return 1.0 / truth.at("zt_ratio");
    if (effect == "rate_dependence") return truth.at("p");
    return std::nan("");
}

const char* sizeName(const std::string& effect)
{
    if (effect == "hertzian_contact") return "1 - n";
    if (effect == "rosin_temperature_shift") return "|dT| (K)";
    if (effect == "torsional_compliance") return "Z0/Zt";
    if (effect == "rate_dependence") return "p";
    return "-";
}

const std::map<std::string, Tolerance>& tolerances()
{
    static const std::map<std::string, Tolerance> t{{"load_exponent", {0.05, false}}, {"shift_k", {3.0, false}}, {"zt_ratio", {0.2, true}},
                                                    {"r_A", {0.1, true}},           {"p", {0.1, false}},       {"h0", {0.1, false}}};
    return t;
}

double usualResidualOf(const std::vector<double>& sortedNullOverFloor)
{
    const std::size_t n = sortedNullOverFloor.size();
    const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n) - 1e-9));
    return sortedNullOverFloor[std::clamp<std::size_t>(rank, 1, n) - 1];
}

std::optional<bool> truthInInterval(const Scored& s, const std::string& p)
{
    if (!s.truth.count(p) || !s.estimate.count(p) || !has(s.found, effectOfParameter(p)) || s.unidentified.count(p)) return std::nullopt;
    const double t = s.truth.at(p);
    return t >= s.estimate.at(p)[1] && t <= s.estimate.at(p)[2];
}

std::vector<fs::path> diagnosedSetFolders(const fs::path& study)
{
    if (!fs::is_directory(study / "sets")) throw LabError(study.string() + ": no sets/ folder (run the study first)");
    std::vector<fs::path> folders;
    for (const auto& e : fs::directory_iterator(study / "sets"))
        if (fs::exists(e.path() / "diagnosis" / "diagnosis.json") && fs::exists(e.path() / "truth.json")) folders.push_back(e.path());
    std::sort(folders.begin(), folders.end());
    return folders;
}

Scored readScored(const fs::path& f)
{
    json t, d;
    std::ifstream(f / "truth.json") >> t;
    std::ifstream(f / "diagnosis" / "diagnosis.json") >> d;
    Scored s;
    s.index = std::stoi(f.filename().string());
    s.seed = t.value("seed", 0ull);
    s.hidden = t["effects"].get<std::vector<std::string>>();
    s.truth = t["params"].get<std::map<std::string, double>>();
    if (t.contains("rig")) s.rig = t["rig"].get<std::map<std::string, double>>();
    // The sensor's true scale is the inverse of the gain the generator applied.
    if (t.contains("gain_units_per_N") && t["gain_units_per_N"].get<double>() > 0.0)
        s.rig["scale_n_per_unit"] = 1.0 / t["gain_units_per_N"].get<double>();
    for (const auto& finding : d["findings"]) {
        const std::string e = finding["effect"].get<std::string>();
        if (e == "none") continue;
        s.found.push_back(e);
        for (const auto& [name, v] : finding["parameters"].items()) {
            s.estimate[name] = {v["value"].get<double>(), v["ci95"][0].get<double>(), v["ci95"][1].get<double>()};
            if (v.contains("identified") && !v["identified"].get<bool>()) s.unidentified.insert(name);
            if (v.contains("ci95_bootstrap")) {
                std::array<double, 2> w{v["ci95_bootstrap"][0].get<double>(), v["ci95_bootstrap"][1].get<double>()};
                if (v.contains("ci95_curvature"))
                    w = {std::min(w[0], v["ci95_curvature"][0].get<double>()), std::max(w[1], v["ci95_curvature"][1].get<double>())};
                s.withoutHalves[name] = w;
            }
            if (v.contains("ci95_statistical")) {
                const double x = v["value"].get<double>(), lo = v["ci95_statistical"][0].get<double>(), hi = v["ci95_statistical"][1].get<double>();
                s.statistical[name] = {lo, hi};
                const double down = v.contains("systematic_moves") ? v["systematic_moves"][0].get<double>() : 0.0;
                const double up = v.contains("systematic_moves") ? v["systematic_moves"][1].get<double>() : 0.0;
                const auto [rigLo, rigHi] = widenedInQuadrature(x, {lo, hi}, down, up);
                s.withRig[name] = {rigLo, rigHi};
            }
        }
    }
    // Every candidate is tried in round 1, so its row there reads each effect's parameter whether
    // or not the rules named it.
    if (d.contains("trials"))
        for (const auto& trial : d["trials"]) {
            if (trial.value("round", 0) != 1 || !trial.contains("parameters") || !trial.contains("effect")) continue;
            for (const std::string& p : physicalParameterNames())
                if (effectOfParameter(p) == trial["effect"].get<std::string>() && trial["parameters"].contains(p))
                    s.firstReading[p] = trial["parameters"][p].get<double>();
        }
    if (d.contains("calibration") && d["calibration"].contains("values"))
        for (const auto& [name, v] : d["calibration"]["values"].items())
            if (v["value"].is_number() && v["ci95"].size() == 2) {
                s.calibration[name] = {v["value"].get<double>(), v["ci95"][0].get<double>(), v["ci95"][1].get<double>()};
                if (v.contains("ci95_curvature") && v["ci95_curvature"].size() == 2) {
                    s.calibrationCurvature[name] = {v["ci95_curvature"][0].get<double>(), v["ci95_curvature"][1].get<double>()};
                } else if (diag::isNuisance(name)) {
                    // Fitted, but from a diagnosis before the widening: its interval is the curvature's.
                    s.calibrationCurvature[name] = {s.calibration[name][1], s.calibration[name][2]};
                    s.calibrationNotWidened.insert(name);
                }
            }
    if (const fs::path split = f / "diagnosis" / "split.json"; fs::exists(split)) {
        const SplitRecord r = readSplitRecord(split);
        s.splitMethod = r.method;
        s.splitSeed = r.seed;
    }
    s.search = searchRecordOf(d, f / "diagnosis" / "diagnosis.json");
    s.metricWeights = metricWeightsOf(d, f / "diagnosis" / "diagnosis.json");
    s.baseline = d["gain"]["baseline"].get<double>();
    s.final = d["gain"]["final"].get<double>();
    s.unexplained = d.contains("unexplained_residual") && !d["unexplained_residual"].is_null();
    if (d.contains("floor") && d["floor"].contains("final_over_floor")) s.overFloor = d["floor"]["final_over_floor"].get<double>();
    s.beyondUsual = s.unexplained && d["unexplained_residual"].value("beyond_usual", false);
    s.firmlyBeyondUsual = s.beyondUsual && isFirmlyBeyondUsual(s.overFloor, d["unexplained_residual"].value("usual_ratio", 0.0));
    if (s.unexplained && d["unexplained_residual"].contains("stand_ins"))
        for (const auto& standIn : d["unexplained_residual"]["stand_ins"]) s.standIns.push_back(standIn["effect"].get<std::string>());
    // The set's units as its diagnosis read them (older plan.json files of newton studies do not
    // say "units").
    if (d.contains("calibration") && d["calibration"].contains("values") && d["calibration"]["values"].contains("scale_n_per_unit")) {
        const std::string meaning = d["calibration"]["values"]["scale_n_per_unit"].value("meaning", "");
        s.units = meaning.rfind("sensor scale: the set is calibrated in N", 0) == 0 ? std::string("N") : std::string("V");
    }
    return s;
}

void drawFigure(const fs::path& file, const std::vector<Scored>& sets)
{
    Canvas canvas(1200, 500);
    const std::vector<std::string>& ids = effectIds();
    // Left: detection and false-positive rate per effect, and the null sets' false positives.
    Axes left(canvas, 70, 40, 520, 330, -0.5, static_cast<double>(ids.size()) + 0.5, 0.0, 1.05);
    left.frame("detection (blue) and false positives (red) per effect", "", "fraction of sets");
    for (std::size_t k = 0; k <= ids.size(); ++k) {
        double hid = 0, det = 0, not_ = 0, fp = 0;
        for (const auto& s : sets) {
            if (k == ids.size()) {
                if (s.hidden.empty()) { ++not_; fp += !s.found.empty(); }
                continue;
            }
            if (has(s.hidden, ids[k])) { ++hid; det += has(s.found, ids[k]); }
            else { ++not_; fp += has(s.found, ids[k]); }
        }
        const double x = static_cast<double>(k);
        if (hid > 0) left.rect(x - 0.35, 0.0, x - 0.02, det / hid, colors::blue);
        if (not_ > 0) left.rect(x + 0.02, 0.0, x + 0.35, std::max(0.005, fp / not_), colors::red);
        const std::string label = k == ids.size() ? "null sets" : ids[k].substr(0, ids[k].find('_'));
        canvas.text(left.px(x), left.py(0.0) + 30, label, 11, colors::black, 0.5, 0.0);
    }
    left.hline(0.9, colors::grey, 1.0, true);
    left.hline(0.05, colors::grey, 1.0, true);
    // Right: detection against effect size, each effect's size scaled to its prior's top.
    Axes right(canvas, 680, 40, 480, 330, 0.0, 1.05, -0.15, 1.15);
    right.frame("named (1) or missed (0) against effect size", "size / largest size in the prior", "named");
    const std::vector<std::pair<std::string, Color>> kinds{{"hertzian_contact", colors::blue}, {"rosin_temperature_shift", colors::red},
                                                           {"torsional_compliance", colors::green}, {"rate_dependence", colors::orange}};
    const std::map<std::string, double> top{{"hertzian_contact", 0.45}, {"rosin_temperature_shift", 20.0}, {"torsional_compliance", 1.0 / 1.2},
                                            {"rate_dependence", 0.6}};
    std::vector<std::pair<std::string, Color>> legend;
    for (const auto& [effect, color] : kinds) {
        std::vector<double> x, y;
        for (const auto& s : sets)
            if (has(s.hidden, effect)) {
                x.push_back(effectSize(effect, s.truth) / top.at(effect));
                y.push_back((has(s.found, effect) ? 1.0 : 0.0) + 0.03 * (static_cast<double>(s.index % 5) - 2.0));
            }
        right.points(x, y, color, 4.0);
        legend.push_back({effect.substr(0, effect.find('_')) + " (" + sizeName(effect) + ")", color});
    }
    right.legendBelow(legend);
    canvas.save(file);
}

} // namespace rosin::lab::scoring
