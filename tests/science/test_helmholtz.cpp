// Steady bowing: Helmholtz motion and its limits (PHYSICS.md 2.4, 9 test 4).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "TestSupport.h"

using namespace rosin;
using namespace rosin::dsp;

namespace {
constexpr double kBeta = 0.0899, kSpeed = 0.1;

BowedStringConfig frictionCurveNoTorsion()
{
    BowedStringConfig c;
    c.friction.model = FrictionModel::FrictionCurve;
    c.waveguide.torsion = false;
    return c;
}

struct SteadyStats {
    double period = 0, slipFraction = 0, slipVelocity = 0, stickVelocityError = 0, ripplesPerPeriod = 0;
    int slipsPerPeriodMax = 0;
    bool helmholtz = false;
};

SteadyStats analyseSteady(const std::vector<BowFrame<double>>& fr, double fs, double f0, double speed, double window)
{
    SteadyStats s;
    const int n = static_cast<int>(fr.size()), start = n - static_cast<int>(window * fs);
    const auto onsets = test::slipOnsets(fr, start, n);
    if (onsets.size() < 3) return s;
    s.period = double(onsets.back() - onsets.front()) / double(onsets.size() - 1) / fs;
    int slipSamples = 0, total = 0;
    double slipVelocity = 0;
    for (int i = onsets.front(); i < onsets.back(); ++i, ++total) {
        if (!fr[i].stick) { ++slipSamples; slipVelocity += fr[i].velocity; }
        else s.stickVelocityError = std::max(s.stickVelocityError, std::abs(fr[i].velocity - speed));
    }
    // Schelleng ripples: the friction force repeats every beta P0 while sticking, so over one
    // period its strongest harmonic above the second is the number of ripples per period.
    {
        const int a = onsets[onsets.size() - 2], b = onsets.back(), len = b - a;
        double bestMag = -1;
        for (int k = 3; k <= 30; ++k) {
            double re = 0, im = 0;
            for (int i = 0; i < len; ++i) {
                re += fr[a + i].friction * std::cos(2 * std::numbers::pi * k * i / len);
                im += fr[a + i].friction * std::sin(2 * std::numbers::pi * k * i / len);
            }
            if (std::hypot(re, im) > bestMag) { bestMag = std::hypot(re, im); s.ripplesPerPeriod = k; }
        }
    }
    s.slipFraction = double(slipSamples) / total;
    s.slipVelocity = slipVelocity / slipSamples;
    // Helmholtz: every onset spacing within 2 % of the nominal period.
    s.helmholtz = true;
    for (std::size_t k = 1; k < onsets.size(); ++k)
        if (std::abs((onsets[k] - onsets[k - 1]) / fs * f0 - 1.0) > 0.02) s.helmholtz = false;
    return s;
}
} // namespace

TEST(Helmholtz, FrictionCurveCelloDMatchesTheIdealSawtoothWithinTolerance)
{
    const BowedStringConfig c = frictionCurveNoTorsion();
    const double f0 = c.string.fundamental(), fs = test::integerDelayRate(c.string);
    const auto fr = test::simulate(c, fs, static_cast<int>(1.0 * fs), [](double t) {
        return test::Controls{1.0, test::ramp(t, kSpeed, 0.05), kBeta};
    });
    const SteadyStats s = analyseSteady(fr, fs, f0, kSpeed, 0.3);
    ASSERT_TRUE(s.helmholtz);
    EXPECT_NEAR(s.period * f0, 1.0, 0.005);
    EXPECT_LT(s.stickVelocityError, 1e-12);                       // string moves with the bow
    EXPECT_NEAR(s.slipFraction / kBeta, 1.0, 0.10);               // slips for beta of the period
    const double idealSlip = -kSpeed * (1.0 - kBeta) / kBeta;     // -1.01 m/s
    EXPECT_NEAR(s.slipVelocity / idealSlip, 1.0, 0.10);
    EXPECT_NEAR(s.ripplesPerPeriod, 1.0 / kBeta, 1.5);            // about 11 Schelleng ripples
}

