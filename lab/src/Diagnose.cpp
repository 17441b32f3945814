#include "rosin/lab/Diagnose.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <random>
#include <set>

#include "DiagnoseEngine.h"
#include "rosin/lab/Error.h"

namespace rosin::lab {

namespace {
bool has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }
} // namespace

std::string EffectModel::name() const
{
    std::string n = has(effects, "rate_dependence") ? "enhanced" : has(effects, "thermal_memory") ? "thermal" : "friction_curve";
    if (has(effects, "rosin_temperature_shift")) n += "+shift";
    if (has(effects, "hertzian_contact")) n += "+hertz";
    if (has(effects, "torsional_compliance")) n += "+torsion";
    return n;
}

namespace {
/// The one table of physical parameters and the effect each belongs to.
const std::vector<std::pair<std::string, std::string>>& physicalParameters()
{
    static const std::vector<std::pair<std::string, std::string>> table{
        {"r_A", "thermal_memory"},         {"h0", "rate_dependence"},
        {"p", "rate_dependence"},          {"load_exponent", "hertzian_contact"},
        {"shift_k", "rosin_temperature_shift"}, {"zt_ratio", "torsional_compliance"}};
    return table;
}
} // namespace

std::string effectOfParameter(const std::string& parameter)
{
    for (const auto& [name, effect] : physicalParameters())
        if (name == parameter) return effect;
    return "calibration";
}

const std::vector<std::string>& physicalParameterNames()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const auto& entry : physicalParameters()) n.push_back(entry.first);
        return n;
    }();
    return names;
}

using namespace diag;

namespace {
/// The model without one effect and its parameters (thermal memory takes the nuisances that
/// matter only to a thermal model with it).
EffectModel removed(EffectModel m, const std::string& effect)
{
    auto thermalOnly = [](const std::string& name) {
        return std::any_of(nuisances().begin(), nuisances().end(), [&](const Nuisance& k) { return k.thermalOnly && k.name == name; });
    };
    m.effects.erase(std::remove(m.effects.begin(), m.effects.end(), effect), m.effects.end());
    for (auto it = m.params.begin(); it != m.params.end();) {
        const bool its = effectOfParameter(it->first) == effect || (effect == "thermal_memory" && thermalOnly(it->first));
        it = its ? m.params.erase(it) : std::next(it);
    }
    return m;
}
} // namespace

