// `rosin study --compare-splits`: the same sets diagnosed under several splits of their strokes,
// set beside set. A finding that one split names and another does not rests on which strokes
// happened to fit, validate and test, not on the data alone; this says how often that happens.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "StudyPlan.h"
#include "StudyScored.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Output.h"
#include "rosin/lab/Study.h"
#include "rosin/lab/SynthData.h"

namespace rosin::lab {
namespace fs = std::filesystem;
using nlohmann::json;
using namespace scoring;

namespace {
std::string percent(int part, int whole)
{
    char b[32];
    std::snprintf(b, sizeof b, "%.0f %%", whole ? 100.0 * part / whole : 0.0);
    return b;
}

std::vector<std::string> sorted(std::vector<std::string> v)
{
    std::sort(v.begin(), v.end());
    return v;
}

/// One study's diagnosed sets by set seed, and how its strokes were split.
struct SplitStudy {
    std::string name;
    std::map<std::uint64_t, Scored> sets;
    std::set<std::uint64_t> splitSeeds;
    std::string describeSplit() const
    {
        return splitSeeds.size() == 1 ? "one split for every set, seed " + std::to_string(*splitSeeds.begin())
                                      : "a split per set, " + std::to_string(splitSeeds.size()) + " seeds over " + std::to_string(sets.size()) + " sets";
    }
};

/// The named parameters of `s` whose interval the data identify, and whether each holds the truth.
std::pair<int, int> coverageOf(const Scored& s)
{
    int covered = 0, intervals = 0;
    for (const std::string& p : physicalParameterNames())
        if (const auto in = truthInInterval(s, p)) {
            covered += *in;
            ++intervals;
        }
    return {covered, intervals};
}

SplitStudy readSplitStudy(const fs::path& study)
{
    SplitStudy out;
    out.name = study.filename().string();
    for (const fs::path& f : diagnosedSetFolders(study)) {
        Scored s = readScored(f);
        if (s.seed == 0) throw LabError(f.string() + "/truth.json: no \"seed\": its set cannot be matched with the other studies' sets");
        out.splitSeeds.insert(s.splitSeed);
        const std::uint64_t seed = s.seed;
        if (!out.sets.emplace(seed, std::move(s)).second)
            throw LabError(f.string() + ": set seed " + std::to_string(seed) + " twice in " + study.string());
    }
    if (out.sets.empty()) throw LabError(study.string() + ": no diagnosed sets");
    return out;
}

/// The procedure must be the same in every study but for the split, or the comparison would
/// measure something else than the split.
void requireOneProcedure(const std::vector<SplitStudy>& studies, const std::vector<fs::path>& folders)
{
    const Scored& first = studies.front().sets.begin()->second;
    for (std::size_t k = 0; k < studies.size(); ++k)
        for (const auto& [seed, s] : studies[k].sets) {
            const std::string where = setFolder(folders[k], s.index).string();
            if (s.splitMethod != first.splitMethod)
                throw LabError(where + "/diagnosis/split.json: method \"" + s.splitMethod + "\" where " + folders.front().string() + " has \"" +
                               first.splitMethod + "\": splits compared must deal the strokes the same way");
            if (!s.search.empty() && !first.search.empty() && s.search != first.search)
                throw LabError(where + "/diagnosis/diagnosis.json: search " + describeSearch(s.search) + " where " + folders.front().string() +
                               " has " + describeSearch(first.search) + ": splits compared must search the same way");
            if (s.metricWeights != first.metricWeights)
                throw LabError(where + "/diagnosis/diagnosis.json: metric weights " + describeMetricWeights(s.metricWeights) + " where " +
                               folders.front().string() + " has " + describeMetricWeights(first.metricWeights) + ": splits compared must use one metric");
        }
}
} // namespace

std::string compareSplits(const fs::path& dir, const std::vector<fs::path>& folders)
{
    if (folders.size() < 2) throw LabError("study --compare-splits: give two or more study folders (the same sets under different splits)");
    const json plan = readPlan(folders.front());
    std::vector<SplitStudy> studies;
    for (const fs::path& f : folders) {
        if (fs::exists(dir) && fs::equivalent(dir, f))
            throw LabError(dir.string() + ": the comparison would be written into a study it compares; write it to another folder");
        const json here = readPlan(f);
        if (populationOf(here) != populationOf(plan) || here.value("seed", json()) != plan.value("seed", json()))
            throw LabError(f.string() + "/plan.json: " + populationOf(here).dump() + " (seed " + here.value("seed", json()).dump() + ") where " +
                           folders.front().string() + " has " + populationOf(plan).dump() + " (seed " + plan.value("seed", json()).dump() +
                           "): splits are compared on one plan's sets");
        studies.push_back(readSplitStudy(f));
    }
    requireOneProcedure(studies, folders);

    // The sets every study diagnosed; the others are counted, not compared.
    std::vector<std::uint64_t> common;
    std::set<std::uint64_t> anywhere;
    for (const auto& st : studies)
        for (const auto& [seed, s] : st.sets) anywhere.insert(seed);
    for (const std::uint64_t seed : anywhere)
        if (std::all_of(studies.begin(), studies.end(), [&](const SplitStudy& st) { return st.sets.count(seed) > 0; })) common.push_back(seed);
    if (common.empty()) throw LabError("study --compare-splits: no set was diagnosed in every study given");
    for (const std::uint64_t seed : common) {
        std::map<std::uint64_t, std::string> splitOf; // split seed -> the study that used it
        for (std::size_t k = 0; k < studies.size(); ++k) {
            const Scored& s = studies[k].sets.at(seed);
            if (const auto [at, fresh] = splitOf.emplace(s.splitSeed, folders[k].string()); !fresh)
                throw LabError(setFolder(folders[k], s.index).string() + "/diagnosis/split.json: split seed " + std::to_string(s.splitSeed) +
                               ", as in " + at->second + ": the same split twice compares nothing");
        }
    }

    const std::vector<std::string>& vocabulary = effectIds();
    struct EffectCount {
        int hidden = 0, every = 0, some = 0, none = 0, wrongAnywhere = 0;
    };
    std::map<std::string, EffectCount> effects;
    struct StudyCount {
        int exact = 0, nulls = 0, nullsNaming = 0, wrong = 0, covered = 0, intervals = 0;
    };
    std::vector<StudyCount> byStudy(studies.size());
    int alike = 0, nullsNamingAnywhere = 0, nulls = 0;
    json perSet = json::array();
    std::ostringstream differing;
    for (const std::uint64_t seed : common) {
        const Scored& ref = studies.front().sets.at(seed);
        const std::vector<std::string> hidden = sorted(ref.hidden);
        bool same = true, nullNamed = false;
        json found = json::object();
        for (std::size_t k = 0; k < studies.size(); ++k) {
            const Scored& s = studies[k].sets.at(seed);
            const std::vector<std::string> f = sorted(s.found);
            same = same && f == sorted(ref.found);
            found[studies[k].name] = f;
            StudyCount& c = byStudy[k];
            c.exact += f == hidden;
            if (hidden.empty()) {
                ++c.nulls;
                c.nullsNaming += !f.empty();
                nullNamed = nullNamed || !f.empty();
            }
            c.wrong += static_cast<int>(std::count_if(f.begin(), f.end(), [&](const std::string& e) { return !has(hidden, e); }));
            const auto [cov, n] = coverageOf(s);
            c.covered += cov;
            c.intervals += n;
        }
        alike += same;
        nulls += hidden.empty();
        nullsNamingAnywhere += nullNamed;
        for (const std::string& e : vocabulary) {
            const int named = static_cast<int>(std::count_if(studies.begin(), studies.end(), [&](const SplitStudy& st) { return has(st.sets.at(seed).found, e); }));
            EffectCount& c = effects[e];
            if (has(hidden, e)) {
                ++c.hidden;
                c.every += named == static_cast<int>(studies.size());
                c.some += named > 0 && named < static_cast<int>(studies.size());
                c.none += named == 0;
            } else {
                c.wrongAnywhere += named > 0;
            }
        }
        perSet.push_back({{"set", ref.index}, {"seed", seed}, {"hidden", hidden}, {"found", found}, {"alike", same}});
        if (!same) {
            differing << "| " << ref.index << " | " << effectsLabel(hidden);
            for (const auto& st : studies) differing << " | " << effectsLabel(sorted(st.sets.at(seed).found));
            differing << " |\n";
        }
    }

    const int n = static_cast<int>(common.size());
    std::ostringstream md;
    md << "# The same sets under " << studies.size() << " splits\n\n";
    md << "Compared: ";
    for (std::size_t k = 0; k < studies.size(); ++k)
        md << (k ? ", " : "") << studies[k].name << " (" << studies[k].describeSplit() << ")";
    md << ". Each set's strokes are dealt into fit, validation and test strokes differently in each; the recordings, the plan (seed "
       << plan.value("seed", json()).dump() << ") and the procedure are the same.\n\n";
    md << n << " sets diagnosed in every study";
    if (anywhere.size() > common.size()) md << " (" << anywhere.size() - common.size() << " more diagnosed in some only, left out)";
    md << ".\n\n**Sets named alike under every split: " << alike << " of " << n << " (" << percent(alike, n) << ").** Null sets naming an effect under any split: "
       << nullsNamingAnywhere << " of " << nulls << ".\n\n";
    md << "| effect | hidden in | named under every split | under some | under none | named where not hidden, under any split |\n|---|---|---|---|---|---|\n";
    json effectsJson = json::object();
    for (const std::string& e : vocabulary) {
        const EffectCount& c = effects[e];
        md << "| " << e << " | " << c.hidden << " | " << c.every << " | " << c.some << " | " << c.none << " | " << c.wrongAnywhere << " of "
           << n - c.hidden << " |\n";
        effectsJson[e] = {{"hidden", c.hidden}, {"named_under_every_split", c.every}, {"named_under_some", c.some}, {"named_under_none", c.none},
                          {"named_where_not_hidden_under_any", c.wrongAnywhere}};
    }
    md << "\n| study | split | named exactly right | null sets naming an effect | labels where not hidden | coverage of the 95 % intervals |\n"
          "|---|---|---|---|---|---|\n";
    json studiesJson = json::array();
    int covered = 0, intervals = 0;
    for (std::size_t k = 0; k < studies.size(); ++k) {
        const StudyCount& c = byStudy[k];
        md << "| " << studies[k].name << " | " << studies[k].describeSplit() << " | " << c.exact << " of " << n << " | " << c.nullsNaming << " of "
           << c.nulls << " | " << c.wrong << " | " << percent(c.covered, c.intervals) << " (" << c.covered << " of " << c.intervals << ") |\n";
        studiesJson.push_back({{"study", studies[k].name}, {"split", studies[k].describeSplit()}, {"exactly_right", c.exact},
                               {"null_sets_naming", c.nullsNaming}, {"labels_where_not_hidden", c.wrong}, {"covered", c.covered},
                               {"intervals", c.intervals}});
        covered += c.covered;
        intervals += c.intervals;
    }
    md << "\nCoverage over every split's intervals: " << percent(covered, intervals) << " (" << covered << " of " << intervals << ").\n";
    if (alike < n) {
        md << "\nThe sets named differently:\n\n| set | hidden |";
        for (const auto& st : studies) md << " " << st.name << " |";
        md << "\n|---|---|";
        for (std::size_t k = 0; k < studies.size(); ++k) md << "---|";
        md << "\n" << differing.str();
    }

    fs::create_directories(dir);
    OutputSet out;
    std::ofstream(out.add(dir / "splits.json"))
        << json{{"plan_seed", plan.value("seed", json())}, {"studies", studiesJson}, {"sets_compared", n},
                {"sets_left_out", anywhere.size() - common.size()}, {"sets_alike", alike}, {"null_sets", nulls},
                {"null_sets_naming_under_any", nullsNamingAnywhere}, {"effects", effectsJson}, {"coverage", {{"covered", covered}, {"intervals", intervals}}},
                {"sets", perSet}}
               .dump(1)
        << "\n";
    std::ofstream(out.add(dir / "splits.md")) << md.str();
    out.commit();
    return md.str();
}

} // namespace rosin::lab
