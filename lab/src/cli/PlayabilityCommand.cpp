// `rosin playability`: the editor's playability map for one string and model, as a figure.
#include "Cli.h"

#include <cstdio>
#include <memory>

#include "rosin/lab/Output.h"
#include "rosin/lab/ViewFigures.h"

namespace rosin::cli {

namespace {

struct PlayabilityCommand {
    ModelOptions model;
    std::string kind = "schelleng", out = "playability";
    double force = 1.0, speed = 0.1, beta = 0.0899, accel = 1.27, frequency = 0.0, sampleRate = 48000.0;
    int columns = 16, rows = 14;
    bool quiet = false;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* cmd = app.add_subcommand("playability", "Map where the bow gives Helmholtz motion on one string: "
                                                          "Schelleng (beta vs force) or Guettler (acceleration vs force)");
        cmd->footer("The same map the plugin window computes in the background. Schelleng: steady bowing at\n"
                    "--speed, judged after 1 s (Helmholtz = one regular slip per period). Guettler: strokes\n"
                    "from rest at constant acceleration, classified like `rosin guettler` (light = short\n"
                    "transient). Axes are set around --force. Writes OUT.png and OUT.csv.");
        model.add(cmd);
        cmd->add_option("--kind", kind, "schelleng or guettler")->check(CLI::IsMember({"schelleng", "guettler"}))->capture_default_str();
        cmd->add_option("--force", force, "Nominal bow force the axes are set around (N)")->check(finiteIn(0.02, 10.0))->capture_default_str();
        cmd->add_option("--speed", speed, "Schelleng: bow speed (m/s)")->check(finiteIn(0.005, 2.0))->capture_default_str();
        cmd->add_option("--beta", beta, "Guettler: bow position")->check(finiteIn(0.02, 0.3))->capture_default_str();
        cmd->add_option("--accel", accel, "Guettler: the attack's acceleration the axis is set around (m/s^2)")->check(finiteIn(0.1, 40.0))->capture_default_str();
        cmd->add_option("--frequency", frequency, "Stop the string at this pitch (Hz); 0 = open string")->check(finiteIn(0.0, 5000.0));
        cmd->add_option("--columns", columns, "Cells across")->check(CLI::Range(2, 64))->capture_default_str();
        cmd->add_option("--rows", rows, "Cells up (forces)")->check(CLI::Range(2, 64))->capture_default_str();
        cmd->add_option("--sample-rate", sampleRate, "Simulation rate (Hz)")->check(finiteIn(8000.0, 384000.0))->capture_default_str();
        cmd->add_option("-o,--out", out, "Output prefix: OUT.png and OUT.csv")->capture_default_str();
        cmd->add_flag("-q,--quiet", quiet, "No progress and no summary");
        return cmd;
    }

    int run()
    {
        const MapKind k = kind == "schelleng" ? MapKind::Schelleng : MapKind::Guettler;
        PlayabilitySpec spec = PlayabilitySpec::around(k, model.build(), force, speed, beta, accel, frequency, columns, rows);
        spec.sampleRate = sampleRate;
        OutputSet outputs;
        const fs::path png = outputs.add(out + ".png"), csv = outputs.add(out + ".csv");
        Progress progress("playability", !quiet);
        const PlayabilityMap map = computePlayability(spec, nullptr, [&](const PlayabilityMap& m) {
            progress.update(static_cast<double>(m.completed()) / static_cast<double>(m.cells.size()));
        });
        progress.finish();
        writePlayabilityPng(png, map, {});
        writePlayabilityCsv(csv, map);
        outputs.commit();
        if (!quiet) {
            std::size_t ok = 0;
            for (const auto& c : map.cells) ok += c.success ? 1 : 0;
            std::printf("%s map of %s at %.1f Hz: %zu of %zu cells in Helmholtz motion\nwrote %s.png and %s.csv\n",
                        mapKindName(k), spec.config.string.name.c_str(), map.f0, ok, map.cells.size(), out.c_str(), out.c_str());
        }
        return 0;
    }
};

} // namespace

Command addPlayabilityCommand(CLI::App& app)
{
    auto command = std::make_shared<PlayabilityCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