TEST(Helmholtz, BridgeForceFlybackIsTwoZ0VbOverBeta)
{
    const BowedStringConfig c = frictionCurveNoTorsion();
    const double fs = test::integerDelayRate(c.string);
    const auto fr = test::simulate(c, fs, static_cast<int>(1.0 * fs), [](double t) {
        return test::Controls{1.0, test::ramp(t, kSpeed, 0.05), kBeta};
    });
    // Peak-to-peak of the bridge force over the last periods ~ the ideal flyback 1.13 N.
    double lo = 1e9, hi = -1e9;
    for (std::size_t i = fr.size() - static_cast<std::size_t>(0.1 * fs); i < fr.size(); ++i) {
        lo = std::min(lo, double(fr[i].bridgeForce));
        hi = std::max(hi, double(fr[i].bridgeForce));
    }
    const double ideal = 2.0 * c.string.impedance() * kSpeed / kBeta;
    EXPECT_NEAR((hi - lo) / ideal, 1.0, 0.15);
}

// Raise the bow force slowly from an established Helmholtz motion until it breaks down; the
// breakdown force is Schelleng's maximum 2 Z0 vb / (beta (mu_s - mu_d)) = 1.33 N (within 30 %).
TEST(Helmholtz, LostBeyondSchellengsMaximumBowForce)
{
    const BowedStringConfig c = frictionCurveNoTorsion();
    const double f0 = c.string.fundamental(), fs = 96000.0;
    double limit = 0.0;
    for (double force = 0.8; force <= 2.6; force += 0.1) {
        const auto fr = test::simulate(c, fs, static_cast<int>(0.6 * fs), [&](double t) {
            const double f = t < 0.15 ? 0.8 : 0.8 + (force - 0.8) * std::min(1.0, (t - 0.15) / 0.2);
            return test::Controls{f, test::ramp(t, kSpeed, 0.05), kBeta};
        });
        if (!analyseSteady(fr, fs, f0, kSpeed, 0.2).helmholtz) break;
        limit = force;
    }
    const double schelleng = 2.0 * c.string.impedance() * kSpeed / (kBeta * (1.2 - 0.35));
    ASSERT_GT(limit, 0.0);
    EXPECT_NEAR(limit / schelleng, 1.0, 0.30) << "limit " << limit << " N vs formula " << schelleng << " N";
}

TEST(Helmholtz, PitchIsRightAtEveryAudioAndResearchRate)
{
    BowedStringConfig c; // thermal model, torsion on: the plugin's default voice
    const double f0 = c.string.fundamental();
    for (double fs : {44100.0, 48000.0, 96000.0, 192000.0}) {
        const auto fr = test::simulate(c, fs, static_cast<int>(1.0 * fs), [](double t) {
            return test::Controls{0.5, test::ramp(t, kSpeed, 0.05), kBeta};
        });
        const SteadyStats s = analyseSteady(fr, fs, f0, kSpeed, 0.3);
        ASSERT_GT(s.period, 0.0) << "fs=" << fs;
        const double cents = 1200.0 * std::log2(1.0 / (s.period * f0));
        EXPECT_NEAR(cents, 0.0, 10.0) << "fs=" << fs;
    }
}

TEST(Helmholtz, FloatAndDoubleVoicesAgreeOnPeriod)
{
    BowedStringConfig c;
    const double fs = 48000.0, f0 = c.string.fundamental();
    auto gesture = [](double t) { return test::Controls{0.5, test::ramp(t, kSpeed, 0.05), kBeta}; };
    const auto fd = test::simulate<double>(c, fs, static_cast<int>(0.8 * fs), gesture);
    const auto ff = test::simulate<float>(c, fs, static_cast<int>(0.8 * fs), gesture);
    std::vector<BowFrame<double>> ffd(ff.size());
    for (std::size_t i = 0; i < ff.size(); ++i)
        ffd[i] = {ff[i].bridgeForce, ff[i].velocity, ff[i].friction, ff[i].temperature, ff[i].history, ff[i].stick};
    const auto sd = analyseSteady(fd, fs, f0, kSpeed, 0.3), sf = analyseSteady(ffd, fs, f0, kSpeed, 0.3);
    EXPECT_NEAR(sf.period / sd.period, 1.0, 1e-3);
}
