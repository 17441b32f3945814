// `rosin panel`.
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

/// Options of `rosin panel` (bound by add()) and what runs when it is chosen.
struct PanelCommand {
    std::vector<std::string> panelFiles, panelTitles;
    std::string panelOut = "panel.png";
    int panelColumns = 2;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* panelCmd = app.add_subcommand("panel", "Lay out Guettler diagrams from earlier `rosin guettler` tables side by side");
        panelCmd->add_option("tables", panelFiles, "JSON tables written by rosin guettler")->required()->check(CLI::ExistingFile);
        panelCmd->add_option("--title", panelTitles, "Title per diagram, in order (default: the model)");
        panelCmd->add_option("--columns", panelColumns, "Diagrams per row")->check(CLI::Range(1, 8))->capture_default_str();
        panelCmd->add_option("-o,--out", panelOut, "PNG to write")->capture_default_str();
        return panelCmd;
    }

    int run()
    {
        std::vector<SweepResult> sweeps;
        for (const auto& f : panelFiles) sweeps.push_back(readSweepJson(f));
        OutputSet outputs;
        const fs::path tmp = outputs.add(panelOut);
        writePanelPng(tmp, sweeps, panelTitles, panelColumns, DiagramOptions{});
        outputs.commit();
        std::printf("wrote %s (%zu diagrams)\n", panelOut.c_str(), sweeps.size());
        return 0;
    }
};

} // namespace

Command addPanelCommand(CLI::App& app)
{
    auto command = std::make_shared<PanelCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
