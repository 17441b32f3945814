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
#include "rosin/engine/Synth.h"

#include <algorithm>
#include <chrono>
#include <vector>

namespace rosin::cli {

namespace {

/// `rosin bench --instrument NAME --voices N`: the instrument engine as the plugin runs it (voices
/// on the fast path, body, mixing), N notes held, timed per block like the peer drivers. The
/// RESULT line gives ns per voice-sample, so one voice compares with one STK Bowed instance.
int benchInstrument(const BenchOptions& o, const std::string& instrument, int voices)
{
    const presets::InstrumentPreset preset = presets::loadInstrument(presets::Library::standard(), instrument);
    engine::ParamValues p = engine::defaultParams();
    p[static_cast<int>(engine::Param::BowForce)] = static_cast<float>(preset.bowForce);
    p[static_cast<int>(engine::Param::BowSpeed)] = static_cast<float>(preset.bowSpeed);
    p[static_cast<int>(engine::Param::BowPosition)] = static_cast<float>(preset.bowPosition);
    p[static_cast<int>(engine::Param::AttackAccel)] = static_cast<float>(preset.attackAccel);
    p[static_cast<int>(engine::Param::RosinTg)] = static_cast<float>(preset.rosinTg);
    auto synth = std::make_unique<engine::Synth>();
    synth->prepare(o.sampleRate, preset, p);
    // One voice plays --freq; a chord spreads its notes over two octaves from the lowest open string.
    const int root = static_cast<int>(std::lround(69.0 + 12.0 * std::log2(o.frequency / 440.0)));
    const int lowest = static_cast<int>(std::lround(69.0 + 12.0 * std::log2(preset.strings[0].fundamental() / preset.tuningA4)));
    for (int v = 0; v < voices; ++v) {
        const int note = voices == 1 ? root : lowest + v * 24 / voices;
        const std::uint8_t on[3] = {0x90, static_cast<std::uint8_t>(std::clamp(note, 0, 127)), 100};
        synth->handleMidi(on, 3);
    }
    std::vector<float> l(static_cast<std::size_t>(o.block)), r(static_cast<std::size_t>(o.block));
    for (long long done = 0; done < static_cast<long long>(o.warmup * o.sampleRate); done += o.block) synth->render(l.data(), r.data(), o.block);
    const auto total = static_cast<long long>(o.seconds * o.sampleRate);
    std::vector<double> passes;
    double sumsq = 0.0;
    long long counted = 0;
    for (int rep = 0; rep < o.reps; ++rep) {
        double ns = 0.0;
        for (long long done = 0; done < total; done += o.block) {
            const int n = static_cast<int>(std::min<long long>(o.block, total - done));
            const auto t0 = std::chrono::steady_clock::now();
            synth->render(l.data(), r.data(), n);
            ns += std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
            for (int i = 0; i < n; ++i) sumsq += static_cast<double>(l[static_cast<std::size_t>(i)]) * l[static_cast<std::size_t>(i)];
            counted += n;
        }
        passes.push_back(ns / static_cast<double>(total));
    }
    std::sort(passes.begin(), passes.end());
    const double perSample = passes.front(), perVoice = perSample / voices;
    const int sounding = synth->activeVoiceCount();
    std::fprintf(stderr, "%s, %d voice(s) (%d sounding), thermal model, body on, %.0f Hz, block %d: best %.1f ns per output sample "
                         "(median %.1f), %.1f ns per voice-sample\n",
                 instrument.c_str(), voices, sounding, o.sampleRate, o.block, perSample, passes[passes.size() / 2], perVoice);
    std::printf("RESULT %s %.3f %.1f %.6g\n", o.name.c_str(), perVoice, 1e9 / o.sampleRate / perVoice, std::sqrt(sumsq / std::max(1LL, counted)));
    return sounding == voices ? 0 : 1;
}

/// Options of `rosin bench` (bound by add()) and what runs when it is chosen.
struct BenchCommand {
    BenchOptions bench;
    ModelOptions benchModel;
    std::string precision = "float", instrument;
    int voices = 1;

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
        benchCmd->add_option("--instrument", instrument, "Time the instrument engine (voices, body, mixing) with this preset instead of one string");
        benchCmd->add_option("--voices", voices, "Notes held at once with --instrument (RESULT then gives ns per voice-sample)")->check(CLI::Range(1, 16));
        return benchCmd;
    }

    int run()
    {
        if (!instrument.empty()) return benchInstrument(bench, instrument, voices);
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
