// `rosin bench`: the peer-benchmark protocol of shared/bench/peers (a held note rendered in
// blocks, timed per block, best pass reported as "RESULT name ns_per_sample rt_factor rms").
#pragma once
#include <string>

#include "rosin/dsp.h"

namespace rosin::lab {

struct BenchOptions {
    double seconds = 60.0, warmup = 0.5, sampleRate = 48000.0, frequency = 440.0;
    int block = 256, reps = 5;
    std::string name = "rosin";
    bool useFloat = true;
    dsp::BowedStringConfig config; ///< string (stopped to `frequency`), model and options
    double force = 0.4, speed = 0.2, beta = 0.1;
};

/// Runs the benchmark, prints the report on stdout; returns the process exit code.
int runBench(const BenchOptions& options);

/// Autocorrelation pitch estimate (Hz) of a steady tone; 0 when none is found.
double estimatePitch(const double* x, int n, double sampleRate, double fMin = 30.0, double fMax = 2000.0);

} // namespace rosin::lab
