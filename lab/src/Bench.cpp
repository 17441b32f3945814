#include "rosin/lab/Bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace rosin::lab {

double estimatePitch(const double* x, int n, double sampleRate, double fMin, double fMax)
{
    const int lagMin = std::max(2, static_cast<int>(sampleRate / fMax));
    const int lagMax = std::min(n / 2 - 2, static_cast<int>(sampleRate / fMin));
    if (lagMax <= lagMin) return 0.0;
    double mean = 0.0;
    for (int i = 0; i < n; ++i) mean += x[i];
    mean /= n;
    std::vector<double> r(static_cast<std::size_t>(lagMax) + 2, 0.0);
    for (int lag = lagMin - 1; lag <= lagMax + 1; ++lag) {
        double s = 0.0;
        for (int i = 0; i + lag < n; ++i) s += (x[i] - mean) * (x[i + lag] - mean);
        r[lag] = s / (n - lag);
    }
    const double best = *std::max_element(r.begin() + lagMin, r.begin() + lagMax + 1);
    if (best <= 0.0) return 0.0;
    // The first strong peak: later peaks are multiples of the period.
    for (int lag = lagMin; lag <= lagMax; ++lag) {
        if (r[lag] >= r[lag - 1] && r[lag] >= r[lag + 1] && r[lag] > 0.8 * best) {
            const double a = r[lag - 1], b = r[lag], c = r[lag + 1];
            const double den = a - 2.0 * b + c;
            const double shift = den != 0.0 ? 0.5 * (a - c) / den : 0.0;
            return sampleRate / (lag + shift);
        }
    }
    return 0.0;
}

namespace {
template <typename T>
int run(const BenchOptions& o)
{
    dsp::BowedStringConfig config = o.config;
    config.string = config.string.stoppedAt(o.frequency);
    auto string = std::make_unique<dsp::BowedString<T>>();
    string->prepare(o.sampleRate, config);
    const int block = o.block;
    std::vector<T> force(block, T(o.force)), speed(block), beta(block, T(o.beta)), out(block);
    long long rendered = 0;
    const double rise = 0.05 * o.sampleRate; // bow speed ramps up over the first 50 ms
    // The controls are the caller's: filled before the clock starts, so only the model's block
    // call is timed (the peer protocol; the STK and Faust drivers time their render call alone).
    auto fillControls = [&](int n) {
        for (int i = 0; i < n; ++i) speed[i] = T(o.speed * std::min(1.0, double(rendered + i) / rise));
    };
    auto renderBlock = [&](int n) {
        string->processBlock(force.data(), speed.data(), beta.data(), out.data(), n);
        rendered += n;
    };
    const auto warm = static_cast<long long>(o.warmup * o.sampleRate);
    for (long long done = 0; done < warm; done += block) {
        fillControls(block);
        renderBlock(block);
    }

    const auto total = static_cast<long long>(o.seconds * o.sampleRate);
    std::vector<double> passSeconds;
    double sumsq = 0.0, peak = 0.0;
    long long timedSamples = 0;
    for (int rep = 0; rep < o.reps; ++rep) {
        double ns = 0.0;
        for (long long done = 0; done < total; done += block) {
            const int n = static_cast<int>(std::min<long long>(block, total - done));
            fillControls(n);
            const auto t0 = std::chrono::steady_clock::now();
            renderBlock(n);
            const auto t1 = std::chrono::steady_clock::now();
            ns += std::chrono::duration<double, std::nano>(t1 - t0).count();
            for (int i = 0; i < n; ++i) {
                sumsq += double(out[i]) * double(out[i]);
                peak = std::max(peak, std::abs(double(out[i])));
            }
            timedSamples += n;
        }
        passSeconds.push_back(ns * 1e-9);
    }
    std::vector<double> tail;
    while (tail.size() < 16384) {
        fillControls(block);
        renderBlock(block);
        tail.insert(tail.end(), out.begin(), out.end());
    }
    tail.resize(16384);
    const double f0 = estimatePitch(tail.data(), static_cast<int>(tail.size()), o.sampleRate);

    std::vector<double> sorted = passSeconds;
    std::sort(sorted.begin(), sorted.end());
    const double best = sorted.front();
    const double median = sorted.size() % 2 ? sorted[sorted.size() / 2]
                                            : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
    const double nsBest = best * 1e9 / double(total), nsMedian = median * 1e9 / double(total);
    const double passAudio = double(total) / o.sampleRate;
    const double rms = std::sqrt(sumsq / double(timedSamples));
    const char* model = config.friction.model == dsp::FrictionModel::Thermal ? "thermal"
                        : config.friction.model == dsp::FrictionModel::Enhanced ? "enhanced" : "friction-curve";
    std::printf("peer            : %s\n", o.name.c_str());
    std::printf("model           : %s, %s, torsion %s, string %s stopped to %.2f Hz\n", model,
                sizeof(T) == 4 ? "float" : "double", config.waveguide.torsion ? "on" : "off",
                o.config.string.name.c_str(), o.frequency);
    std::printf("sample rate     : %.0f Hz, block %d\n", o.sampleRate, block);
    std::printf("ns per sample   : best %.3f | median %.3f\n", nsBest, nsMedian);
    std::printf("real-time factor: %.1f x best (audio s / wall s, 1 voice, 1 core)\n", passAudio / best);
    std::printf("output rms      : %.6g N (peak %.6g N)\n", rms, peak);
    std::printf("f0 estimate     : %.2f Hz\n", f0);
    std::printf("RESULT %s %.3f %.1f %.6g\n", o.name.c_str(), nsBest, passAudio / best, rms);
    std::fflush(stdout);
    if (!(rms > 1e-6) || !std::isfinite(rms)) {
        std::fprintf(stderr, "rosin bench: the note was silent or not finite\n");
        return 1;
    }
    return 0;
}
} // namespace

int runBench(const BenchOptions& options)
{
    return options.useFloat ? run<float>(options) : run<double>(options);
}

} // namespace rosin::lab
