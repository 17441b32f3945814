// `rosin strings`.
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

/// Options of `rosin strings` (bound by add()) and what runs when it is chosen.
struct StringsCommand {
    std::string stringsPresets;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* stringsCmd = app.add_subcommand("strings", "List the string presets with their physical constants");
        stringsCmd->add_option("--presets", stringsPresets, "A presets folder searched before the others");
        return stringsCmd;
    }

    int run()
    {
        std::printf("%-16s %-5s %9s %7s %7s %9s %8s %8s\n", "id", "note", "f0 (Hz)", "L (m)", "T (N)", "m (g/m)",
                    "Z0 (kg/s)", "c (m/s)");
        presets::Library library = presets::Library::standard();
        if (!stringsPresets.empty()) library.addFolder(stringsPresets);
        for (const auto& p : presets::allStrings(library)) {
            const auto& q = p.params;
            std::printf("%-16s %-5s %9.2f %7.3f %7.1f %9.3f %8.3f %8.1f\n", p.id.c_str(), p.note.c_str(),
                        q.fundamental(), q.length, q.tension, 1e3 * q.massPerLength, q.impedance(), q.waveSpeed());
        }
        return 0;
    }
};

} // namespace

Command addStringsCommand(CLI::App& app)
{
    auto command = std::make_shared<StringsCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
