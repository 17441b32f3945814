// `rosin synth-data`.
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
#include "rosin/lab/ReferenceData.h"
#include "rosin/lab/Render.h"
#include "rosin/lab/Signal.h"
#include "rosin/lab/SynthData.h"

namespace rosin::cli {

namespace {

/// Options of `rosin synth-data` (bound by add()) and what runs when it is chosen.
struct SynthDataCommand {
    SynthSpec synth;
    std::string synthOut = "set", wavKind = "pcm24";
    std::vector<std::string> synthParams, rigParams, statedUncertainties;
    bool synthQuiet = false;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* synthCmd = app.add_subcommand("synth-data", "Write a measurement set (rosin-measurement/1) simulated with hidden "
                                                              "effects and a real rig's artefacts");
        std::string rigKeys;
        for (const auto& p : referenceRigPriors()) rigKeys += "  " + p.key + ": " + p.meaning + "\n";
        synthCmd->footer("Effects (docs/diagnosis.md): thermal_memory, rate_dependence, hertzian_contact,\n"
                         "rosin_temperature_shift, torsional_compliance; none given = the baseline (friction curve,\n"
                         "Amontons, no torsion, reference rosin). Their parameters are drawn from the seed unless\n"
                         "given, and written with the gain to OUT.truth.json beside the set, never inside it.\n"
                         "--generator model: dsp/'s own model makes the data (a consistency check).\n"
                         "--generator reference: the reference simulator (finite-difference stiff string, bridge\n"
                         "resonances, exact-kernel heat) on a rig drawn from the seed; --rig-param fixes a value:\n" + rigKeys +
                         "--generator model-on-rig: the same draws as reference (effects, rig, sensor, hum, noise,\n"
                         "gain), but dsp/'s model makes the strokes on the rig's tension, bow position, rosin curve\n"
                         "and bow-side effusivity, everything else at the model's own values: the diagnosis's ceiling.\n");
        synthCmd->add_option("--generator", synth.generator, "model, reference or model-on-rig")
            ->check(CLI::IsMember({"model", "reference", "model-on-rig"}))
            ->capture_default_str();
        synthCmd->add_option("--rig-param", rigParams, "Reference rig value NAME=VALUE instead of a drawn one (see below)");
        synthCmd->add_option("--stated-uncertainty", statedUncertainties,
                             "Reference: a lab that measured its rig, NAME=FRACTION (tension, beta): the rig's error is drawn within "
                             "+-FRACTION and the manifest states it; q: the manifest states the string's Q at f0 and 5 kHz within "
                             "+-FRACTION of the rig's; torsion: its c_t / c and torsional Q likewise");
        synthCmd->add_option("--oversampling", synth.oversampling, "Reference: simulation rate / file rate")->check(CLI::Range(4, 32))->capture_default_str();
        synthCmd->add_option("--gesture", synth.gesture, "Reference: guettler, exp_speed (v0/tv x F), exp_force (speed x F0) or mixed")
            ->check(CLI::IsMember({"guettler", "exp_speed", "exp_force", "mixed"}))->capture_default_str();
        synthCmd->add_option("-o,--out", synthOut, "New folder for the set (must not exist)")->capture_default_str();
        synthCmd->add_option("--effect", synth.effects, "Hidden effect; repeat for several")->check(CLI::IsMember(effectIds()));
        synthCmd->add_option("--param", synthParams, "Hidden parameter NAME=VALUE (r_A, h0, p, load_exponent, shift_k, zt_ratio)");
        synthCmd->add_option("--seed", synth.seed, "Seed of parameters, jitter and artefacts")->capture_default_str();
        synthCmd->add_option("--grid", synth.grid, "Strokes per axis of the Guettler grid")->check(CLI::Range(2, 60))->capture_default_str();
        synthCmd->add_option("--rate", synth.outRate, "Sample rate of the files (Hz)")->check(finiteIn(8000, 384000))->capture_default_str();
        synthCmd->add_option("--sim-rate", synth.simRate, "Rate of the simulation behind them (Hz)")->check(finiteIn(8000, 1e6))->capture_default_str();
        synthCmd->add_option("--units", synth.units, "V (unknown gain) or N (calibrated)")->check(CLI::IsMember({"V", "N"}))->capture_default_str();
        synthCmd->add_option("--noise", synth.noise, "White noise (N rms)")->check(finiteIn(0, 1))->capture_default_str();
        synthCmd->add_option("--hum", synth.humHz, "Mains frequency (Hz; 0 = no hum)")->check(CLI::IsMember({"0", "50", "60"}))->capture_default_str();
        synthCmd->add_option("--hum-level", synth.humLevel, "Hum amplitude (N)")->check(finiteIn(0, 1))->capture_default_str();
        synthCmd->add_option("--dc", synth.dcLevel, "DC offset (N)")->check(finiteIn(-10, 10))->capture_default_str();
        synthCmd->add_option("--trigger-max", synth.triggerMax, "Gesture starts up to this late in each file (s)")->check(finiteIn(0, 1))->capture_default_str();
        synthCmd->add_option("--jitter", synth.jitter, "Per-stroke relative jitter of force and acceleration")->check(finiteIn(0, 0.2))->capture_default_str();
        synthCmd->add_option("--wav", wavKind, "Sample format: pcm16, pcm24, pcm32, float, double")
            ->check(CLI::IsMember({"pcm16", "pcm24", "pcm32", "float", "double"}))
            ->capture_default_str();
        synthCmd->add_flag("--gaussian-reflections", synth.gaussianReflections, "Simulate with MSW83 Gaussian-pulse reflections");
        synthCmd->add_option("--two-ended", synth.twoEnded, "Steady strokes recorded at both string ends")->check(CLI::Range(0, 20))->capture_default_str();
        synthCmd->add_flag("-q,--quiet", synthQuiet, "No progress and no summary");
        return synthCmd;
    }

