// The run-time switches a playable voice needs (model, contact law, rosin, finger, body) must
// give exactly what a voice prepared that way from the start gives, without reallocating.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "TestSupport.h"

using namespace rosin;
using namespace rosin::dsp;

namespace {
std::vector<double> stroke(BowedString<double>& s, int n, double force = 0.6, double speed = 0.1, double beta = 0.09)
{
    std::vector<double> out(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = s.processSample(force, speed, beta);
    return out;
}

double maxDifference(const std::vector<double>& a, const std::vector<double>& b)
{
    double d = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
    return d;
}

double peak(const std::vector<double>& a)
{
    double p = 0.0;
    for (double x : a) p = std::max(p, std::abs(x));
    return p;
}
} // namespace

TEST(PlayableVoice, ModelSwitchMatchesAVoicePreparedWithThatModel)
{
    const double fs = 48000.0;
    for (FrictionModel target : {FrictionModel::FrictionCurve, FrictionModel::Thermal, FrictionModel::Enhanced}) {
        BowedStringConfig c;
        c.friction.model = FrictionModel::Thermal;
        c.friction.switchable = true;
        BowedString<double> switched;
        switched.prepare(fs, c);
        ASSERT_TRUE(switched.junction().setModel(target));
        switched.reset();
        BowedStringConfig d;
        d.friction.model = target;
        BowedString<double> direct;
        direct.prepare(fs, d);
        const auto a = stroke(switched, 9600), b = stroke(direct, 9600);
        EXPECT_GT(peak(b), 0.05);
        EXPECT_EQ(maxDifference(a, b), 0.0) << static_cast<int>(target);
    }
}

TEST(PlayableVoice, ModelSwitchWithoutItsTableIsRefused)
{
    BowedStringConfig c;
    c.friction.model = FrictionModel::FrictionCurve; // not switchable: no temperature tables
    BowedString<double> s;
    s.prepare(48000.0, c);
    EXPECT_FALSE(s.junction().setModel(FrictionModel::Thermal));
    EXPECT_EQ(s.junction().params().model, FrictionModel::FrictionCurve);
}

TEST(PlayableVoice, RosinContactAndFootprintSwitchesMatchPreparedVoices)
{
    const double fs = 48000.0;
    BowedStringConfig base;
    base.friction.switchable = true;
    BowedString<double> switched;
    switched.prepare(fs, base);
    switched.junction().setGlassTransition(16.0);
    switched.junction().setContactLaw(ContactLaw::PowerLaw, 2.0 / 3.0);
    switched.junction().setFootprintRatio(0.8);
    switched.junction().setAmbient(25.0);
    switched.reset();

    BowedStringConfig d;
    d.friction.thermal.glassTransitionCelsius = 16.0;
    d.friction.contactLaw = ContactLaw::PowerLaw;
    d.friction.thermal.footprintRatio = 0.8;
    d.friction.thermal.ambientCelsius = 25.0;
    BowedString<double> direct;
    direct.prepare(fs, d);
    const auto a = stroke(switched, 9600), b = stroke(direct, 9600);
    EXPECT_GT(peak(b), 0.05);
    EXPECT_LT(maxDifference(a, b), 1e-12);
}

TEST(PlayableVoice, StoppingTheStringMatchesAShorterStringAndItsPitch)
{
    const double fs = 48000.0;
    BowedStringConfig c;
    c.friction.model = FrictionModel::FrictionCurve;
    c.waveguide.lowestPitchRatio = 0.5;
    BowedString<double> stopped;
    stopped.prepare(fs, c);
    stopped.waveguide().setFundamental(220.0);
    stopped.reset();

    BowedStringConfig d = c;
    d.string = c.string.stoppedAt(220.0);
    BowedString<double> shorter;
    shorter.prepare(fs, d);
    const auto a = stroke(stopped, 24000, 0.6, 0.1, 0.1), b = stroke(shorter, 24000, 0.6, 0.1, 0.1);
    EXPECT_LT(maxDifference(a, b), 1e-12);

    // Helmholtz period: the autocorrelation peak of the last 0.25 s, refined by a parabola.
    auto corr = [&](int lag) {
        double r = 0.0;
        for (std::size_t i = 12000; i + static_cast<std::size_t>(lag) < a.size(); ++i) r += a[i] * a[i + static_cast<std::size_t>(lag)];
        return r;
    };
    int best = 120;
    for (int lag = 120; lag <= 480; ++lag)
        if (corr(lag) > corr(best)) best = lag;
    const double r0 = corr(best - 1), r1 = corr(best), r2 = corr(best + 1);
    const double period = best + 0.5 * (r0 - r2) / (r0 - 2.0 * r1 + r2);
    EXPECT_NEAR(fs / period, 220.0, 220.0 * 0.005);
}

TEST(PlayableVoice, FundamentalIsClampedToTheRoomPrepareMade)
{
    BowedStringConfig c;
    c.waveguide.lowestPitchRatio = 0.5;
    BowedString<double> s;
    s.prepare(48000.0, c);
    s.waveguide().setFundamental(10.0); // far below an octave under the open D
    EXPECT_NEAR(s.waveguide().fundamental(), 0.5 * c.string.fundamental(), 1e-9);
    s.waveguide().setFundamental(std::nan(""));
    EXPECT_NEAR(s.waveguide().fundamental(), 0.5 * c.string.fundamental(), 1e-9);
    const auto out = stroke(s, 4800);
    for (double x : out) ASSERT_TRUE(std::isfinite(x));
}

TEST(ModalBody, EachModePeaksAtItsGainAndFallsOffAsASecondOrderResonance)
{
    const double fs = 48000.0;
    BodyParams p;
    p.count = 1;
    p.modes[0] = {400.0, 30.0, 2.0};
    p.direct = 0.0;
    ModalBody<double> body;
    body.prepare(fs, p);
    auto amplitude = [&](double f) {
        body.reset();
        double a = 0.0;
        for (int n = 0; n < 96000; ++n) {
            const double y = body.processSample(std::sin(2.0 * std::numbers::pi * f * n / fs));
            if (n > 48000) a = std::max(a, std::abs(y));
        }
        return a;
    };
    EXPECT_NEAR(amplitude(400.0), 2.0, 0.02);
    // |H| = gain / sqrt(1 + Q^2 (f/f0 - f0/f)^2) for a band-pass resonance (bilinear warping is small here).
    const double expected = 2.0 / std::sqrt(1.0 + 900.0 * std::pow(2.0 - 0.5, 2.0));
    EXPECT_NEAR(amplitude(800.0), expected, 0.05 * expected);
}

TEST(ModalBody, ModesOutsideTheBandAreDroppedNotUnstable)
{
    BodyParams p;
    p.count = 3;
    p.modes[0] = {400.0, 30.0, 1.0};
    p.modes[1] = {30000.0, 30.0, 1.0}; // above Nyquist at 48 kHz
    p.modes[2] = {500.0, 0.0, 1.0};    // no damping given
    ModalBody<float> body;
    body.prepare(48000.0, p);
    EXPECT_EQ(body.activeModes(), 1);
    float y = 0.0f;
    for (int n = 0; n < 48000; ++n) y = body.processSample(n == 0 ? 1.0f : 0.0f);
    EXPECT_TRUE(std::isfinite(y));
    EXPECT_LT(std::abs(y), 1e-3f);
}

// A light finger at the node of harmonic n: bowed, the string speaks n f0 (natural harmonics).
TEST(PlayableVoice, ALightFingerAtANodeSoundsTheHarmonic)
{
    const double fs = 48000.0;
    for (int n : {2, 3, 4}) {
        BowedStringConfig c;
        c.friction.model = FrictionModel::Thermal;
        BowedString<double> s;
        s.prepare(fs, c);
        s.waveguide().setHarmonic(n, 1.0);
        const auto a = stroke(s, 36000, 0.3, 0.2, 0.06);
        auto corr = [&](int lag) {
            double r = 0.0;
            for (std::size_t i = 18000; i + static_cast<std::size_t>(lag) < a.size(); ++i) r += a[i] * a[i + static_cast<std::size_t>(lag)];
            return r;
        };
        const double target = n * c.string.fundamental();
        const int expect = static_cast<int>(fs / target);
        int best = expect - 6;
        for (int lag = expect - 6; lag <= expect + 6; ++lag)
            if (corr(lag) > corr(best)) best = lag;
        const double r0 = corr(best - 1), r1 = corr(best), r2 = corr(best + 1);
        const double period = best + 0.5 * (r0 - r2) / (r0 - 2.0 * r1 + r2);
        EXPECT_LT(std::abs(1200.0 * std::log2(fs / period / target)), 10.0) << "harmonic " << n;
        // Periodic at the harmonic's period, not only at the open string's: as strong at P/n as at P.
        const int open = static_cast<int>(std::lround(fs / c.string.fundamental()));
        EXPECT_GT(corr(best), 0.8 * corr(open)) << n;
        EXPECT_GT(peak(a), 0.02) << n;
        // The control: without the finger the same bow plays the open string, and the test sees it.
        BowedString<double> plain;
        plain.prepare(fs, c);
        const auto b = stroke(plain, 36000, 0.3, 0.2, 0.06);
        auto corrB = [&](int lag) {
            double r = 0.0;
            for (std::size_t i = 18000; i + static_cast<std::size_t>(lag) < b.size(); ++i) r += b[i] * b[i + static_cast<std::size_t>(lag)];
            return r;
        };
        EXPECT_LT(corrB(best), 0.8 * corrB(open)) << n;
    }
}
