// `rosin guettler`.
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

struct GuettlerCli {
    double aMin = 0.15, aMax = 3.0, fMin = 0.15, fMax = 3.0;
    int aCount = 20, fCount = 20, variants = 1;
    std::vector<double> betas{0.0899};
    std::uint64_t seed = 1;
    double sampleRate = 48000.0;
    std::string out = "guettler";
    bool noBounds = false, noFit = false, quiet = false;
};

int runGuettler(const ModelOptions& m, const GuettlerCli& g)
{
    SweepSpec spec;
    spec.config = m.build();
    spec.label = m.model + (m.model == "enhanced" ? " (" + m.speedFunction + ")" : "") + ", " +
                 (spec.config.friction.fit == dsp::SteadyFit::WoodhouseGalluzzo ? "WG" : "SW") + " fit, " + m.contact;
    spec.sampleRate = g.sampleRate;
    spec.accelerations = SweepSpec::grid(g.aMin, g.aMax, g.aCount);
    spec.forces = SweepSpec::grid(g.fMin, g.fMax, g.fCount);
    spec.betas = g.betas;
    spec.variants = g.variants;
    spec.seed = g.seed;
    const Distributed& dist = Distributed::instance();
    OutputSet outputs;
    fs::path csv, json, png;
    if (dist.isRoot()) {
        csv = outputs.add(g.out + ".csv");
        json = outputs.add(g.out + ".json");
        png = outputs.add(g.out + ".png");
    }
    Progress progress("sweep", !g.quiet && dist.isRoot());
    const SweepResult r = runSweep(spec, [&](double x) { progress.update(x); });
    progress.finish();
    if (!dist.isRoot()) return 0;
    writeSweepCsv(csv, r);
    writeSweepJson(json, r);
    DiagramOptions o;
    o.bounds = !g.noBounds;
    o.fit = !g.noFit;
    o.muS = dsp::steadySliding(spec.config.friction.fit, 0.0).mu;
    writeGuettlerPng(png, r, o);
    outputs.commit();
    if (!g.quiet) {
        const std::size_t cells = r.cells.size();
        std::printf("%s on %s: %d of %zu cells reach Helmholtz within 25 periods%s\n", spec.label.c_str(),
                    spec.config.string.name.c_str(), r.successCount(), cells,
                    g.variants > 1 ? (" (min over " + std::to_string(g.variants) + " variants)").c_str() : "");
        for (std::size_t ib = 0; ib < spec.betas.size(); ++ib) {
            const BoundaryFit fit = fitLowerBoundary(r, ib);
            if (fit.valid)
                std::printf("beta %.4g: lower boundary F = %.3f a^p, p = %.3f (95%% CI %.3f..%.3f, %zu columns)\n", spec.betas[ib],
                            fit.c, fit.p, fit.pLow, fit.pHigh, fit.accelerations.size());
            else
                std::printf("beta %.4g: too few boundary points for a fit\n", spec.betas[ib]);
        }
        std::printf("%.2f s wall, %.0f strokes/s, %.1f M samples/s on %d process(es); wrote %s.{csv,json,png}\n", r.wallSeconds,
                    double(cells * static_cast<std::size_t>(g.variants)) / r.wallSeconds, double(r.simulatedSamples) / r.wallSeconds / 1e6,
                    dist.size(), g.out.c_str());
    }
    return 0;
}

} // namespace

namespace {

/// Options of `rosin guettler` (bound by add()) and what runs when it is chosen.
struct GuettlerCommand {
    ModelOptions guettlerModel;
    GuettlerCli gcli;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* guettlerCmd = app.add_subcommand("guettler", "Guettler diagram: a constant-acceleration stroke from rest for every "
                                                               "(acceleration, force) cell, classified; table (CSV, JSON) and PNG");
        guettlerCmd->footer("Colours: light = Helmholtz soon after the first slip, dark = late (25 periods); blue double slip,\n"
                            "cyan double flyback, red irregular, black no slip; a dot marks S-motion. Dashed lines: Guettler's\n"
                            "lossless-string bounds; black curve: the fitted lower boundary F = c a^p.\n"
                            "Runs on all cores; under `mpirun -np N rosin guettler ...` the grid is split over N processes\n"
                            "and the table is identical to a single-process run.");
        guettlerModel.add(guettlerCmd);
        guettlerCmd->add_option("--accel-min", gcli.aMin, "Lowest acceleration (m/s^2)")->check(finiteIn(0.001, 100))->capture_default_str();
        guettlerCmd->add_option("--accel-max", gcli.aMax, "Highest acceleration (m/s^2)")->check(finiteIn(0.001, 100))->capture_default_str();
        guettlerCmd->add_option("--accel-count", gcli.aCount, "Accelerations")->check(CLI::Range(1, 400))->capture_default_str();
        guettlerCmd->add_option("--force-min", gcli.fMin, "Lowest bow force (N)")->check(finiteIn(0.001, 20))->capture_default_str();
        guettlerCmd->add_option("--force-max", gcli.fMax, "Highest bow force (N)")->check(finiteIn(0.001, 20))->capture_default_str();
        guettlerCmd->add_option("--force-count", gcli.fCount, "Forces")->check(CLI::Range(1, 400))->capture_default_str();
        guettlerCmd->add_option("--beta", gcli.betas, "Bow position(s); repeat for several diagrams")
            ->check(finiteIn(dsp::config::minBeta, dsp::config::maxBeta))
            ->capture_default_str();
        guettlerCmd->add_option("--variants", gcli.variants, "1 = plain; N = minimum transient over N perturbed runs (PHYSICS.md 6.7)")
            ->check(CLI::Range(1, 64))
            ->capture_default_str();
        guettlerCmd->add_option("--seed", gcli.seed, "Seed of the perturbations (results are deterministic per seed)")->capture_default_str();
        guettlerCmd->add_option("--sample-rate", gcli.sampleRate, "Simulation rate (Hz); 48 kHz is converged for maps (see README)")
            ->check(finiteIn(8000.0, 1.0e6))
            ->capture_default_str();
        guettlerCmd->add_option("-o,--out", gcli.out, "Output prefix: OUT.csv, OUT.json, OUT.png")->capture_default_str();
        guettlerCmd->add_flag("--no-bounds", gcli.noBounds, "Leave out Guettler's theoretical bounds");
        guettlerCmd->add_flag("--no-fit", gcli.noFit, "Leave out the fitted lower boundary");
        guettlerCmd->add_flag("-q,--quiet", gcli.quiet, "No progress and no summary");
        return guettlerCmd;
    }

    int run()
    {
        if (gcli.aMin > gcli.aMax) throw LabError("--accel-min must not exceed --accel-max");
        if (gcli.fMin > gcli.fMax) throw LabError("--force-min must not exceed --force-max");
        return runGuettler(guettlerModel, gcli);
    }
};

} // namespace

Command addGuettlerCommand(CLI::App& app)
{
    auto command = std::make_shared<GuettlerCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
