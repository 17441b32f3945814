// The instrument engine as the plugin runs it (voices, body, mixing): ns per sample per voice
// and how many voices fit in real time on one core at 48 kHz. The same path through the built
// VST3/LV2 wrappers is timed by `rosin-host bench` (README, Benchmarks).
#include <benchmark/benchmark.h>

#include <vector>

#include "rosin/engine/Synth.h"

using namespace rosin::engine;

static void BM_SynthVoices(benchmark::State& state)
{
    const int voices = static_cast<int>(state.range(0));
    const int model = static_cast<int>(state.range(1));
    const double fs = 48000.0;
    ParamValues p = defaultParams();
    p[static_cast<int>(Param::FrictionModel)] = static_cast<float>(model);
    Synth synth;
    synth.prepare(fs, rosin::presets::loadInstrument(rosin::presets::Library(), "violin"), p);
    for (int v = 0; v < voices; ++v) {
        const std::uint8_t on[3] = {0x90, static_cast<std::uint8_t>(79 - 3 * v), 100};
        synth.handleMidi(on, 3);
    }
    constexpr int block = 256;
    std::vector<float> l(block), r(block);
    for (int i = 0; i < 100; ++i) synth.render(l.data(), r.data(), block); // past the attack
    for (auto _ : state) {
        synth.render(l.data(), r.data(), block);
        benchmark::DoNotOptimize(l.data());
        benchmark::ClobberMemory();
    }
    const double samples = static_cast<double>(state.iterations()) * block;
    state.counters["ns_per_sample_per_voice"] = benchmark::Counter(samples * voices, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["voices_realtime_48k"] = benchmark::Counter(samples * voices / fs, benchmark::Counter::kIsRate);
    state.SetLabel(model == 0 ? "friction curve" : model == 1 ? "thermal" : "enhanced");
}
BENCHMARK(BM_SynthVoices)->ArgsProduct({{1, 4, 16}, {0, 1, 2}})->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
