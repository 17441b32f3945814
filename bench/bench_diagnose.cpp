// `rosin diagnose` on a 12x12 Guettler set from the reference simulator, nuisances fitted
// (issue 20's goal: at most 60 s wall on 2 cores). The set is made once, written to disk and
// read back as the CLI would; each iteration is a whole diagnosis, so one iteration is timed.
#include <benchmark/benchmark.h>
#include <sndfile.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>

#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/ReferenceData.h"

using namespace rosin::lab;
namespace fs = std::filesystem;

namespace {

constexpr double kGoalSeconds = 60.0;

/// A 12x12 reference set with every rig imperfection (gain, DC, hum, noise, trigger), hiding
/// `effect` ("" = a null set), made once per effect and kept for every benchmark that uses it.
const MeasurementSet& referenceSet(const std::string& effect)
{
    static std::map<std::string, MeasurementSet> made;
    if (auto it = made.find(effect); it != made.end()) return it->second;
    SynthSpec spec;
    spec.generator = "reference";
    spec.grid = 12;
    spec.seed = 2020;
    if (!effect.empty()) spec.effects = {effect};
    SynthTruth truth;
    const fs::path dir = fs::temp_directory_path() / ("rosin-bench-diagnose-" + std::to_string(::getpid()) + "-" + effect);
    fs::remove_all(dir);
    writeMeasurementSet(dir, synthesize(spec, truth), SF_FORMAT_PCM_24);
    MeasurementSet set = readMeasurementSet(dir);
    fs::remove_all(dir);
    return made.emplace(effect, std::move(set)).first->second;
}

void BM_Diagnose12x12(benchmark::State& state, const std::string& effect, bool secondStart)
{
    const MeasurementSet& set = referenceSet(effect);
    const int threads = static_cast<int>(state.range(0));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads > 0 ? threads : tbb::info::default_concurrency());
    DiagnoseOptions options;
    options.fitNuisances = true;
    options.quiet = true;
    options.secondStart = secondStart; // --second-start: what it costs against the same goal
    long long simulations = 0;
    double seconds = 0;
    for (auto _ : state) {
        const Diagnosis d = diagnose(set, options);
        simulations += d.simulations;
        seconds += d.seconds;
        benchmark::DoNotOptimize(d.findings.data());
    }
    const double perDiagnosis = seconds / static_cast<double>(state.iterations());
    state.counters["strokes"] = static_cast<double>(set.strokes.size());
    state.counters["simulations_per_s"] = benchmark::Counter(static_cast<double>(simulations), benchmark::Counter::kIsRate);
    state.counters["goal_s"] = kGoalSeconds;
    state.counters["within_goal"] = perDiagnosis <= kGoalSeconds ? 1.0 : 0.0;
}

} // namespace

BENCHMARK_CAPTURE(BM_Diagnose12x12, null_set, std::string(), false)
    ->ArgName("threads")->Arg(2)->Arg(0)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Diagnose12x12, thermal_set, std::string("thermal_memory"), false)
    ->ArgName("threads")->Arg(2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Diagnose12x12, thermal_set_second_start, std::string("thermal_memory"), true)
    ->ArgName("threads")->Arg(2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

BENCHMARK_MAIN();
