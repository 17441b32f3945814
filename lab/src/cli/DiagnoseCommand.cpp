// `rosin diagnose`.
#include "Cli.h"

#include <sndfile.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "rosin/lab/Bench.h"
#include "rosin/lab/Classifier.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Distributed.h"
#include "rosin/lab/FigureSet.h"
#include "rosin/lab/Figures.h"
#include "rosin/lab/Gesture.h"
#include "rosin/lab/Guettler.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/Output.h"
#include "rosin/lab/Render.h"
#include "rosin/lab/Signal.h"
#include "rosin/lab/SynthData.h"

namespace rosin::cli {

namespace {

/// "r_A=0.064, p=0.073, ...": the shipped defaults, so the help never goes stale.
std::string defaultDiscrepancyText()
{
    std::string text;
    const DiagnoseOptions defaults;
    for (const auto* table : {&defaults.modelDiscrepancy, &defaults.calibrationDiscrepancy})
        for (const auto& [name, sd] : *table) {
            char value[32];
            std::snprintf(value, sizeof value, "%g", sd);
            text += (text.empty() ? "" : ", ") + name + "=" + value;
        }
    return text;
}

/// Options of `rosin diagnose` (bound by add()) and what runs when it is chosen.
struct DiagnoseCommand {
    std::string diagSet, diagOut = "diagnosis";
    DiagnoseOptions diagOptions;
    std::vector<std::string> discrepancy;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* diagnoseCmd = app.add_subcommand("diagnose", "Compare a measurement set with the model, name what it gets wrong, "
                                                               "extend it, and measure the gain on held-out strokes");
        diagnoseCmd->footer("Writes OUT/diagnosis.json (format in docs/diagnosis.md), OUT/report.md and its figures\n"
                            "(maps.png, overlays.png, jumps.png). A broken set is refused before anything is written.");
        diagnoseCmd->add_option("set", diagSet, "Measurement set folder (rosin-measurement/1)")->required();
        diagnoseCmd->add_option("-o,--out", diagOut, "New output folder")->capture_default_str();
        diagnoseCmd->add_option("--seed", diagOptions.seed, "Seed of the fit/held-out split and the bootstraps")->capture_default_str();
        diagnoseCmd->add_option("--sim-rate", diagOptions.simRate, "Simulation rate (Hz)")->check(finiteIn(16000, 400000))->capture_default_str();
        diagnoseCmd->add_option("--max-evaluations", diagOptions.maxEvaluations, "Model evaluations per candidate fit")->check(CLI::Range(5, 500))->capture_default_str();
        diagnoseCmd->add_option("--naming-threshold", diagOptions.namingThreshold, "Least validation-error fall (share) of a named effect")->check(finiteIn(0, 1))->capture_default_str();
        diagnoseCmd->add_option("--residual-factor", diagOptions.residualFactor, "Final error above this many floors: unexplained residual")->check(finiteIn(1, 100))->capture_default_str();
        diagnoseCmd->add_option("--usual-residual", diagOptions.usualResidualRatio,
                                "Final error over floor that the model leaves on the study's reference rigs with nothing hidden: a residual "
                                "above it is reported as more than the usual difference (0 = no comparison)")
            ->check(finiteIn(0, 1000))
            ->capture_default_str();
        diagnoseCmd->add_option("--shift-margin", diagOptions.shiftOverRateMargin,
                                "Least validation-error fall (share) of a rosin shift below the rate dependence fitted in the same round "
                                "(the naming threshold when smaller)")
            ->check(finiteIn(0, 1))
            ->capture_default_str();
        diagnoseCmd->add_option("--model-discrepancy", discrepancy,
                                "NAME=SD: the model's own error for parameter NAME (r_A and zt_ratio relative, others absolute; 0 = none) or for a "
                                "calibrated nuisance (tension_scale, beta_scale, rod_effusivity_scale: scales), "
                                "instead of the study-calibrated default (" + defaultDiscrepancyText() + ")");
        addSearchFlags(*diagnoseCmd, diagOptions);
        diagnoseCmd->add_flag("!--no-nuisances", diagOptions.fitNuisances, "Do not fit tension, bow position and the bow side's thermal effusivity as calibration");
        diagnoseCmd->add_flag("-q,--quiet", diagOptions.quiet, "No progress and no summary");
        return diagnoseCmd;
    }

