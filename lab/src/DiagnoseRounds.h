// Step 4 of a diagnosis (internal to lab/): from the calibrated baseline, effects are added one
// round at a time under the naming rules (docs/diagnosis.md, "Naming rules" and "After a finding").
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "DiagnoseEngine.h"

namespace rosin::lab::diag {

/// The naming rounds of one diagnosis. Each round fits every open candidate on the fit strokes,
/// judges them in order of their validation fall, tries the open pairs when no single one is
/// named, and then asks the findings it already has whether they still earn their place. The
/// findings, dropped findings and trial rows go into the Diagnosis as they are decided.
class NamingRounds {
public:
    NamingRounds(Diagnosis& d, const Engine& engine, const DiagnoseOptions& o, const StringInfo& info, const std::vector<Prepared>& strokes,
                 const StrokeSplit& split, const EffectModel& baseline, const std::vector<ErrorParts>& baselineTest,
                 std::function<void(const std::string&, double)> say);

    /// The rules the rounds follow, with this set's priors and the options' thresholds, in the
    /// report's words (diagnosis.json's "rules").
    static std::vector<std::string> rules(const DiagnoseOptions& o, const StringInfo& info);
    /// Runs rounds until one has nothing to try or names nothing.
    void run();
    /// The model the rounds ended with, and its errors on the test strokes.
    const EffectModel& model() const { return current_; }
    const std::vector<ErrorParts>& testErrors() const { return currentTest_; }

private:
    /// A candidate fitted this round: its parameters, validation errors, paired gain and trial row.
    struct Tried {
        Candidate c;
        std::vector<double> x;
        std::vector<ErrorParts> val;
        std::array<double, 3> gain;
        std::size_t trial;
    };
    /// The model refitted without an earlier finding, and how far its validation error rises.
    struct Without {
        std::string effect;
        EffectModel model;
        std::vector<ErrorParts> val;
        double share = 0;
    };

    /// One round; false when it ends the diagnosis (nothing left to try, or nothing named).
    bool nextRound();
    /// The candidate's validation errors, its paired gain and its trial row with rule 1's verdict.
    Tried evaluate(const Candidate& c, std::vector<double> x, double fitError, std::uint64_t bootstrapStream);
    /// A further search of c on `base` from `from` (no grid); its end replaces x when it fits the
    /// fit strokes better.
    void searchAgain(const EffectModel& base, const Candidate& c, std::vector<double> from, int evaluations, double step,
                     std::vector<double>& x, double& fitError) const;
    /// A candidate's whole search on `base`: the grid and COBYLA, then the further searches. The
    /// same routine refits a round's winner without an earlier finding, so the two models compared
    /// there were searched equally hard.
    std::vector<double> search(const EffectModel& base, const Candidate& c, double& fitError) const;
    bool passesRuleOne(const Tried& t) const;
    /// Rules 2-5 for a candidate whose validation fall passed rule 1; the verdict goes on its trial.
    bool judge(const Tried& t);
    /// When no single candidate is named: each open pair as one candidate. The named pair, if any.
    const Tried* tryPairs();
    /// This round's findings, at the parameters of `model`, with the intervals rule 4 gave them.
    std::vector<Finding> newFindings(const EffectModel& model) const;
    /// Rule 4 asked of this round's own finding where the model now has it.
    bool ownFindingAtNull() const;
    /// All parameters refitted together, kept unless they do worse on validation.
    void jointRefit();
    /// Every earlier finding must still earn its place beside this round's; the weakest that does
    /// not (or one the joint refit moved to its no-effect value) is dropped, one at a time.
    void askEarlierFindings();
    /// A trial row for an earlier finding asked beside this round's: kept or dropped, and why.
    void recordWithout(const Without& w, const std::string& verdict);
    /// The report and the model go back to where the round began.
    void undoThisRound(const std::string& verdict);

    Diagnosis& d_;
    const Engine& engine_;
    const DiagnoseOptions& o_;
    const StringInfo& info_;
    const std::vector<Prepared>& strokes_;
    const std::vector<std::size_t>&fitSet_, &valSet_, &testSet_;
    std::function<void(const std::string&, double)> say_; ///< progress: what, and how far (0-1)

    EffectModel current_;
    std::vector<ErrorParts> currentVal_, currentTest_;
    int round_ = 0;
    std::set<std::string> dropped_; ///< effects named, then dropped beside a later finding

    // What a round knows while it runs (reset at its start).
    std::vector<Tried> tried_, pairs_;
    const Tried* best_ = nullptr;
    std::map<std::string, double> halfWidth_;                    ///< the judged candidate's bootstrap half-widths (the curvature's where they returned to the estimate)
    std::set<std::string> returnedToEstimate_;                   ///< its parameters whose bootstrap refits all came back to the estimate
    std::map<std::string, std::array<double, 2>> halvesOffset_; ///< the named candidate's halves, from its value
    std::map<std::string, double> roundValidation_;             ///< every candidate's validation error this round
    EffectModel from_;                                           ///< the model before the round's winner
    std::vector<ErrorParts> stepBefore_;                         ///< its validation errors
    RoundStart atRoundStart_;
};

} // namespace rosin::lab::diag
