// The `rosin` command: offline science on the bowed-string model. Each subcommand lives in
// cli/<Name>Command.cpp; this file only registers them and reports errors.
#include <cstdio>
#include <vector>

#include "cli/Cli.h"

using namespace rosin::cli;

int main(int argc, char** argv)
{
    CLI::App app{"rosin: bowed-string physics from rosin friction (Woodhouse, Euphonics 9.6).\n"
                 "Simulates bow strokes on a string with a chosen friction model and writes what a\n"
                 "researcher measures: the bridge force, and the bow-point velocity, friction force\n"
                 "and contact temperature behind it. All quantities are SI units."};
    app.require_subcommand(1);
    app.footer("Examples:\n"
               "  rosin render --force 1 --accel 1 --out stroke      Guettler stroke on the cello D\n"
               "  rosin render --gesture-file presets/gestures/demo-phrase.csv --listen --out phrase\n"
               "  rosin render --model enhanced --contact hertz --gesture constant --speed 0.1\n"
               "  rosin strings                                      list the string presets\n"
               "Run `rosin COMMAND --help` for each command's options.");

    const std::vector<Command> commands{addRenderCommand(app),   addStringsCommand(app),  addBenchCommand(app),
                                        addGuettlerCommand(app), addPanelCommand(app),    addClassifyCommand(app),
                                        addDiagnoseCommand(app), addSynthDataCommand(app), addFiguresCommand(app),
                                        addPlayabilityCommand(app), addStudyCommand(app)};

    if (argc > 1 && argv[1][0] != '-') {
        bool known = false;
        for (const CLI::App* sub : app.get_subcommands({})) known |= sub->get_name() == argv[1];
        if (!known) {
            std::fprintf(stderr, "rosin: unknown command '%s' (render, guettler, panel, classify, figures, synth-data, diagnose, strings, bench; see rosin --help)\n", argv[1]);
            return 2;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        for (const Command& c : commands)
            if (*c.app) return c.run();
    } catch (const LabError& e) {
        std::fprintf(stderr, "rosin: %s\n", e.what());
        return 2;
    } catch (const rosin::presets::PresetError& e) {
        std::fprintf(stderr, "rosin: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rosin: unexpected error: %s\n", e.what());
        return 3;
    }
    return 0;
}