Diagnosis diagnose(const MeasurementSet& set, const DiagnoseOptions& o, const std::function<void(const std::string&, double)>& progress)
{
    const auto start = std::chrono::steady_clock::now();
    auto say = [&](const std::string& what, double x) {
        if (progress) progress(what, x);
    };
    checkMetricWeights(o.metricWeights, "metric weights");
    Diagnosis d;
    d.setName = set.folder.string();
    d.warnings = set.warnings;
    // The string: the manifest, completed from the cello D.
    const StringInfo info = stringInfoOf(set);
    if (!set.tension) d.warnings.push_back("rig.string.tension_n missing: assumed " + std::to_string(info.tension) + " N (cello D)");
    if (!set.length) d.warnings.push_back("rig.string.length_m missing: assumed " + std::to_string(info.length) + " m (cello D)");

    // 1. Clean every recording, find its gesture start, convert the set to newtons.
    say("preparing", 0.0);
    std::vector<Prepared> strokes = prepareStrokes(set, info, o, d);
    const std::size_t n = strokes.size();

    // 2. Fit, validation and test strokes, drawn from the seed before anything is fitted.
    std::vector<StrokePlace> places(n);
    for (std::size_t i = 0; i < n; ++i) places[i] = {set.strokes[i].gesture, strokes[i].gesture.drive(), strokes[i].gesture.force};
    const StrokeSplit split = splitStrokes(places, o, set.folder.string());
    const std::vector<std::size_t>&testSet = split.test, &valSet = split.validation, &fitSet = split.fit;
    for (auto i : fitSet) d.fitIds.push_back(strokes[i].id);
    for (auto i : valSet) d.validationIds.push_back(strokes[i].id);
    for (auto i : testSet) d.heldoutIds.push_back(strokes[i].id);
    d.nFit = fitSet.size();
    d.nValidation = valSet.size();
    d.nHeldout = testSet.size();

    // 3. Calibration before causes: the rig's steady sliding, then tension and bow position.
    std::optional<dsp::SteadyCurve> steady;
    if (set.steady.size() >= 5) {
        const SteadyFitResult sf = fitSteadySliding(set.steady);
        steady = sf.curve;
        d.calibration.push_back({"mu_static", "static friction of the rig's rosin, from steady_sliding.csv (SW00 shape, 4 factors)", sf.muStatic,
                                 sf.muStatic - 1.96 * sf.muStaticSd, sf.muStatic + 1.96 * sf.muStaticSd});
        if (sf.rms > 0.05)
            d.warnings.push_back("steady_sliding.csv departs from the SW00 shape by " + std::to_string(100 * sf.rms) + " % rms");
    } else {
        d.warnings.push_back(set.steady.empty() ? "no steady_sliding.csv: the reference SW00 curve is assumed for this rosin"
                                                : "steady_sliding.csv has fewer than 5 rows: the reference SW00 curve is assumed");
    }
    Engine engine(strokes, info, o.simRate, steady, set.units == "V", o.metricWeights);
    EffectModel current;
    {
        // Which string constants the model plays (Engine::config decides): what the lab measured,
        // or the model's own. Not fitted, so each interval is its value.
        const dsp::StringParams played = engine.config(current).string;
        const auto given = [&](const char* name, const std::string& meaning, double value) {
            d.calibration.push_back({name, meaning, value, value, value});
        };
        const std::string silent = "the model's own: the manifest does not state it";
        const std::string losses = info.statesQ() ? "as the manifest states it (rig.string.q_f0, q_5khz)" : silent;
        given("string_q_f0", "the string's transverse Q at f0, " + losses, played.qLow);
        given("string_q_5khz", "the string's transverse Q at 5 kHz, " + losses, played.qHigh);
        const std::string torsional = info.statesTorsion() ? "as the manifest states it (rig.string.torsion_speed_ratio, q_torsion)" : silent;
        given("torsion_speed_ratio", "the string's torsional wave speed over its transverse one, played where a roll is tried, " + torsional,
              played.torsionSpeedRatio);
        given("torsion_q", "the string's torsional Q, played where a roll is tried, " + torsional, played.qTorsion);
        if (info.statesTorsion()) d.statedTorsionSpeedRatio = played.torsionSpeedRatio;
    }
    if (o.fitNuisances) {
        say("calibration: tension and bow position", 0.0);
        Candidate cal = candidate("calibration", {"tension_scale", "beta_scale"}, {1.0, 1.0});
        cal.adds.clear(); // calibration is not an effect
        const auto x = diag::fit(engine, current, cal, fitSet, cal.start, o.maxEvaluations, 0.2, nullptr, true, o.secondStart);
        current = apply(current, cal, x);
    }
    d.baseline = current;
    const std::vector<ErrorParts> baselineTest = engine.errors(current, testSet);
    std::vector<ErrorParts> currentVal = engine.errors(current, valSet), currentTest = baselineTest;
    const auto prior = [&](const char* name, const std::optional<double>& stated) {
        char text[32];
        std::snprintf(text, sizeof text, "+-%.3g %%", 100.0 * (boundsOf(name, info).second - 1.0));
        return std::string(text) + (stated ? " (the manifest's stated prior)" : "");
    };
    d.rules = {"Calibration first: the steady-sliding curve from steady_sliding.csv, the string's transverse Q and its torsional c_t / c and Q_t from the manifest where it states them (else the model's), tension within " + prior("tension_scale", info.tensionPrior) +
                   " and bow position within " + prior("beta_scale", info.betaPrior) +
                   " of the manifest, fitted on the fit strokes with the baseline model; effects are fitted on top of them. Once thermal memory "
               "is tried, the bow side's thermal effusivity (0.65-1.35 x 450) is a nuisance too.",
               "An effect is fitted on the fit strokes and named only when (1) its validation-error fall is the largest of the round "
               "with a 95 % paired-bootstrap interval above 0, (2) the fall is at least " + std::to_string(static_cast<int>(std::lround(100 * o.namingThreshold))) +
                   " % of the validation error (threshold calibrated on null sets), and a candidate that brings thermal memory along "
                   "(rate dependence, a rosin shift) also falls below thermal memory alone by that share, and a rate dependence or a rosin shift also below the other of the two, "
                   "fitted in the same round, by that share (else the data do not tell them apart)" + shiftMarginText(o) + "; a rosin shift fitted beside a named rate dependence "
                   "must not have the other sign than round 1's shift candidate when that one was 10 K or more (else it stands in for the rate law's form), (3) it also lowers the error of the test strokes, "
                   "(4) the 95 % interval of its parameter excludes the no-effect value (exponent 1, shift 0 K, "
                   "Z_t/Z_0 >= 7.5, speed exponent <= 0.03), both the bootstrap refits' interval and that interval widened in quadrature "
                   "by the model discrepancy the studies measured (the one the report prints" + nameableEdgesText(o) + "), and (5) searched afresh on the low- and on the high-drive half of the fit strokes "
                   "(bow acceleration; v0/tv for exp_speed and bow speed for exp_force strokes, each gesture split at its own median) it keeps away from the no-effect value with consistent values. Every candidate is fitted with the nuisances and the "
                   "parameters of effects already named free beside its own. A parameter fitted within 1 % of either end of its search range "
                   "(r_A 0.5-2, p 0.1-0.8, load exponent 0.4-1.1, shift -30 to +30 K, Z_t/Z_0 0.7-8) is a stand-in and is not named; "
                   "h0, which no data fix, is asked neither this nor (5).",
               "After each new finding all parameters are refitted together, and every finding, the new one included, must still hold rule 4's "
               "interval clear of its no-effect value where the refit left it; every earlier one must also still earn its place: the model is refitted without it, and an effect whose "
               "absence raises the validation error by less than the naming threshold is dropped. A dropped effect is not tried again. A new "
               "finding that fails rule 4 there, or once refitted without an earlier finding it displaced, is not named: the round is undone, "
               "the earlier findings stand as they were, and the new effect is not tried again.",
               "The reported gain compares the calibrated baseline and the final model on the test strokes only."};
    if (o.tryPairs)
        d.rules.push_back("When a round names nothing, a Hertzian contact and a rolling string still open are tried together as one candidate "
                          "(one r_A), from the grid and from where their own fits that round left them; the pair names both only when its "
                          "validation error is also below each of the two alone, fitted in that round, by the naming threshold, and rules 2-5 "
                          "hold for all its parameters.");
    if (o.usualResidualRatio > 0.0) d.rules.push_back(standInRuleText(o.usualResidualRatio));

    // 4. From the calibrated baseline, add effects one round at a time.
    int round = 0;
    std::set<std::string> dropped; // effects named, then dropped beside a later finding
    while (true) {
        ++round;
        std::vector<Candidate> cands;
        for (const Candidate& c : candidates(current))
            if (!dropped.count(c.effect)) cands.push_back(withNuisances(c, current));
        if (cands.empty()) break;
        struct Tried {
            Candidate c;
            std::vector<double> x;
            std::vector<ErrorParts> val;
            std::array<double, 3> gain;
            std::size_t trial;
        };
        std::vector<Tried> tried;
        const double valBefore = mean(currentVal);
        // The candidate's validation errors, its paired gain and its trial row with rule 1's verdict.
        auto evaluate = [&](const Candidate& c, std::vector<double> x, double fitError, std::uint64_t bootstrapStream) {
            Tried t{c, std::move(x), {}, {}, d.trials.size()};
            t.val = engine.errors(apply(current, c, t.x), valSet);
            t.gain = pairedGain(currentVal, t.val, o.bootstrap, o.seed + bootstrapStream);
            Trial trial;
            trial.round = round;
            trial.effect = c.effect;
            for (std::size_t j = 0; j < c.names.size(); ++j) trial.parameters[c.names[j]] = t.x[j];
            trial.fitError = fitError;
            trial.gain = t.gain[0];
            trial.gainLow = t.gain[1];
            trial.gainHigh = t.gain[2];
            trial.relativeGain = valBefore > 0 ? t.gain[0] / valBefore : 0.0;
            trial.verdict = "not the largest fall";
            if (!(t.gain[1] > 0.0)) trial.verdict = "validation fall not significant";
            else if (trial.relativeGain < o.namingThreshold) trial.verdict = "validation fall below the threshold";
            d.trials.push_back(trial);
            return t;
        };
        // A further search of c on `base` from `from` (no grid); its end replaces x when it fits the fit strokes better.
        auto searchAgain = [&](const EffectModel& base, const Candidate& c, std::vector<double> from, int evaluations, double step,
                               std::vector<double>& x, double& fitError) {
            double againError = 0.0;
            std::vector<double> again = diag::fit(engine, base, c, fitSet, std::move(from), evaluations, step, &againError, false);
            if (againError < fitError) x = std::move(again), fitError = againError;
        };
        // A candidate's whole search on `base`: the grid and COBYLA, then the further searches below.
        // The same routine refits this round's winner without an earlier finding, so the two models
        // compared there were searched equally hard.
        auto search = [&](const EffectModel& base, const Candidate& c, double& fitError) {
            std::vector<double> x = diag::fit(engine, base, c, fitSet, c.start, o.maxEvaluations, 0.2, &fitError, true, o.secondStart);
            // A rolling string changes the scale of every force the ramps read, so the parameters
            // named without it sit far from where they belong beside it, and the grid from there
            // misses the valley: search also from where round 1 left the torsion on the baseline,
            // with twice the evaluations (COBYLA spends one per parameter, seven or more here,
            // before its first step).
            if (const auto from = roundOneStart(d.trials, c); round > 1 && from) searchAgain(base, c, *from, 2 * o.maxEvaluations, 0.2, x, fitError);
            // A later round's contact fits r_A and the nuisances beside its exponent, and COBYLA's
            // first simplex can stay where the earlier finding left them (seed 2057, set 6: fit
            // error 0.124 at exponent 0.78, where the contact-and-roll pair's search reached 0.104
            // at 0.68 with no roll): search again from where it ended, with a wider first step.
            if (o.restartContact && round > 1 && c.effect == "hertzian_contact") searchAgain(base, c, x, o.maxEvaluations, 0.35, x, fitError);
            return x;
        };
        auto passesRuleOne = [&](const Tried& t) { return t.gain[1] > 0.0 && d.trials[t.trial].relativeGain >= o.namingThreshold; };
        for (std::size_t k = 0; k < cands.size(); ++k) {
            say("round " + std::to_string(round) + ": " + cands[k].effect, static_cast<double>(k) / static_cast<double>(cands.size()));
            double fitError = 0;
            std::vector<double> x = search(current, cands[k], fitError);
            tried.push_back(evaluate(cands[k], std::move(x), fitError, static_cast<std::uint64_t>(round * 100 + static_cast<int>(k))));
        }
        std::sort(tried.begin(), tried.end(), [](const Tried& a, const Tried& b) { return a.gain[0] > b.gain[0]; });
        const Tried* best = nullptr;
        std::map<std::string, double> halfWidth;
        std::map<std::string, std::array<double, 2>> halvesOffset; // the named candidate's halves, from its value
        std::map<std::string, double> roundValidation;               // every candidate's validation error this round
        for (const Tried& t : tried) roundValidation[t.c.effect] = mean(t.val);
        // Rules 2-5 for a candidate whose validation fall passed rule 1; the verdict goes on its trial.
        auto judge = [&](const Tried& t) {
            Trial& trial = d.trials[t.trial];
            std::map<std::string, double> fitted;
            for (std::size_t j = 0; j < t.c.names.size(); ++j) fitted[t.c.names[j]] = t.x[j];
            if (atNull(t.c.effect, fitted)) { trial.verdict = "fitted at the effect's own absence"; return false; }
            if (pinnedAtEdge(t.c, t.x)) { trial.verdict = "fitted at the edge of its search range (a stand-in, not a measurement)"; return false; }
            // Rule 2's comparisons with the round's other candidates (docs/diagnosis.md).
            if (const std::string failed = standInVerdict(trial, t.c, roundValidation, current.effects, d.trials, o.namingThreshold, o.shiftOverRateMargin); !failed.empty()) {
                trial.verdict = failed;
                return false;
            }
            // (3) the test strokes
            const EffectModel cand = apply(current, t.c, t.x);
            trial.testGain = mean(currentTest) - mean(engine.errors(cand, testSet));
            if (!(trial.testGain > 0.0)) { trial.verdict = "no gain on the test strokes"; return false; }
            // (4) intervals from refits on bootstrap resamples, each from a fresh start
            say("round " + std::to_string(round) + ": uncertainty of " + t.c.effect, 0.0);
            std::vector<std::vector<double>> refits;
            std::mt19937_64 prng(o.seed * 31ull + static_cast<std::uint64_t>(round));
            std::uniform_int_distribution<std::size_t> pick(0, fitSet.size() - 1);
            std::uniform_real_distribution<double> jump(-0.15, 0.15);
            // the estimate's error on a resample, from its per-stroke errors on the fit strokes
            const std::vector<ErrorParts> estimateOnFit = engine.errors(cand, fitSet);
            for (int b = 0; b < o.parameterBootstrap; ++b) {
                std::vector<std::size_t> resampled;
                std::vector<ErrorParts> estimateOnResample;
                for (std::size_t k = 0; k < fitSet.size(); ++k) {
                    const std::size_t at = pick(prng);
                    resampled.push_back(fitSet[at]);
                    estimateOnResample.push_back(estimateOnFit[at]);
                }
                std::vector<double> freshStart = t.x;
                for (std::size_t k = 0; k < freshStart.size(); ++k)
                    freshStart[k] = std::clamp(freshStart[k] + jump(prng) * (t.c.hi[k] - t.c.lo[k]), t.c.lo[k], t.c.hi[k]);
                const int evaluations = std::max(8, o.maxEvaluations / 2);
                double refitError = 0.0;
                std::vector<double> refit = diag::fit(engine, current, t.c, resampled, freshStart, evaluations, 0.1, &refitError, false);
                // A refit that ends worse on its own resample than the estimate has not converged
                // (a few COBYLA steps for five or more parameters): search again from the estimate.
                if (mean(estimateOnResample) < refitError)
                    refit = diag::fit(engine, current, t.c, resampled, t.x, evaluations, 0.05, nullptr, false);
                refits.push_back(std::move(refit));
            }
            halfWidth.clear();
            bool atNullInterval = false, atNullWithDiscrepancy = false;
            // Rules (4) and (5) judge the candidate's own parameters; those of earlier findings and
            // the nuisances were free in the refits but were judged when they entered.
            for (std::size_t k = 0; k < t.c.scanned; ++k) {
                double m = 0, v = 0;
                for (const auto& r : refits) m += r[k];
                m /= static_cast<double>(refits.size());
                for (const auto& r : refits) v += (r[k] - m) * (r[k] - m);
                const double hw = refits.size() > 1 ? 1.96 * std::sqrt(v / static_cast<double>(refits.size() - 1)) : 0.0;
                halfWidth[t.c.names[k]] = hw;
                atNullInterval = atNullInterval || intervalAtNull(t.c.names[k], t.x[k] - hw, t.x[k] + hw);
                // The interval the report will print carries the model's own error on rigs it does
                // not describe; a finding whose printed interval reaches no effect is not proved,
                // so it is not named (the studies' spurious shifts all had one: docs/diagnosis.md).
                const double wide = namingHalfWidth(o, t.c.names[k], t.x[k], hw);
                atNullWithDiscrepancy = atNullWithDiscrepancy || intervalAtNull(t.c.names[k], t.x[k] - wide, t.x[k] + wide);
            }
            if (atNullInterval) { trial.verdict = "interval reaches the no-effect value"; return false; }
            if (atNullWithDiscrepancy) { trial.verdict = "interval reaches the no-effect value once the model discrepancy is counted"; return false; }
            // (5) the two drive halves of the fit strokes
            const std::vector<std::vector<double>> halves = diag::driveHalves(engine, current, t.c, fitSet, strokes, t.x, o.maxEvaluations);
            if (!halvesConsistent(t.c, halves[0], halves[1], halfWidth)) {
                trial.verdict = "not consistent on the two drive halves (bow acceleration, or the gesture's own drive)";
                return false;
            }
            trial.verdict = "named";
            for (std::size_t k = 0; k < t.c.scanned; ++k) halvesOffset[t.c.names[k]] = {halves[0][k] - t.x[k], halves[1][k] - t.x[k]};
            return true;
        };
        for (const Tried& t : tried)
            if (passesRuleOne(t) && judge(t)) {
                best = &t;
                break;
            }
        // Two effects that each fit worse alone than together (a roll beside a contact) are out of
        // reach of rounds of single effects: when this round names nothing, each open pair is tried
        // as one candidate, from the grid and from where its two effects' own fits left them.
        std::vector<Tried> pairs;
        pairs.reserve(pairedEffects().size());
        if (o.tryPairs && !best)
            for (const auto& [a, b] : pairedEffects()) {
                const auto raw = offered(current, a + "+" + b);
                auto single = [&](const std::string& effect) {
                    return std::find_if(tried.begin(), tried.end(), [&](const Tried& t) { return t.c.effect == effect; });
                };
                const auto alone = single(a), other = single(b);
                if (!raw || alone == tried.end() || other == tried.end()) continue;
                const Candidate c = withNuisances(*raw, current);
                say("round " + std::to_string(round) + ": " + c.effect, 0.0);
                double fitError = 0.0;
                std::vector<double> x = diag::fit(engine, current, c, fitSet, c.start, 2 * o.maxEvaluations, 0.2, &fitError, true, o.secondStart);
                searchAgain(current, c, startFromParts(c, alone->c, alone->x, other->c, other->x), 2 * o.maxEvaluations, 0.2, x, fitError);
                pairs.push_back(evaluate(c, std::move(x), fitError, static_cast<std::uint64_t>(round * 100 + 50)));
                const Tried& t = pairs.back();
                Trial& trial = d.trials[t.trial];
                const double overA = relativeFall(mean(alone->val), mean(t.val)), overB = relativeFall(mean(other->val), mean(t.val));
                if (!passesRuleOne(t)) continue;
                if (std::min(overA, overB) < o.namingThreshold) {
                    trial.verdict = "no better than " + (overA < overB ? a : b) + " alone";
                    continue;
                }
                if (judge(t)) {
                    best = &t;
                    break;
                }
            }
        if (!best) break;
        d.trials[best->trial].kept = true;
        const double before = mean(currentVal);
        const std::vector<ErrorParts> stepBefore = currentVal;
        const EffectModel from = current;
        current = apply(current, best->c, best->x);
        currentVal = best->val;
        // This round's findings, at the parameters of `model`, with the intervals rule 4 gave them.
        auto newFindings = [&](const EffectModel& model) {
            std::vector<Finding> found;
            for (const auto& effect : best->c.adds) {
                if (has(from.effects, effect)) continue;
                Finding finding;
                finding.effect = effect;
                for (const auto& name : best->c.names)
                    if (effectOfParameter(name) == effect) {
                        const double v = model.params.at(name);
                        finding.parameters[name] = {v, v - halfWidth[name], v + halfWidth[name]};
                        // the halves keep their offsets from the value, which the joint refit moved
                        if (const auto h = halvesOffset.find(name); h != halvesOffset.end()) finding.halves[name] = {v + h->second[0], v + h->second[1]};
                    }
                found.push_back(std::move(finding));
            }
            return found;
        };
        // A parameter fitted before a later effect entered may have stood in for it: refit all
        // parameters, nuisances included, and keep the refit unless it does worse on validation.
        if (current.params.size() > 1) {
            say("round " + std::to_string(round) + ": joint refit", 0.0);
            Candidate all;
            all.effect = "joint";
            for (const auto& [name, value] : current.params) {
                const auto [lo, hi] = boundsOf(name, info);
                all.names.push_back(name);
                all.lo.push_back(lo);
                all.hi.push_back(hi);
                all.start.push_back(value);
            }
            const auto x = diag::fit(engine, current, all, fitSet, all.start, o.maxEvaluations, 0.05, nullptr, false);
            const EffectModel refit = apply(current, all, x);
            const auto refitVal = engine.errors(refit, valSet);
            if (mean(refitVal) <= mean(currentVal)) {
                current = refit;
                currentVal = refitVal;
            }
        }
        // Rule 4 holds where the joint refit left this round's own finding, as it must for the
        // earlier ones below: a refit that moves it to where its interval reaches no effect says the
        // data do not prove it (seed 2079, set 6: a shift judged at 17.4 K, refitted to 15.5 K, under
        // the 15.7 K that rule 4 can name). The round names nothing, and the effect is not tried again.
        const diag::RoundStart atRoundStart = diag::roundStart(d, dropped);
        auto ownFindingAtNull = [&] {
            const auto found = newFindings(current);
            return std::any_of(found.begin(), found.end(), [&](const Finding& f) { return movedToNull(f, current.params, o); });
        };
        // the report and the model go back to where the round began
        auto undoThisRound = [&](const std::string& verdict) {
            diag::undoRound(d, dropped, atRoundStart, best->trial, membersOf(best->c.effect), verdict);
            current = from;
            currentVal = stepBefore;
        };
        if (ownFindingAtNull()) {
            undoThisRound("passed rules 1-5, then the joint refit moved its parameter to where its interval reaches the no-effect value");
            continue;
        }
        // An effect named earlier may have stood in for the one named now (a rosin shift for a
        // contact not yet tried): each earlier finding must still earn its place, by the naming
        // threshold on validation, against the model refitted without it. The weakest goes first,
        // and a dropped effect is not tried again.
        EffectModel earlier = from; // the model before this round, less what has been dropped since
        while (true) {
            struct Without {
                std::string effect;
                EffectModel model;
                std::vector<ErrorParts> val;
                double share = 0;
            };
            std::vector<Without> tested;
            for (const auto& effect : earlier.effects) {
                if (!has(current.effects, effect)) continue;
                if (effect == "thermal_memory" && std::any_of(current.effects.begin(), current.effects.end(), needsThermal)) continue;
                say("round " + std::to_string(round) + ": without " + effect, 0.0);
                // Searched as hard as the model it is compared with: this round's winner is fitted
                // again on the model that never named the earlier effect, by the search that found
                // it (a joint refit from where the earlier effect left the other parameters stays
                // there). The winner is new this round, so the model without the earlier effect
                // offers it. A pair's further start from its two parts is not repeated: its parts
                // were fitted beside the earlier effect.
                const EffectModel withoutEarlier = removed(earlier, effect);
                const auto winner = offered(withoutEarlier, best->c.effect);
                if (!winner) continue;
                const Candidate c = withNuisances(*winner, withoutEarlier);
                double fitError = 0.0;
                Without w{effect, apply(withoutEarlier, c, search(withoutEarlier, c, fitError)), {}, 0.0};
                w.val = engine.errors(w.model, valSet);
                w.share = relativeFall(mean(w.val), mean(currentVal));
                tested.push_back(std::move(w));
            }
            // An earlier finding whose parameter the joint refit moved to where its interval (the
            // half-width it was named with, and the model discrepancy) reaches the no-effect value
            // fails rule 4 now.
            const auto stale = std::find_if(tested.begin(), tested.end(), [&](const Without& w) {
                return std::any_of(d.findings.begin(), d.findings.end(),
                                   [&](const Finding& f) { return f.effect == w.effect && movedToNull(f, current.params, o); });
            });
            const auto weakest = stale != tested.end() ? stale
                                                       : std::min_element(tested.begin(), tested.end(), [](const Without& a, const Without& b) { return a.share < b.share; });
            auto record = [&](const Without& w, const std::string& verdict) {
                Trial t;
                t.round = round;
                t.effect = w.effect;
                for (const auto& [name, value] : current.params)
                    if (effectOfParameter(name) == w.effect) t.parameters[name] = value;
                t.gain = mean(w.val) - mean(currentVal);
                t.relativeGain = w.share;
                t.verdict = verdict;
                d.trials.push_back(t);
            };
            if (weakest == tested.end() || (stale == tested.end() && weakest->share >= o.namingThreshold)) {
                for (const Without& w : tested) record(w, "kept beside " + best->c.effect + ": without it the validation error rises by the share shown");
                break;
            }
            record(*weakest, stale != tested.end() ? "dropped: beside " + best->c.effect + " its parameter moved to where its interval reaches the no-effect value"
                                                   : "dropped: beside " + best->c.effect + " it no longer lowers the validation error by the threshold");
            d.findings.erase(std::remove_if(d.findings.begin(), d.findings.end(), [&](const Finding& f) { return f.effect == weakest->effect; }),
                             d.findings.end());
            dropped.insert(weakest->effect);
            earlier = removed(earlier, weakest->effect);
            current = weakest->model;
            currentVal = weakest->val;
        }
        // Refitted without an earlier finding it displaced, this round's own finding is asked rule 4
        // again: if it now reaches no effect, neither change is proved and the round is undone.
        if (d.findings.size() < atRoundStart.findings.size() && ownFindingAtNull()) {
            undoThisRound("passed rules 1-5, then, refitted without the earlier finding it displaced, its parameter moved to where its "
                          "interval reaches the no-effect value");
            continue;
        }
        // Earlier findings report where their parameters are now (they moved with this round's fit).
        for (auto& f : d.findings)
            for (auto& [name, v] : f.parameters) {
                const double moved = current.params.at(name) - v[0];
                for (double& x2 : v) x2 += moved;
                if (f.halves.count(name))
                    for (double& x2 : f.halves[name]) x2 += moved;
            }
        currentTest = engine.errors(current, testSet);
        for (Finding& finding : newFindings(current)) {
            const std::string& effect = finding.effect;
            finding.heldoutBefore = before;
            finding.heldoutAfter = mean(currentVal);
            finding.evidence = describe(effect, stepBefore, currentVal, valSet, from, before, finding.heldoutAfter);
            d.findings.push_back(std::move(finding));
        }
    }
    d.final = current;
    // Calibration intervals and the findings' second interval, from the local curvature; then what
    // the rig may be that neither the fits nor the metric can fix.
    addCurvatureIntervals(d, engine, current, fitSet, info, o, [&](const std::string& what) { say(what, 0.0); });
    for (auto& f : d.findings)
        for (const auto& [name, v] : f.parameters)
            if (const double model = discrepancyHalfWidth(o, name, v[0]); model > 0.0) f.discrepancy[name] = model;
    d.baselineError = mean(baselineTest);
    d.finalError = mean(currentTest);
    const auto g = pairedGain(baselineTest, currentTest, o.bootstrap, o.seed + 999);
    d.relativeGain = d.baselineError > 0 ? g[0] / d.baselineError : 0.0;
    d.gainLow = d.baselineError > 0 ? g[1] / d.baselineError : 0.0;
    d.gainHigh = d.baselineError > 0 ? g[2] / d.baselineError : 0.0;

    // 5. The set's own floor, and what the final model leaves above it.
    say("noise and chaos floor", 0.0);
    d.residual = measureResidual(engine, current, testSet, currentTest, strokes, o);
    setAsideStandIns(d);

    // 4. What the report shows: every stroke under the baseline and the final model.
    say("report", 0.0);
    d.ids.resize(n);
    d.gestures.resize(n);
    d.drive.resize(n);
    d.force.resize(n);
    d.measured.resize(n);
    d.baselineSim.resize(n);
    d.finalSim.resize(n);
    d.baselineParts.resize(n);
    d.finalParts.resize(n);
    d.measuredForce.resize(n);
    d.baselineForce.resize(n);
    d.finalForce.resize(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        d.ids[i] = strokes[i].id;
        d.gestures[i] = set.strokes[i].gesture;
        d.drive[i] = strokes[i].gesture.drive();
        d.force[i] = strokes[i].gesture.force;
        d.measured[i] = strokes[i].feat;
        d.baselineSim[i] = engine.simulate(d.baseline, i, &d.baselineForce[i]);
        d.finalSim[i] = engine.simulate(d.final, i, &d.finalForce[i]);
        d.baselineParts[i] = compare(strokes[i].feat, d.baselineSim[i], strokes[i].gesture, info, o.metricWeights);
        d.finalParts[i] = compare(strokes[i].feat, d.finalSim[i], strokes[i].gesture, info, o.metricWeights);
        d.measuredForce[i].assign(strokes[i].force.begin(), strokes[i].force.begin() + static_cast<long>(std::min(strokes[i].force.size(), d.baselineForce[i].size())));
    });
    // 5. The ramps' scale assumed a string that does not roll. Every fit compared a rolling model
    //    in that scale (Engine::rampSoftening); a named torsion now says how much softer the ramps
    //    were, so the reported scale takes that factor (the final model's, at its own Z_t/Z_0).
    //    Without a named torsion, a roll no model named would read the ramps' scale 1/s too large,
    //    and a volt set cannot tell (seed 2061: 22 missed rolls of Z_t/Z_0 1.2-3 read it 0.6 to
    //    14.6 % high; with tension and bow position stated to +-1 % the interval then held the
    //    rig's scale on 11 of 29 sets). So the interval's low end leaves room for the rig
    //    unknown's roll, as every finding's interval does.
    const double softer = engine.rampSoftening(d.final);
    const bool rolled = softer < 1.0;
    const bool roomForARoll = engine.scaleFromRamps() && !has(d.final.effects, "torsional_compliance");
    if (rolled) d.scale *= softer;
    for (auto& c : d.calibration) {
        if (c.name != "scale_n_per_unit") continue;
        char note[128];
        if (rolled) {
            c.value *= softer;
            c.low *= softer;
            c.high *= softer;
            std::snprintf(note, sizeof note, "; times %.3f, the ramps' softening by a rolling string", softer);
            c.meaning += note;
        }
        if (roomForARoll) {
            const double s = softeningAt(kReadilyRollingZt, d.statedTorsionSpeedRatio);
            c.low *= s;
            std::snprintf(note, sizeof note, "; its low end times %.3f, the softening of a roll of Z_t/Z_0 = %g that no model named", s, kReadilyRollingZt);
            c.meaning += note;
        }
    }
    // 6. Two-ended steady strokes: bow-point velocity and friction reconstructed from the end
    //    forces, measured and as the final model would show them.
    d.loops = compareTwoEnded(set, info, engine, d.final, d.scale, o, [&](const std::string& what) { say(what, 0.0); });
    d.simulations = engine.simulations();
    d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return d;
}

} // namespace rosin::lab
