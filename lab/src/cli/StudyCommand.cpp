// `rosin study`.
#include "Cli.h"

#include <cstdio>
#include <memory>

#include "rosin/lab/Distributed.h"
#include "rosin/lab/Output.h"
#include "rosin/lab/ReferenceData.h"
#include "rosin/lab/Study.h"
#include "rosin/lab/SynthData.h"

namespace rosin::cli {

namespace {

struct StudyCommand {
    StudyOptions options;
    std::string out = "study";
    bool scoreOnly = false;
    std::vector<std::string> rigValues;
    std::vector<std::string> paramRanges;
    std::vector<std::string> statedUncertainties;
    std::vector<std::string> pool;
    std::vector<std::string> compare;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* cmd = app.add_subcommand("study", "Diagnose many reference sets (data the model did not make) and score the "
                                                    "findings against what was hidden");
        cmd->footer("Writes OUT/sets/NNN/{truth.json, diagnosis/}, then OUT/study.csv, study.json, summary.md and study.png:\n"
                    "detection per effect, false positives (null sets and per effect), parameter error, coverage of\n"
                    "the 95 % intervals, detection against effect size. An interrupted study resumes where it\n"
                    "stopped. Minutes per set: run by hand, not in CI. Under mpirun the sets are dealt to ranks.");
        cmd->add_option("-o,--out", out, "Study folder (created, or resumed)")->capture_default_str();
        cmd->add_option("--sets", options.sets, "Number of sets (a real study: 30 or more)")->check(CLI::Range(1, 1000))->capture_default_str();
        cmd->add_option("--nulls", options.nulls, "Of which with nothing hidden")->check(CLI::Range(0, 1000))->capture_default_str();
        cmd->add_option("--grid", options.grid, "Strokes per axis of each set")->check(CLI::Range(3, 30))->capture_default_str();
        cmd->add_option("--seed", options.seed, "Seed of the plan and of every set")->capture_default_str();
        cmd->add_option("--plan", options.plan,
                        "Plan version: 1 as in studies up to seed 2042, 2 also hides a rate dependence beside a rosin shift")
            ->check(CLI::Range(1, 2))
            ->capture_default_str();
        cmd->add_option("--gesture", options.gesture, "Strokes of every set: guettler, exp_speed, exp_force or mixed")
            ->check(CLI::IsMember({"guettler", "exp_speed", "exp_force", "mixed"}))->capture_default_str();
        cmd->add_option("--units", options.units,
                        "Sensor units of every set: V (an unknown gain, set from the pre-slip ramps) or N (calibrated, within the rig's "
                        "calibration_error); exp_force sets are always N")
            ->check(CLI::IsMember({"V", "N"}))->capture_default_str();
        cmd->add_option("--generator", options.generator,
                        "What makes the sets: reference (the reference simulator, which shares no code with the model) or "
                        "model-on-rig (the same plan and rigs, made by dsp/'s own model: the diagnosis's ceiling)")
            ->check(CLI::IsMember({"reference", "model-on-rig"}))
            ->capture_default_str();
        cmd->add_option("--oversampling", options.oversampling, "Reference simulation rate / file rate")->check(CLI::Range(4, 32))->capture_default_str();
        cmd->add_option("--diagnose-seed", options.diagnose.seed, "Seed of each diagnosis's split and bootstraps")->capture_default_str();
        cmd->add_flag("--split-per-set", options.splitPerSet,
                      "Give every set its own split (and bootstraps), seeded from the set's seed and --diagnose-seed, so that the study "
                      "samples which strokes fit, validate and test; without it every set of a grid shares one split");
        cmd->add_option("--rig-param", rigValues,
                        "Reference rig value NAME=VALUE fixed in every set instead of drawn (names: rosin synth-data --help), e.g. "
                        "inharmonicity=1e-3 for strongly stiff strings");
        cmd->add_option("--param-range", paramRanges,
                        "Hidden parameter NAME=LO:HI drawn from this range, inside its prior, instead of the whole prior (names: r_A, h0, p, "
                        "load_exponent, shift_k as its size, zt_ratio), e.g. zt_ratio=1.2:3 for a study of strongly rolling strings");
        cmd->add_option("--stated-uncertainty", statedUncertainties,
                        "Rigs of a lab that measured them, NAME=FRACTION (tension, beta): each rig's error is drawn within +-FRACTION "
                        "and its manifest states it, e.g. tension=0.01 beta=0.01; q=FRACTION: each manifest states its string's "
                        "Q at f0 and 5 kHz within +-FRACTION of the rig's; torsion=FRACTION: its c_t / c and torsional Q likewise");
        addSearchFlags(*cmd, options.diagnose);
        cmd->add_flag("--keep-sets", options.keepSets, "Keep the generated WAV sets");
        cmd->add_option("--only", options.only, "Run only these sets (indices, e.g. 3,13; the folder's plan stays the whole study)")->delimiter(',')->check(CLI::NonNegativeNumber);
        cmd->add_option("--hiding", options.hiding, "Run only the sets that hide this effect")->check(CLI::IsMember(effectIds()));
        cmd->add_flag("--generate-only", options.generateOnly,
                      "Only simulate the sets and keep them; a later run without it diagnoses the kept sets instead of simulating them again");
        cmd->add_flag("--score-only", scoreOnly, "Only score what OUT already holds");
        cmd->add_option("--pool", pool,
                        "Score these finished studies (folders) together into OUT, as one study of all their sets; runs no set. They must "
                        "share grid, gesture, units, generator, fixed rig values, parameter ranges and stated uncertainties, and OUT must be "
                        "none of them")
            ->check(CLI::ExistingDirectory)
            ->excludes("--only", "--hiding", "--generate-only", "--keep-sets", "--score-only");
        cmd->add_option("--compare-splits", compare,
                        "Set these finished studies of one plan, each diagnosed under another split (--diagnose-seed, --split-per-set), "
                        "side by side into OUT/splits.md and splits.json: the sets named alike under every split, each effect named "
                        "under every split, some or none, and each split's coverage; runs no set")
            ->check(CLI::ExistingDirectory)
            ->excludes("--pool", "--only", "--hiding", "--generate-only", "--keep-sets", "--score-only");
        cmd->add_flag("-q,--quiet", options.quiet, "No progress and no summary");
        return cmd;
    }

