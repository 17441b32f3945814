// `rosin figures`.
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

/// Options of `rosin figures` (bound by add()) and what runs when it is chosen.
struct FiguresCommand {
    FigureSetOptions figOptions;
    std::string figDir = "figures";

    CLI::App* add(CLI::App& app)
    {
        CLI::App* figuresCmd = app.add_subcommand("figures", "Regenerate the Euphonics 9.6 figure set from scratch (PNG + CSV/JSON)");
        figuresCmd->add_option("-o,--out", figDir, "Output directory")->capture_default_str();
        figuresCmd->add_option("--sample-rate", figOptions.sweepRate, "Rate of the Guettler sweeps (Hz)")->check(finiteIn(8000.0, 1.0e6))->capture_default_str();
        figuresCmd->add_option("--variants", figOptions.variants, "Variants of the min-over-N maps")->check(CLI::Range(2, 64))->capture_default_str();
        figuresCmd->add_option("--grid", figOptions.grid, "Cells per axis")->check(CLI::Range(5, 100))->capture_default_str();
        figuresCmd->add_option("--seed", figOptions.seed, "Perturbation seed")->capture_default_str();
        figuresCmd->add_flag("-q,--quiet", figOptions.quiet, "No progress and no summary");
        return figuresCmd;
    }

    int run()
    {
        const std::string report = writeFigureSet(figDir, figOptions);
        if (!figOptions.quiet) std::printf("%s", report.c_str());
        return 0;
    }
};

} // namespace

Command addFiguresCommand(CLI::App& app)
{
    auto command = std::make_shared<FiguresCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
