// The fit / validation / test split of a diagnosis (docs/diagnosis.md, step 3).
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Error.h"

namespace rosin::lab {

const char* splitMethodName(const DiagnoseOptions& o) { return o.stratifiedSplit ? "stratified" : "random"; }

std::map<std::string, bool> searchSwitches(const DiagnoseOptions& o)
{
    return {{"pairs", o.tryPairs}, {"contact_restart", o.restartContact}, {"second_start", o.secondStart}};
}

void checkMetricWeights(const std::array<double, 5>& weights, const std::string& what)
{
    double sum = 0;
    for (double w : weights) {
        if (!std::isfinite(w) || w < 0.0) throw LabError(what + ": every weight must be a finite number of 0 or more");
        sum += w;
    }
    if (std::abs(sum - 1.0) > 1e-3) throw LabError(what + ": the five weights must sum to 1 (they sum to " + std::to_string(sum) + ")");
    // A metric without the first slip's parts has nothing a friction law sets deterministically.
    if (weights[0] + weights[1] + weights[2] <= 0.0) throw LabError(what + ": the first slip's three parts cannot all weigh 0");
}

bool defaultMetricWeights(const std::array<double, 5>& weights) { return weights == ErrorParts::kWeights; }

StrokeSplit splitStrokes(const std::vector<StrokePlace>& places, const DiagnoseOptions& o, const std::string& setName)
{
    const std::size_t n = places.size();
    const auto nTest = static_cast<std::size_t>(std::lround(o.testFraction * static_cast<double>(n)));
    const auto nVal = static_cast<std::size_t>(std::lround(o.validationFraction * static_cast<double>(n)));
    if (nTest < 4 || nVal < 4 || n < nTest + nVal + 6)
        throw LabError(setName + ": too few strokes to split into fit, validation and test sets (need 16)");
    StrokeSplit split;
    std::mt19937_64 rng(o.seed);
    std::vector<std::size_t> shuffled(n);
    std::iota(shuffled.begin(), shuffled.end(), 0);
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    if (!o.stratifiedSplit) {
        // The default, and how every diagnosis before the stratified split dealt them.
        split.test.assign(shuffled.begin(), shuffled.begin() + static_cast<long>(nTest));
        split.validation.assign(shuffled.begin() + static_cast<long>(nTest), shuffled.begin() + static_cast<long>(nTest + nVal));
        split.fit.assign(shuffled.begin() + static_cast<long>(nTest + nVal), shuffled.end());
    } else {
        // Each stroke's level on three factors: its gesture, its drive and its bow force (ranked
        // among the set's distinct values of its gesture and binned into at most 12 levels).
        constexpr std::size_t kLevels = 12;
        std::array<std::vector<std::size_t>, 3> level;
        for (auto& l : level) l.resize(n);
        std::map<std::string, std::size_t> gestureLevel;
        for (std::size_t i = 0; i < n; ++i) level[0][i] = gestureLevel.emplace(places[i].gesture, gestureLevel.size()).first->second;
        for (int axis = 0; axis < 2; ++axis) {
            const auto value = [&](std::size_t i) { return axis == 0 ? places[i].drive : places[i].force; };
            std::map<std::string, std::set<double>> distinct; // per gesture
            for (std::size_t i = 0; i < n; ++i) distinct[places[i].gesture].insert(value(i));
            for (std::size_t i = 0; i < n; ++i) {
                const std::set<double>& values = distinct.at(places[i].gesture);
                const auto rank = static_cast<std::size_t>(std::distance(values.begin(), values.find(value(i))));
                level[static_cast<std::size_t>(axis) + 1][i] = rank * std::min(kLevels, values.size()) / values.size();
            }
        }
        // Minimisation (Pocock and Simon's allocation for clinical trials): strokes in the seed's
        // order each go to the role, among those with room left, that holds the smallest share of
        // its quota at the stroke's levels; the totals are exact.
        const std::array<std::size_t, 3> quota{nTest, nVal, n - nTest - nVal};
        std::array<std::size_t, 3> dealt{};
        std::array<std::array<std::map<std::size_t, double>, 3>, 3> held; // [role][factor][level]
        std::vector<std::size_t> role(n);
        for (const std::size_t i : shuffled) {
            std::size_t best = 3;
            double bestScore = 0;
            for (std::size_t r = 0; r < 3; ++r) {
                if (dealt[r] == quota[r]) continue;
                double score = 0;
                for (std::size_t f = 0; f < 3; ++f) score += held[r][f][level[f][i]] / static_cast<double>(quota[r]);
                // ties go to the role with the most room left, so the seed's order keeps its say
                score -= 1e-9 * static_cast<double>(quota[r] - dealt[r]) / static_cast<double>(quota[r]);
                if (best == 3 || score < bestScore) best = r, bestScore = score;
            }
            ++dealt[best];
            role[i] = best;
            for (std::size_t f = 0; f < 3; ++f) held[best][f][level[f][i]] += 1.0;
        }
        // The last strokes dealt have little choice left; swaps between roles that bring every
        // level's counts closer to its share (squared, relative to the role's quota) finish it.
        std::array<std::map<std::size_t, double>, 3> levelSize;
        for (std::size_t f = 0; f < 3; ++f)
            for (std::size_t i = 0; i < n; ++i) levelSize[f][level[f][i]] += 1.0;
        auto cost = [&](std::size_t r, std::size_t f, std::size_t l, double count) {
            const double expected = levelSize[f][l] * static_cast<double>(quota[r]) / static_cast<double>(n);
            return (count - expected) * (count - expected) / static_cast<double>(quota[r]);
        };
        auto imbalance = [&] {
            double c = 0;
            for (std::size_t r = 0; r < 3; ++r)
                for (std::size_t f = 0; f < 3; ++f)
                    for (const auto& [l, size] : levelSize[f]) c += cost(r, f, l, held[r][f][l]);
            return c;
        };
        auto move = [&](std::size_t i, std::size_t to) {
            for (std::size_t f = 0; f < 3; ++f) {
                held[role[i]][f][level[f][i]] -= 1.0;
                held[to][f][level[f][i]] += 1.0;
            }
            role[i] = to;
        };
        double now = imbalance();
        for (bool improved = true; improved;) {
            improved = false;
            for (std::size_t a = 0; a < n; ++a)
                for (std::size_t b = a + 1; b < n; ++b) {
                    const std::size_t i = shuffled[a], j = shuffled[b], ri = role[i], rj = role[j];
                    if (ri == rj) continue;
                    move(i, rj);
                    move(j, ri);
                    if (const double after = imbalance(); after < now - 1e-9) {
                        now = after;
                        improved = true;
                    } else {
                        move(j, rj);
                        move(i, ri);
                    }
                }
        }
        for (std::size_t i = 0; i < n; ++i) (role[i] == 0 ? split.test : role[i] == 1 ? split.validation : split.fit).push_back(i);
    }
    for (auto* v : {&split.test, &split.validation, &split.fit}) std::sort(v->begin(), v->end());
    return split;
}

} // namespace rosin::lab