    int run()
    {
        options.rig = parseRigValues(rigValues);
        options.paramRanges = parseParamRanges(paramRanges);
        options.statedUncertainty = parseStatedUncertainties(statedUncertainties);
        if (!compare.empty()) {
            if (!Distributed::instance().isRoot()) return 0;
            const std::string summary = compareSplits(out, std::vector<std::filesystem::path>(compare.begin(), compare.end()));
            if (!options.quiet) std::printf("%s\nwrote %s/splits.md, splits.json\n", summary.c_str(), out.c_str());
            return 0;
        }
        if (!pool.empty()) {
            if (!Distributed::instance().isRoot()) return 0;
            const std::string summary = scoreStudies(out, std::vector<std::filesystem::path>(pool.begin(), pool.end()));
            if (!options.quiet) std::printf("%s\nwrote %s/study.csv, study.json, summary.md, study.png\n", summary.c_str(), out.c_str());
            return 0;
        }
        if (!scoreOnly) {
            Progress progress("study", !options.quiet && Distributed::instance().isRoot());
            runStudy(out, options, [&](const std::string&, double x) { progress.update(x); });
            progress.finish();
        }
        if (!Distributed::instance().isRoot()) return 0;
        if (options.generateOnly) {
            if (!options.quiet) std::printf("kept the sets in %s/sets; run again without --generate-only to diagnose them\n", out.c_str());
            return 0;
        }
        const std::string summary = scoreStudy(out);
        if (!options.quiet) std::printf("%s\nwrote %s/study.csv, study.json, summary.md, study.png\n", summary.c_str(), out.c_str());
        return 0;
    }
};

} // namespace

Command addStudyCommand(CLI::App& app)
{
    auto command = std::make_shared<StudyCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
