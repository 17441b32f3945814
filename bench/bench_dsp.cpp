// ns per sample of one bowed-string voice: each friction model, float and double, with and
// without torsion, at 48 kHz in 256-sample blocks (the plugin's path). Goals live in README.
#include <benchmark/benchmark.h>

#include <vector>

#include "rosin/dsp.h"

using namespace rosin::dsp;

template <typename T>
static void BM_Voice(benchmark::State& state)
{
    BowedStringConfig c;
    c.friction.model = static_cast<FrictionModel>(state.range(0));
    if (c.friction.model == FrictionModel::Enhanced) c.friction.fit = SteadyFit::WoodhouseGalluzzo;
    c.waveguide.torsion = state.range(1) != 0;
    c.string = c.string.stoppedAt(220.0);
    const double fs = 48000.0;
    const int block = 256;
    BowedString<T> s;
    s.prepare(fs, c);
    std::vector<T> force(block, T(0.5)), speed(block, T(0.1)), beta(block, T(0.1)), out(block);
    for (int i = 0; i < 200; ++i) s.processBlock(force.data(), speed.data(), beta.data(), out.data(), block); // into Helmholtz
    for (auto _ : state) {
        s.processBlock(force.data(), speed.data(), beta.data(), out.data(), block);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * block);
    state.counters["ns_per_sample"] =
        benchmark::Counter(static_cast<double>(state.iterations() * block), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

static void modelArgs(benchmark::internal::Benchmark* b)
{
    b->ArgNames({"model", "torsion"});
    for (int model : {0, 1, 2})
        for (int torsion : {0, 1}) b->Args({model, torsion});
}

BENCHMARK_TEMPLATE(BM_Voice, float)->Apply(modelArgs);
BENCHMARK_TEMPLATE(BM_Voice, double)->Apply(modelArgs);

static void BM_TemperatureLawBuild(benchmark::State& state)
{
    ThermalParams tp;
    for (auto _ : state) {
        TemperatureLaw law;
        law.build(SteadyFit::SmithWoodhouse, std::nullopt, tp);
        benchmark::DoNotOptimize(law);
    }
}
BENCHMARK(BM_TemperatureLawBuild)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
