// `rosin bench`.
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

/// Options of `rosin bench` (bound by add()) and what runs when it is chosen.
struct BenchCommand {
    BenchOptions bench;
    ModelOptions benchModel;
    std::string precision = "float";

    CLI::App* add(CLI::App& app)
    {
        CLI::App* benchCmd = app.add_subcommand("bench", "Time one held note (the shared/bench/peers protocol): prints "
                                                         "RESULT name ns_per_sample rt_factor rms");
        benchModel.string = "violin-A";
        benchModel.add(benchCmd);
        benchCmd->add_option("--seconds", bench.seconds, "Audio seconds per timed pass")->check(finiteIn(0.01, 3600.0))->capture_default_str();
        benchCmd->add_option("--warmup", bench.warmup, "Untimed seconds before timing")->check(finiteIn(0.0, 60.0))->capture_default_str();
        benchCmd->add_option("--sr", bench.sampleRate, "Sample rate (Hz)")->check(finiteIn(8000.0, 1.0e6))->capture_default_str();
        benchCmd->add_option("--block", bench.block, "Block size")->check(CLI::Range(1, 65536))->capture_default_str();
        benchCmd->add_option("--reps", bench.reps, "Timed passes (best is reported)")->check(CLI::Range(1, 1000))->capture_default_str();
        benchCmd->add_option("--name", bench.name, "Name in the RESULT line")->capture_default_str();
        benchCmd->add_option("--freq", bench.frequency, "Pitch of the held note (Hz): the string is stopped to it")
            ->check(finiteIn(20.0, 4000.0))
            ->capture_default_str();
        benchCmd->add_option("--precision", precision, "float (plugin voice) or double (research)")
            ->check(CLI::IsMember({"float", "double"}))
            ->capture_default_str();
        return benchCmd;
    }

    int run()
    {
        bench.config = benchModel.build();
        bench.useFloat = precision == "float";
        return runBench(bench);
    }
};

} // namespace

Command addBenchCommand(CLI::App& app)
{
    auto command = std::make_shared<BenchCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