    int run()
    {
        for (const std::string& item : discrepancy) {
            const auto eq = item.find('=');
            const std::string name = item.substr(0, eq);
            const double sd = eq != std::string::npos ? wholeNumber(item.substr(eq + 1)).value_or(std::nan("")) : std::nan("");
            const bool nuisance = diagOptions.calibrationDiscrepancy.count(name) > 0;
            if ((effectOfParameter(name) == "calibration" && !nuisance) || !std::isfinite(sd) || sd < 0.0 || sd > 10.0) // neither a finding's parameter nor a nuisance
                throw LabError("--model-discrepancy " + item + ": expected NAME=SD with NAME one of r_A, h0, p, load_exponent, shift_k, zt_ratio, "
                               "tension_scale, beta_scale, rod_effusivity_scale and SD from 0 to 10");
            (nuisance ? diagOptions.calibrationDiscrepancy : diagOptions.modelDiscrepancy)[name] = sd;
        }
        if (fs::exists(diagOut)) throw LabError(diagOut + ": already exists (choose a new folder)");
        const MeasurementSet set = readMeasurementSet(diagSet);
        Progress progress("diagnosing", !diagOptions.quiet);
        const Diagnosis dg = diagnose(set, diagOptions, [&](const std::string&, double x) { progress.update(x); });
        progress.finish();
        std::string hidden = ".";
        hidden += fs::path(diagOut).filename().string();
        hidden += ".partial";
        const fs::path tmp = (fs::path(diagOut).has_parent_path() ? fs::path(diagOut).parent_path() : fs::path(".")) / hidden;
        fs::remove_all(tmp);
        try {
            writeDiagnosis(tmp, dg, diagOptions);
            fs::rename(tmp, diagOut);
        } catch (...) {
            std::error_code ec;
            fs::remove_all(tmp, ec);
            throw;
        }
        if (!diagOptions.quiet) {
            for (const auto& w : dg.warnings) std::printf("warning: %s\n", w.c_str());
            for (const auto& t : dg.trials) {
                std::printf("round %d: %-24s", t.round, t.effect.c_str());
                for (const auto& [k, v] : t.parameters) std::printf(" %s=%.3g", k.c_str(), v);
                std::printf("  validation fall %.3f [%.3f, %.3f]: %s\n", t.gain, t.gainLow, t.gainHigh, t.verdict.c_str());
            }
            for (const auto& c : dg.calibration) std::printf("calibration: %s = %.4g [%.4g, %.4g]\n", c.name.c_str(), c.value, c.low, c.high);
            if (dg.findings.empty())
                std::printf(dg.residual.present ? "finding: none named, but an unexplained residual (%.1f x the floor)\n"
                                                : "finding: none (the calibrated baseline is within %.1f x the floor)\n", dg.residual.ratio);
            if (dg.residual.present) std::printf("unexplained residual at %s: %s\n", dg.residual.where.c_str(), dg.residual.looksLike.c_str());
            for (const auto& f : dg.findings) {
                std::printf("finding: %s", f.effect.c_str());
                for (const auto& [name, v] : f.parameters) std::printf("  %s = %.3g [%.3g, %.3g]", name.c_str(), v[0], v[1], v[2]);
                std::printf("\n  %s\n", f.evidence.c_str());
            }
            std::printf("test error %.3f -> %.3f (gain %.0f %%, CI %.0f..%.0f %%); %lld simulations in %.1f s; wrote %s/\n",
                        dg.baselineError, dg.finalError, 100 * dg.relativeGain, 100 * dg.gainLow, 100 * dg.gainHigh,
                        dg.simulations, dg.seconds, diagOut.c_str());
        }
        return 0;
    }
};

} // namespace

Command addDiagnoseCommand(CLI::App& app)
{
    auto command = std::make_shared<DiagnoseCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