    int run()
    {
        for (const auto& kv : synthParams) {
            const auto eq = kv.find('=');
            if (eq == std::string::npos) throw LabError("--param: expected NAME=VALUE, got '" + kv + "'");
            const std::string key = kv.substr(0, eq);
            if (key != "r_A" && key != "load_exponent" && key != "shift_k" && key != "zt_ratio" && key != "h0" && key != "p")
                throw LabError("--param: unknown parameter '" + key + "'");
            const std::optional<double> value = wholeNumber(kv.substr(eq + 1));
            if (!value) throw LabError("--param: '" + kv + "' has no number");
            synth.params[key] = *value;
        }
        synth.rig = parseRigValues(rigParams);
        synth.statedUncertainty = parseStatedUncertainties(statedUncertainties);
        if (fs::exists(synthOut)) throw LabError(synthOut + ": already exists (choose a new folder)");
        const std::map<std::string, int> formats{{"pcm16", SF_FORMAT_PCM_16}, {"pcm24", SF_FORMAT_PCM_24},
                                                 {"pcm32", SF_FORMAT_PCM_32}, {"float", SF_FORMAT_FLOAT},
                                                 {"double", SF_FORMAT_DOUBLE}};
        Progress progress("synthesising", !synthQuiet);
        SynthTruth truth;
        const MeasurementSet set = synthesize(synth, truth, [&](double x) { progress.update(x); });
        progress.finish();
        OutputSet outputs;
        const fs::path truthTmp = outputs.add(synthOut + ".truth.json");
        writeTruth(truthTmp, truth, synth.seed);
        writeMeasurementSet(synthOut, set, formats.at(wavKind));
        outputs.commit();
        if (!synthQuiet)
            std::printf("wrote %s (%zu strokes at %.0f Hz, units %s) and %s.truth.json\n", synthOut.c_str(), set.strokes.size(),
                        set.sampleRate, set.units.c_str(), synthOut.c_str());
        return 0;
    }
};

} // namespace

Command addSynthDataCommand(CLI::App& app)
{
    auto command = std::make_shared<SynthDataCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
