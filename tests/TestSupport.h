// Helpers shared by the dsp tests: run a string with a control trajectory, find slips.
#pragma once
#include <cmath>
#include <functional>
#include <vector>

#include "rosin/dsp.h"

namespace rosin::test {

struct Controls {
    double force, speed, beta;
};

/// Runs `samples` samples of a freshly reset string, controls given as a function of time.
template <typename T = double>
std::vector<dsp::BowFrame<T>> simulate(const dsp::BowedStringConfig& config, double fs, int samples,
                                       const std::function<Controls(double)>& gesture)
{
    dsp::BowedString<T> string;
    string.prepare(fs, config);
    std::vector<dsp::BowFrame<T>> frames(static_cast<std::size_t>(samples));
    for (int n = 0; n < samples; ++n) {
        const Controls c = gesture(n / fs);
        string.processSample(static_cast<T>(c.force), static_cast<T>(c.speed), static_cast<T>(c.beta), &frames[n]);
    }
    return frames;
}

/// Indices where the contact goes from stick to slip, within [from, to).
template <typename T>
std::vector<int> slipOnsets(const std::vector<dsp::BowFrame<T>>& frames, int from, int to)
{
    std::vector<int> onsets;
    for (int n = std::max(from, 1); n < to; ++n)
        if (!frames[n].stick && frames[n - 1].stick) onsets.push_back(n);
    return onsets;
}

/// Sample rate at which the cello D reference string has integer segment delays at
/// beta = 90/1001 = 0.0899 (PHYSICS.md 1.5).
inline double integerDelayRate(const dsp::StringParams& s) { return 1001.0 * s.fundamental(); }
inline constexpr double integerBeta = 90.0 / 1001.0;

/// Bow speed that rises linearly to `target` over `rise` seconds, then holds.
inline double ramp(double t, double target, double rise) { return target * std::min(1.0, t / rise); }

} // namespace rosin::test
