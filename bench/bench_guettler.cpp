// Guettler sweeps: strokes per second and simulated samples per second for each model, on one
// core and on all cores (10x10 grid at the 48 kHz sweep rate, one variant).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include "rosin/lab/Guettler.h"

using namespace rosin;
using namespace rosin::lab;

static void BM_GuettlerSweep(benchmark::State& state)
{
    SweepSpec s;
    s.config.friction.model = static_cast<dsp::FrictionModel>(state.range(0));
    s.config.friction.fit = dsp::SteadyFit::WoodhouseGalluzzo;
    s.accelerations = SweepSpec::grid(0.15, 3.0, 10);
    s.forces = SweepSpec::grid(0.15, 3.0, 10);
    const int threads = static_cast<int>(state.range(1));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads > 0 ? threads : tbb::info::default_concurrency());
    long long strokes = 0, samples = 0;
    for (auto _ : state) {
        const SweepResult r = runSweep(s);
        strokes += static_cast<long long>(r.cells.size());
        samples += r.simulatedSamples;
        benchmark::DoNotOptimize(r.cells.data());
    }
    state.counters["strokes_per_s"] = benchmark::Counter(static_cast<double>(strokes), benchmark::Counter::kIsRate);
    state.counters["Msamples_per_s"] = benchmark::Counter(static_cast<double>(samples) / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GuettlerSweep)
    ->ArgNames({"model", "threads"})
    ->Args({0, 1})->Args({1, 1})->Args({2, 1})
    ->Args({0, 0})->Args({1, 0})->Args({2, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
