#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "rosin/dsp.h"

using namespace rosin::dsp;

TEST(DelayLine, IntegerDelayIsExact)
{
    DelayLine<double> line;
    line.prepare(64);
    for (int n = 0; n < 100; ++n) {
        if (n >= 17) {
            EXPECT_EQ(line.read(17.0), double(n - 17));
        }
        line.write(double(n));
    }
}

// Reads are one add from the write index into the mirrored half (no wrap): every delay from
// the shortest to the capacity must return the right sample, through several wraps of the buffer.
TEST(DelayLine, EveryDelayReadsTheRightSampleThroughWraps)
{
    DelayLine<float> line;
    line.prepare(40); // 64 slots, capacity 59
    const int maxDelay = static_cast<int>(line.capacity());
    ASSERT_GE(maxDelay, 40);
    for (int n = 0; n < 400; ++n) { // > 6 wraps
        for (int d = 1; d <= std::min(n, maxDelay); ++d) {
            ASSERT_EQ(line.read(static_cast<double>(d)), static_cast<float>(n - d)) << "delay " << d << " at " << n;
            const auto t = line.tap(static_cast<double>(d) + 0.5);
            const float* p = line.stencil(t); // oldest first: delays base + 3 .. base
            if (n >= static_cast<int>(t.base) + 3) {
                for (int k = 0; k < 4; ++k) ASSERT_EQ(p[k], static_cast<float>(n - static_cast<int>(t.base) - 3 + k));
            }
        }
        line.write(static_cast<float>(n));
    }
}

TEST(DelayLine, FractionalDelayShiftsPhaseOfALowSine)
{
    DelayLine<double> line;
    line.prepare(256);
    const double w = 2.0 * std::numbers::pi * 0.01, d = 40.37;
    double worst = 0.0;
    for (int n = 0; n < 400; ++n) {
        if (n > 100) worst = std::max(worst, std::abs(line.read(d) - std::sin(w * (n - d))));
        line.write(std::sin(w * n));
    }
    EXPECT_LT(worst, 1e-5);
}

namespace {
/// Delay (samples) of a slow sine through a fresh copy of the filter, from the last upward zero
/// crossings of input and output within `samples`.
double measuredPhaseDelay(OnePoleLoss<double> filter, double w, int samples)
{
    filter.reset();
    double lastCrossIn = 0, lastCrossOut = 0, prevIn = 0, prevOut = 0;
    for (int n = 0; n < samples; ++n) {
        const double x = std::sin(w * n), y = filter.process(x);
        if (prevIn < 0 && x >= 0) lastCrossIn = n - x / (x - prevIn);
        if (prevOut < 0 && y >= 0) lastCrossOut = n - y / (y - prevOut);
        prevIn = x;
        prevOut = y;
    }
    return lastCrossOut - lastCrossIn;
}
} // namespace

TEST(OnePoleLoss, HitsBothMagnitudeTargetsAndReportsItsPhaseDelay)
{
    OnePoleLoss<double> f;
    const double w1 = 0.01, w2 = 0.05, m1 = 0.999, m2 = 0.99;
    f.design(m1, w1, m2, w2);
    auto mag = [&](double w) {
        const double p = f.a1;
        return f.b0 / std::sqrt(1.0 + 2.0 * p * std::cos(w) + p * p);
    };
    EXPECT_NEAR(mag(w1), m1, 1e-12);
    EXPECT_NEAR(mag(w2), m2, 1e-12);
    EXPECT_LT(f.a1, 0.0); // low-pass: more loss at the higher frequency
    // Phase delay checked against a measured delay of a slow sine through the filter.
    const double pd = f.phaseDelay(w1);
    EXPECT_GT(pd, 0.0);
    EXPECT_NEAR(measuredPhaseDelay(f, w1, 20000), pd, 0.01);
}

// The DC shelf gives back at zero frequency what the low-pass loses there (a held deflection
// holds), while the pair still hits both targets and its phase delay is what a sine measures.
TEST(OnePoleLoss, TheDcShelfRestoresUnitGainAtDcAndKeepsBothTargets)
{
    // Targets of the cello D's torsional finger side at 48 kHz: the heaviest loss the string has.
    const double w1 = 2 * std::numbers::pi * 146.83 / 48000, w2 = 5 * w1, m1 = 0.909105, m2 = 0.620969;
    OnePoleLoss<double> plain, restored;
    plain.design(m1, w1, m2, w2);
    restored.design(m1, w1, m2, w2, 0.5 * w1);
    EXPECT_NEAR(plain.dcGain(), 0.9316, 0.002); // the low-pass alone loses 7 % at DC
    EXPECT_NEAR(restored.dcGain(), 1.0, 2e-6);
    EXPECT_LE(restored.dcGain(), OnePoleLoss<double>::kDcGain);
    EXPECT_NEAR(restored.magnitude(w1), m1, 5e-4);
    EXPECT_NEAR(restored.magnitude(w2), m2, 5e-4);
    for (double w = 0.001; w < 3.1; w *= 1.3) EXPECT_LE(restored.magnitude(w), 1.0) << "w=" << w; // passive
    // DC: a step settles at the DC gain.
    OnePoleLoss<double> g = restored;
    g.reset();
    double y = 0;
    for (int n = 0; n < 200000; ++n) y = g.process(1.0);
    EXPECT_NEAR(y, 1.0, 2e-6);
    EXPECT_NEAR(measuredPhaseDelay(restored, w1, 40000), restored.phaseDelay(w1), 0.01); // against a slow sine
    // Rounded to float, the DC gain still never exceeds 1.
    OnePoleLoss<float> single;
    single.design(m1, w1, m2, w2, 0.5 * w1);
    EXPECT_LE(single.dcGain(), OnePoleLoss<float>::kDcGain);
    EXPECT_NEAR(single.dcGain(), 1.0, 1e-5);
}

TEST(DispersionChain, PhaseDelayFallsWithFrequency)
{
    const double a = -0.5;
    const double low = DispersionChain<double>::sectionPhaseDelay(a, 1e-4);
    const double high = DispersionChain<double>::sectionPhaseDelay(a, 3.0);
    EXPECT_NEAR(low, (1 - a) / (1 + a), 1e-6);
    EXPECT_LT(high, low);
    EXPECT_GT(high, 0.9);
}
