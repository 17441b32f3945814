#include "DiagnoseRounds.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace rosin::lab::diag {

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

NamingRounds::NamingRounds(Diagnosis& d, const Engine& engine, const DiagnoseOptions& o, const StringInfo& info,
                           const std::vector<Prepared>& strokes, const StrokeSplit& split, const EffectModel& baseline,
                           const std::vector<ErrorParts>& baselineTest, std::function<void(const std::string&, double)> say)
    : d_(d), engine_(engine), o_(o), info_(info), strokes_(strokes), fitSet_(split.fit), valSet_(split.validation), testSet_(split.test),
      say_(std::move(say)), current_(baseline), currentVal_(engine.errors(baseline, split.validation)), currentTest_(baselineTest)
{
}

std::vector<std::string> NamingRounds::rules(const DiagnoseOptions& o, const StringInfo& info)
{
    const auto prior = [&](const char* name, const std::optional<double>& stated) {
        char text[32];
        std::snprintf(text, sizeof text, "+-%.3g %%", 100.0 * (boundsOf(name, info).second - 1.0));
        return std::string(text) + (stated ? " (the manifest's stated prior)" : "");
    };
    std::vector<std::string> rules{
        "Calibration first: the steady-sliding curve from steady_sliding.csv, the string's transverse Q and its torsional c_t / c and Q_t from the manifest where it states them (else the model's), tension within " + prior("tension_scale", info.tensionPrior) +
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
            "by the model discrepancy the studies measured (the one the report prints" + nameableEdgesText(o) + "; where every refit came back to the estimate, "
            "the local curvature's width stands in for the bootstrap's here and in rule 5), and (5) searched afresh on the low- and on the high-drive half of the fit strokes "
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
        rules.push_back("When a round names nothing, a Hertzian contact and a rolling string still open are tried together as one candidate "
                        "(one r_A), from the grid and from where their own fits that round left them; the pair names both only when its "
                        "validation error is also below each of the two alone, fitted in that round, by the naming threshold, and rules 2-5 "
                        "hold for all its parameters.");
    if (o.usualResidualRatio > 0.0) rules.push_back(standInRuleText(o.usualResidualRatio));
    return rules;
}

void NamingRounds::run()
{
    while (nextRound()) {
    }
}

NamingRounds::Tried NamingRounds::evaluate(const Candidate& c, std::vector<double> x, double fitError, std::uint64_t bootstrapStream)
{
    Tried t{c, std::move(x), {}, {}, d_.trials.size()};
    t.val = engine_.errors(apply(current_, c, t.x), valSet_);
    t.gain = pairedGain(currentVal_, t.val, o_.bootstrap, o_.seed + bootstrapStream);
    Trial trial;
    trial.round = round_;
    trial.effect = c.effect;
    for (std::size_t j = 0; j < c.names.size(); ++j) trial.parameters[c.names[j]] = t.x[j];
    trial.fitError = fitError;
    trial.gain = t.gain[0];
    trial.gainLow = t.gain[1];
    trial.gainHigh = t.gain[2];
    const double before = mean(currentVal_); // the round's start: no candidate has been kept yet
    trial.relativeGain = before > 0 ? t.gain[0] / before : 0.0;
    trial.verdict = "not the largest fall";
    if (!(t.gain[1] > 0.0)) trial.verdict = "validation fall not significant";
    else if (trial.relativeGain < o_.namingThreshold) trial.verdict = "validation fall below the threshold";
    d_.trials.push_back(trial);
    return t;
}

void NamingRounds::searchAgain(const EffectModel& base, const Candidate& c, std::vector<double> from, int evaluations, double step,
                               std::vector<double>& x, double& fitError) const
{
    double againError = 0.0;
    std::vector<double> again = diag::fit(engine_, base, c, fitSet_, std::move(from), evaluations, step, &againError, false);
    if (againError < fitError) x = std::move(again), fitError = againError;
}

std::vector<double> NamingRounds::search(const EffectModel& base, const Candidate& c, double& fitError) const
{
    std::vector<double> x = diag::fit(engine_, base, c, fitSet_, c.start, o_.maxEvaluations, 0.2, &fitError, true, o_.secondStart);
    // A rolling string changes the scale of every force the ramps read, so the parameters
    // named without it sit far from where they belong beside it, and the grid from there
    // misses the valley: search also from where round 1 left the torsion on the baseline,
    // with twice the evaluations (COBYLA spends one per parameter, seven or more here,
    // before its first step).
    if (const auto from = roundOneStart(d_.trials, c); round_ > 1 && from) searchAgain(base, c, *from, 2 * o_.maxEvaluations, 0.2, x, fitError);
    // A later round's contact fits r_A and the nuisances beside its exponent, and COBYLA's
    // first simplex can stay where the earlier finding left them (seed 2057, set 6: fit
    // error 0.124 at exponent 0.78, where the contact-and-roll pair's search reached 0.104
    // at 0.68 with no roll): search again from where it ended, with a wider first step.
    if (o_.restartContact && round_ > 1 && c.effect == "hertzian_contact") searchAgain(base, c, x, o_.maxEvaluations, 0.35, x, fitError);
    return x;
}

bool NamingRounds::passesRuleOne(const Tried& t) const { return t.gain[1] > 0.0 && d_.trials[t.trial].relativeGain >= o_.namingThreshold; }

bool NamingRounds::judge(const Tried& t)
{
    Trial& trial = d_.trials[t.trial];
    std::map<std::string, double> fitted;
    for (std::size_t j = 0; j < t.c.names.size(); ++j) fitted[t.c.names[j]] = t.x[j];
    if (atNull(t.c.effect, fitted)) { trial.verdict = "fitted at the effect's own absence"; return false; }
    if (pinnedAtEdge(t.c, t.x)) { trial.verdict = "fitted at the edge of its search range (a stand-in, not a measurement)"; return false; }
    // Rule 2's comparisons with the round's other candidates (docs/diagnosis.md).
    if (const std::string failed = standInVerdict(trial, t.c, roundValidation_, current_.effects, d_.trials, o_.namingThreshold, o_.shiftOverRateMargin);
        !failed.empty()) {
        trial.verdict = failed;
        return false;
    }
    // (3) the test strokes
    const EffectModel cand = apply(current_, t.c, t.x);
    trial.testGain = mean(currentTest_) - mean(engine_.errors(cand, testSet_));
    if (!(trial.testGain > 0.0)) { trial.verdict = "no gain on the test strokes"; return false; }
    // (4) intervals from refits on bootstrap resamples, each from a fresh start
    say_("round " + std::to_string(round_) + ": uncertainty of " + t.c.effect, 0.0);
    std::vector<std::vector<double>> refits;
    std::mt19937_64 prng(o_.seed * 31ull + static_cast<std::uint64_t>(round_));
    std::uniform_int_distribution<std::size_t> pick(0, fitSet_.size() - 1);
    std::uniform_real_distribution<double> jump(-0.15, 0.15);
    // the estimate's error on a resample, from its per-stroke errors on the fit strokes
    const std::vector<ErrorParts> estimateOnFit = engine_.errors(cand, fitSet_);
    for (int b = 0; b < o_.parameterBootstrap; ++b) {
        std::vector<std::size_t> resampled;
        std::vector<ErrorParts> estimateOnResample;
        for (std::size_t k = 0; k < fitSet_.size(); ++k) {
            const std::size_t at = pick(prng);
            resampled.push_back(fitSet_[at]);
            estimateOnResample.push_back(estimateOnFit[at]);
        }
        std::vector<double> freshStart = t.x;
        for (std::size_t k = 0; k < freshStart.size(); ++k)
            freshStart[k] = std::clamp(freshStart[k] + jump(prng) * (t.c.hi[k] - t.c.lo[k]), t.c.lo[k], t.c.hi[k]);
        const int evaluations = std::max(8, o_.maxEvaluations / 2);
        double refitError = 0.0;
        std::vector<double> refit = diag::fit(engine_, current_, t.c, resampled, freshStart, evaluations, 0.1, &refitError, false);
        // A refit that ends worse on its own resample than the estimate has not converged
        // (a few COBYLA steps for five or more parameters): search again from the estimate.
        if (mean(estimateOnResample) < refitError) refit = diag::fit(engine_, current_, t.c, resampled, t.x, evaluations, 0.05, nullptr, false);
        refits.push_back(std::move(refit));
    }
    halfWidth_.clear();
    returnedToEstimate_.clear();
    std::vector<double> width = bootstrapHalfWidths(t.c, refits, returnedToEstimate_);
    // Refits that all came back to the estimate (a search that ends in a narrow pit of the rough
    // surface: a contact's restart) measured where the search sticks, not what the data allow,
    // and left rule 5 only a tenth of the range (seed 2081/25: a load exponent of 0.668 for 0.739
    // refused for halves 0.074 apart, 0.070 allowed). Those parameters take the local
    // curvature's width instead.
    if (!returnedToEstimate_.empty()) {
        const std::vector<double> curvature = curvatureHalfWidths(engine_, current_, t.c, t.x, fitSet_);
        for (std::size_t k = 0; k < t.c.scanned; ++k)
            if (returnedToEstimate_.count(t.c.names[k])) width[k] = std::max(width[k], curvature[k]);
    }
    bool atNullInterval = false, atNullWithDiscrepancy = false;
    // Rules (4) and (5) judge the candidate's own parameters; those of earlier findings and
    // the nuisances were free in the refits but were judged when they entered.
    for (std::size_t k = 0; k < t.c.scanned; ++k) {
        const double hw = width[k];
        halfWidth_[t.c.names[k]] = hw;
        atNullInterval = atNullInterval || intervalAtNull(t.c.names[k], t.x[k] - hw, t.x[k] + hw);
        // The interval the report will print carries the model's own error on rigs it does
        // not describe; a finding whose printed interval reaches no effect is not proved,
        // so it is not named (the studies' spurious shifts all had one: docs/diagnosis.md).
        const double wide = namingHalfWidth(o_, t.c.names[k], t.x[k], hw);
        atNullWithDiscrepancy = atNullWithDiscrepancy || intervalAtNull(t.c.names[k], t.x[k] - wide, t.x[k] + wide);
    }
    if (atNullInterval) { trial.verdict = "interval reaches the no-effect value"; return false; }
    if (atNullWithDiscrepancy) { trial.verdict = "interval reaches the no-effect value once the model discrepancy is counted"; return false; }
    // (5) the two drive halves of the fit strokes
    const std::vector<std::vector<double>> halves = diag::driveHalves(engine_, current_, t.c, fitSet_, strokes_, t.x, o_.maxEvaluations);
    if (const std::string why = halvesDisagreement(t.c, halves[0], halves[1], halfWidth_); !why.empty()) {
        trial.verdict = "not consistent on the two drive halves (bow acceleration, or the gesture's own drive): " + why;
        return false;
    }
    trial.verdict = "named";
    for (std::size_t k = 0; k < t.c.scanned; ++k) halvesOffset_[t.c.names[k]] = {halves[0][k] - t.x[k], halves[1][k] - t.x[k]};
    return true;
}

const NamingRounds::Tried* NamingRounds::tryPairs()
{
    auto single = [&](const std::string& effect) {
        return std::find_if(tried_.begin(), tried_.end(), [&](const Tried& t) { return t.c.effect == effect; });
    };
    // Pointers into pairs_ stay valid: it never grows past this.
    pairs_.reserve(pairedEffects().size());
    for (const auto& [a, b] : pairedEffects()) {
        const auto raw = offered(current_, a + "+" + b);
        const auto alone = single(a), other = single(b);
        if (!raw || alone == tried_.end() || other == tried_.end()) continue;
        const Candidate c = withNuisances(*raw, current_);
        say_("round " + std::to_string(round_) + ": " + c.effect, 0.0);
        double fitError = 0.0;
        std::vector<double> x = diag::fit(engine_, current_, c, fitSet_, c.start, 2 * o_.maxEvaluations, 0.2, &fitError, true, o_.secondStart);
        searchAgain(current_, c, startFromParts(c, alone->c, alone->x, other->c, other->x), 2 * o_.maxEvaluations, 0.2, x, fitError);
        pairs_.push_back(evaluate(c, std::move(x), fitError, static_cast<std::uint64_t>(round_ * 100 + 50)));
        const Tried& t = pairs_.back();
        Trial& trial = d_.trials[t.trial];
        const double overA = relativeFall(mean(alone->val), mean(t.val)), overB = relativeFall(mean(other->val), mean(t.val));
        if (!passesRuleOne(t)) continue;
        if (std::min(overA, overB) < o_.namingThreshold) {
            trial.verdict = "no better than " + (overA < overB ? a : b) + " alone";
            continue;
        }
        if (judge(t)) return &t;
    }
    return nullptr;
}

std::vector<Finding> NamingRounds::newFindings(const EffectModel& model) const
{
    std::vector<Finding> found;
    for (const auto& effect : best_->c.adds) {
        if (has(from_.effects, effect)) continue;
        Finding finding;
        finding.effect = effect;
        for (const auto& name : best_->c.names)
            if (effectOfParameter(name) == effect) {
                const double v = model.params.at(name);
                const auto hw = halfWidth_.find(name);
                const double w = hw != halfWidth_.end() ? hw->second : 0.0;
                finding.parameters[name] = {v, v - w, v + w};
                if (returnedToEstimate_.count(name)) finding.bootstrapAtEstimate.insert(name);
                // the halves keep their offsets from the value, which the joint refit moved
                if (const auto h = halvesOffset_.find(name); h != halvesOffset_.end()) finding.halves[name] = {v + h->second[0], v + h->second[1]};
            }
        found.push_back(std::move(finding));
    }
    return found;
}

bool NamingRounds::ownFindingAtNull() const
{
    const auto found = newFindings(current_);
    return std::any_of(found.begin(), found.end(), [&](const Finding& f) { return movedToNull(f, current_.params, o_); });
}

void NamingRounds::jointRefit()
{
    // A parameter fitted before a later effect entered may have stood in for it: refit all
    // parameters, nuisances included, and keep the refit unless it does worse on validation.
    if (current_.params.size() <= 1) return;
    say_("round " + std::to_string(round_) + ": joint refit", 0.0);
    Candidate all;
    all.effect = "joint";
    for (const auto& [name, value] : current_.params) {
        const auto [lo, hi] = boundsOf(name, info_);
        all.names.push_back(name);
        all.lo.push_back(lo);
        all.hi.push_back(hi);
        all.start.push_back(value);
    }
    const auto x = diag::fit(engine_, current_, all, fitSet_, all.start, o_.maxEvaluations, 0.05, nullptr, false);
    const EffectModel refit = apply(current_, all, x);
    const auto refitVal = engine_.errors(refit, valSet_);
    if (mean(refitVal) <= mean(currentVal_)) {
        current_ = refit;
        currentVal_ = refitVal;
    }
}

void NamingRounds::recordWithout(const Without& w, const std::string& verdict)
{
    Trial t;
    t.round = round_;
    t.effect = w.effect;
    for (const auto& [name, value] : current_.params)
        if (effectOfParameter(name) == w.effect) t.parameters[name] = value;
    t.gain = mean(w.val) - mean(currentVal_);
    t.relativeGain = w.share;
    t.verdict = verdict;
    d_.trials.push_back(t);
}

void NamingRounds::askEarlierFindings()
{
    // An effect named earlier may have stood in for the one named now (a rosin shift for a
    // contact not yet tried): each earlier finding must still earn its place, by the naming
    // threshold on validation, against the model refitted without it. The weakest goes first,
    // and a dropped effect is not tried again.
    EffectModel earlier = from_; // the model before this round, less what has been dropped since
    while (true) {
        std::vector<Without> tested;
        for (const auto& effect : earlier.effects) {
            if (!has(current_.effects, effect)) continue;
            if (effect == "thermal_memory" && std::any_of(current_.effects.begin(), current_.effects.end(), needsThermal)) continue;
            say_("round " + std::to_string(round_) + ": without " + effect, 0.0);
            // Searched as hard as the model it is compared with: this round's winner is fitted
            // again on the model that never named the earlier effect, by the search that found
            // it (a joint refit from where the earlier effect left the other parameters stays
            // there). The winner is new this round, so the model without the earlier effect
            // offers it. A pair's further start from its two parts is not repeated: its parts
            // were fitted beside the earlier effect.
            const EffectModel withoutEarlier = removed(earlier, effect);
            const auto winner = offered(withoutEarlier, best_->c.effect);
            if (!winner) continue;
            const Candidate c = withNuisances(*winner, withoutEarlier);
            double fitError = 0.0;
            Without w{effect, apply(withoutEarlier, c, search(withoutEarlier, c, fitError)), {}, 0.0};
            w.val = engine_.errors(w.model, valSet_);
            w.share = relativeFall(mean(w.val), mean(currentVal_));
            tested.push_back(std::move(w));
        }
        // An earlier finding whose parameter the joint refit moved to where its interval (the
        // half-width it was named with, and the model discrepancy) reaches the no-effect value
        // fails rule 4 now.
        const auto stale = std::find_if(tested.begin(), tested.end(), [&](const Without& w) {
            return std::any_of(d_.findings.begin(), d_.findings.end(), [&](const Finding& f) { return f.effect == w.effect && movedToNull(f, current_.params, o_); });
        });
        const auto weakest =
            stale != tested.end() ? stale : std::min_element(tested.begin(), tested.end(), [](const Without& a, const Without& b) { return a.share < b.share; });
        if (weakest == tested.end() || (stale == tested.end() && weakest->share >= o_.namingThreshold)) {
            for (const Without& w : tested) recordWithout(w, "kept beside " + best_->c.effect + ": without it the validation error rises by the share shown");
            return;
        }
        recordWithout(*weakest, stale != tested.end() ? "dropped: beside " + best_->c.effect + " its parameter moved to where its interval reaches the no-effect value"
                                               : "dropped: beside " + best_->c.effect + " it no longer lowers the validation error by the threshold");
        d_.findings.erase(std::remove_if(d_.findings.begin(), d_.findings.end(), [&](const Finding& f) { return f.effect == weakest->effect; }),
                          d_.findings.end());
        dropped_.insert(weakest->effect);
        earlier = removed(earlier, weakest->effect);
        current_ = weakest->model;
        currentVal_ = weakest->val;
    }
}

void NamingRounds::undoThisRound(const std::string& verdict)
{
    diag::undoRound(d_, dropped_, atRoundStart_, best_->trial, membersOf(best_->c.effect), verdict);
    current_ = from_;
    currentVal_ = stepBefore_;
}

bool NamingRounds::nextRound()
{
    ++round_;
    tried_.clear();
    pairs_.clear();
    best_ = nullptr;
    halfWidth_.clear();
    returnedToEstimate_.clear();
    halvesOffset_.clear();
    roundValidation_.clear();

    std::vector<Candidate> cands;
    for (const Candidate& c : candidates(current_))
        if (!dropped_.count(c.effect)) cands.push_back(withNuisances(c, current_));
    if (cands.empty()) return false;
    for (std::size_t k = 0; k < cands.size(); ++k) {
        say_("round " + std::to_string(round_) + ": " + cands[k].effect, static_cast<double>(k) / static_cast<double>(cands.size()));
        double fitError = 0;
        std::vector<double> x = search(current_, cands[k], fitError);
        tried_.push_back(evaluate(cands[k], std::move(x), fitError, static_cast<std::uint64_t>(round_ * 100 + static_cast<int>(k))));
    }
    std::sort(tried_.begin(), tried_.end(), [](const Tried& a, const Tried& b) { return a.gain[0] > b.gain[0]; });
    for (const Tried& t : tried_) roundValidation_[t.c.effect] = mean(t.val);
    for (const Tried& t : tried_)
        if (passesRuleOne(t) && judge(t)) {
            best_ = &t;
            break;
        }
    // Two effects that each fit worse alone than together (a roll beside a contact) are out of
    // reach of rounds of single effects: when this round names nothing, each open pair is tried
    // as one candidate, from the grid and from where its two effects' own fits left them.
    if (o_.tryPairs && !best_) best_ = tryPairs();
    if (!best_) return false;

    d_.trials[best_->trial].kept = true;
    from_ = current_;
    stepBefore_ = currentVal_;
    current_ = apply(current_, best_->c, best_->x);
    currentVal_ = best_->val;
    jointRefit();
    // Rule 4 holds where the joint refit left this round's own finding, as it must for the
    // earlier ones below: a refit that moves it to where its interval reaches no effect says the
    // data do not prove it (seed 2079, set 6: a shift judged at 17.4 K, refitted to 15.5 K, under
    // the 15.7 K that rule 4 can name). The round names nothing, and the effect is not tried again.
    atRoundStart_ = roundStart(d_, dropped_);
    if (ownFindingAtNull()) {
        undoThisRound("passed rules 1-5, then the joint refit moved its parameter to where its interval reaches the no-effect value");
        return true;
    }
    askEarlierFindings();
    // Refitted without an earlier finding it displaced, this round's own finding is asked rule 4
    // again: if it now reaches no effect, neither change is proved and the round is undone.
    if (d_.findings.size() < atRoundStart_.findings.size() && ownFindingAtNull()) {
        undoThisRound("passed rules 1-5, then, refitted without the earlier finding it displaced, its parameter moved to where its "
                  "interval reaches the no-effect value");
        return true;
    }
    // Earlier findings report where their parameters are now (they moved with this round's fit).
    for (auto& f : d_.findings)
        for (auto& [name, v] : f.parameters) {
            const double moved = current_.params.at(name) - v[0];
            for (double& x2 : v) x2 += moved;
            if (f.halves.count(name))
                for (double& x2 : f.halves[name]) x2 += moved;
        }
    currentTest_ = engine_.errors(current_, testSet_);
    std::vector<Finding> found = newFindings(current_);
    std::vector<std::string> named;
    for (const Finding& f : found) named.push_back(f.effect);
    // The round's single-effect fits tell apart what each of several effects named at once added.
    std::map<std::string, AloneFit> alone;
    for (const Tried& t : tried_)
        if (has(named, t.c.effect)) alone[t.c.effect] = {apply(from_, t.c, t.x), t.val};
    for (Finding& finding : found) {
        FindingEvidence e = roundEvidence(finding.effect, named, alone, stepBefore_, currentVal_, valSet_, from_);
        finding.evidence = std::move(e.text);
        finding.heldoutBefore = e.before;
        finding.heldoutAfter = e.after;
        d_.findings.push_back(std::move(finding));
    }
    return true;
}

} // namespace rosin::lab::diag
