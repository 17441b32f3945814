// The load line v = vh + f / (2 Zeff) and the friction law hold every sample, in every model.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <ostream>
#include <string>

#include "RandomGesture.h"
#include "TestSupport.h"

using namespace rosin;
using namespace rosin::dsp;

namespace {
struct Case {
    FrictionModel model;
    bool torsion;
    ContactLaw contact;
};

std::string caseName(const Case& k)
{
    const char* model = k.model == FrictionModel::FrictionCurve ? "FrictionCurve" : k.model == FrictionModel::Thermal ? "Thermal" : "Enhanced";
    return std::string(model) + (k.torsion ? "_Torsion" : "") + (k.contact == ContactLaw::Amontons ? "_Amontons" : "_Hertzian");
}

// ctest takes the printed parameter into the test's name: printed from its fields, not its bytes.
void PrintTo(const Case& k, std::ostream* os) { *os << caseName(k); }
} // namespace

class JunctionEquation : public ::testing::TestWithParam<Case> {};

TEST_P(JunctionEquation, HoldsEverySampleAndFrictionObeysTheLaw)
{
    const Case k = GetParam();
    BowedStringConfig c;
    c.friction.model = k.model;
    c.friction.contactLaw = k.contact;
    if (k.model == FrictionModel::Enhanced) c.friction.fit = SteadyFit::WoodhouseGalluzzo;
    c.waveguide.torsion = k.torsion;
    const double fs = 96000.0;
    BowedString<double> s;
    s.prepare(fs, c);
    const double twoZ = 2.0 * s.effectiveImpedance();
    const auto& j = s.junction();
    int slips = 0, sticks = 0;
    for (int n = 0; n < static_cast<int>(0.5 * fs); ++n) {
        const double t = n / fs;
        const double force = 0.3 + 0.8 * std::sin(7.0 * t) * std::sin(7.0 * t);
        const double speed = 0.3 * std::sin(2.0 * std::numbers::pi * 3.0 * t); // reversing bow
        BowFrame<double> fr;
        s.processSample(force, speed, 0.08 + 0.03 * std::sin(5.0 * t), &fr);
        const double residual = fr.velocity - (fr.history + fr.friction / twoZ);
        ASSERT_LT(std::abs(residual), 1e-12 * (1.0 + std::abs(fr.velocity))) << "n=" << n;
        if (fr.stick) {
            ++sticks;
            ASSERT_EQ(fr.velocity, speed);
            ASSERT_LE(std::abs(fr.friction), j.stickLimit(force, fr.temperature) * (1 + 1e-12));
        } else {
            ++slips;
            const double dv = fr.velocity - speed;
            double law = 0;
            if (k.model == FrictionModel::Thermal) law = j.stickLimit(force, fr.temperature);
            else if (k.model == FrictionModel::FrictionCurve)
                law = j.contactArea().effectiveLoad(force) * steadySliding(c.friction.fit, dv).mu;
            else
                law = j.stickLimit(force, fr.temperature) * speedFunction(c.friction.speedFunction, dv).mu
                      / speedFunction(c.friction.speedFunction, 0.0).mu;
            ASSERT_NEAR(std::abs(fr.friction), law, 1e-9 * (1 + law)) << "n=" << n;
            ASSERT_LT(fr.friction * dv, 0.0) << "friction must oppose sliding, n=" << n;
        }
    }
    EXPECT_GT(slips, 100);
    EXPECT_GT(sticks, 100);
}

INSTANTIATE_TEST_SUITE_P(AllModels, JunctionEquation,
                         ::testing::Values(Case{FrictionModel::FrictionCurve, false, ContactLaw::Amontons},
                                           Case{FrictionModel::FrictionCurve, true, ContactLaw::PowerLaw},
                                           Case{FrictionModel::Thermal, false, ContactLaw::Amontons},
                                           Case{FrictionModel::Thermal, true, ContactLaw::PowerLaw},
                                           Case{FrictionModel::Enhanced, false, ContactLaw::Amontons},
                                           Case{FrictionModel::Enhanced, true, ContactLaw::PowerLaw}),
                         // Names from the case, not from its bytes: gtest would print the struct's
                         // padding, which differs from build to build and so renamed the ctest tests.
                         [](const ::testing::TestParamInfo<Case>& param) { return caseName(param.param); });

// The thermal junction skips work where it can: sticking samples that stay below the limit of
// a lookup at a warmer temperature do not read the table, and a contact that was still takes
// the short temperature step. Against the model written out in full (implicit step, table
// read and stick test every sample), through slips, sticks, force changes, a lifted bow and
// ambient changes, every result must be the same number.
TEST(ThermalJunction, DecidesAsTheModelWrittenOutEverySample)
{
    for (ContactLaw contact : {ContactLaw::Amontons, ContactLaw::PowerLaw}) {
        const double fs = 48000.0;
        BowedStringConfig c;
        c.friction.model = FrictionModel::Thermal;
        c.friction.contactLaw = contact;
        // a bow's footprint other than the steady test's: the written-out heat must follow it too
        c.friction.thermal.footprintRatio = contact == ContactLaw::PowerLaw ? 1.3 : 1.0;
        BowedString<double> s;
        s.prepare(fs, c);
        ThermalContact<double> reference;
        reference.prepare(fs, c.friction.thermal);
        const double twoZ = 2.0 * s.effectiveImpedance();
        double heatPerLoad = 0.0, slide = 0.0, slopePerLoad = 0.0;
        int sticks = 0, slips = 0, wellInside = 0;
        for (int n = 0; n < static_cast<int>(1.5 * fs); ++n) {
            const double t = n / fs;
            if (n == static_cast<int>(0.6 * fs)) s.junction().setAmbient(30.0); // the law shifts mid-note
            double force = t < 0.4 ? 0.6 : (t < 1.0 ? 0.6 + 0.5 * std::sin(9.0 * t) * std::sin(9.0 * t) : 1.2);
            if (t > 1.3 && t < 1.32) force = 0.0; // lifted for a moment
            const double speed = 0.25 * std::min(1.0, t / 0.05);
            BowFrame<double> fr;
            s.processSample(force, speed, 0.1, &fr);

            const auto& j = s.junction();
            const double load = j.contactArea().effectiveLoad(force);
            const double theta = reference.step(heatPerLoad * load, slide, j.contactArea().areaPerNewton * load, slopePerLoad * load);
            const MuSlope m = j.temperatureLaw().at(theta);
            const double limit = load * m.mu;
            const double fStick = twoZ * (speed - fr.history);
            double f = fStick, v = speed;
            const bool stick = std::abs(fStick) <= limit;
            if (stick) {
                heatPerLoad = slide = slopePerLoad = 0.0;
                ++sticks;
            } else {
                f = fStick >= 0.0 ? limit : -limit;
                v = fr.history + f * (0.5 / s.effectiveImpedance());
                const double dv = std::abs(v - speed);
                heatPerLoad = std::abs(f) * dv * (load > 0.0 ? 1.0 / load : 0.0);
                slide = dv;
                slopePerLoad = dv > 0.0 ? dv * m.slope : 0.0;
                ++slips;
            }
            if (stick && limit > 1.01 * std::abs(fStick)) ++wellInside; // where the table read can be skipped
            ASSERT_EQ(fr.stick, stick) << "sample " << n;
            ASSERT_EQ(fr.temperature, theta) << "sample " << n;
            ASSERT_EQ(fr.friction, f) << "sample " << n;
            ASSERT_EQ(fr.velocity, v) << "sample " << n;
        }
        EXPECT_GT(slips, 3000);
        EXPECT_GT(sticks, 30000);
        EXPECT_GT(wellInside, 10000);
    }
}

// The shortcut rests on friction falling as the contact warms: true of both steady-sliding fits.
TEST(TemperatureLaw, FrictionFallsAsTheContactWarmsForBothFits)
{
    ThermalParams tp;
    for (SteadyFit fit : {SteadyFit::SmithWoodhouse, SteadyFit::WoodhouseGalluzzo}) {
        TemperatureLaw law;
        law.build(fit, std::nullopt, tp);
        EXPECT_TRUE(law.nonIncreasing());
        double previous = law(0.0);
        for (double theta = 0.0; theta < law.thetaMax() + 5.0; theta += 0.01) {
            ASSERT_LE(law(theta), previous) << "theta=" << theta;
            previous = law(theta);
        }
        EXPECT_LT(law(law.thetaMax()), law(0.0) - 0.2);
    }
}

TEST(BowedString, BlockSizeDoesNotChangeTheOutput)
{
    BowedStringConfig c;
    const double fs = 48000.0;
    const int n = 24000;
    std::vector<double> force(n), speed(n), beta(n);
    for (int i = 0; i < n; ++i) {
        force[i] = 0.4 + 0.3 * std::sin(i * 1e-3);
        speed[i] = 0.2 * std::sin(i * 2e-4);
        beta[i] = 0.1 + 0.02 * std::sin(i * 5e-4);
    }
    std::vector<double> reference(n);
    {
        BowedString<double> s;
        s.prepare(fs, c);
        for (int i = 0; i < n; ++i) reference[i] = s.processSample(force[i], speed[i], beta[i]);
    }
    for (int block : {1, 7, 64, 512, 4096}) {
        BowedString<double> s;
        s.prepare(fs, c);
        std::vector<double> out(n);
        for (int start = 0; start < n; start += block) {
            const int len = std::min(block, n - start);
            s.processBlock(&force[start], &speed[start], &beta[start], &out[start], len);
        }
        for (int i = 0; i < n; ++i) ASSERT_EQ(out[i], reference[i]) << "block " << block << " sample " << i;
    }
}

// processBlock runs a playing voice (plain string, thermal model, no frames) through its own
// loop with the switches fixed at compile time, and reads short delay lines with narrow loads.
// It must give processSample's output bit for bit, in float and double, with torsion on and
// off, while the bow moves far enough that the shortest line crosses the narrow-load threshold.
template <typename T>
class VoiceLoop : public ::testing::Test {};
using VoiceLoopTypes = ::testing::Types<float, double>;
TYPED_TEST_SUITE(VoiceLoop, VoiceLoopTypes);

TYPED_TEST(VoiceLoop, MatchesProcessSampleBitForBit)
{
    using T = TypeParam;
    const double fs = 48000.0;
    const int n = 30000;
    std::vector<T> force(n), speed(n), beta(n);
    for (int i = 0; i < n; ++i) {
        force[i] = T(0.5 + 0.3 * std::sin(i * 7e-4));
        speed[i] = T(0.25 * std::sin(i * 2.5e-4));
        beta[i] = T(0.14 + 0.11 * std::sin(i * 3e-4)); // 0.03..0.25: torsional bridge side 2..32 samples
    }
    for (bool torsion : {true, false}) {
        BowedStringConfig c;
        c.waveguide.torsion = torsion;
        BowedString<T> reference, voice, traced;
        for (auto* s : {&reference, &voice, &traced}) s->prepare(fs, c);
        ASSERT_TRUE(voice.waveguide().packed());
        BowedString<T> listened; // the instrument's use: bridge force plus the stick flags
        listened.prepare(fs, c);
        std::vector<T> expected(n), out(n), outTraced(n), outListened(n);
        std::vector<BowFrame<T>> frames(n);
        std::vector<std::uint8_t> expectedStick(n), stick(n);
        int slips = 0;
        for (int i = 0; i < n; ++i) {
            BowFrame<T> f;
            expected[i] = reference.processSample(force[i], speed[i], beta[i], &f);
            expectedStick[i] = f.stick ? 1 : 0;
            slips += f.stick ? 0 : 1;
        }
        for (int start = 0; start < n; start += 333) {
            const int len = std::min(333, n - start);
            voice.processBlock(&force[start], &speed[start], &beta[start], &out[start], len);
            traced.processBlock(&force[start], &speed[start], &beta[start], &outTraced[start], len, &frames[start]);
            listened.processBlock(&force[start], &speed[start], &beta[start], &outListened[start], len, nullptr, &stick[start]);
        }
        EXPECT_GT(slips, n / 50) << "the gesture must make the string slip, or the slip path goes untested";
        for (int i = 0; i < n; ++i) {
            ASSERT_EQ(out[i], expected[i]) << "torsion " << torsion << " sample " << i;
            ASSERT_EQ(outTraced[i], expected[i]) << "torsion " << torsion << " sample " << i;
            ASSERT_EQ(outListened[i], expected[i]) << "torsion " << torsion << " sample " << i;
            ASSERT_EQ(stick[i], expectedStick[i]) << "torsion " << torsion << " sample " << i;
        }
    }
}

TEST(Simd, NarrowLoadReadsTheSameFourValues)
{
    const float f[6] = {1.5f, -2.25f, 3.0f, 4.75f, -5.5f, 6.0f};
    const double d[6] = {1.5, -2.25, 3.0, 4.75, -5.5, 6.0};
    for (int k = 0; k < 3; ++k) {
        const auto a = simd::load4Narrow(f + k), b = simd::load4(f + k);
        const auto c = simd::load4Narrow(d + k), e = simd::load4(d + k);
        for (int j = 0; j < 4; ++j) {
            EXPECT_EQ(a[j], f[k + j]);
            EXPECT_EQ(b[j], f[k + j]);
            EXPECT_EQ(c[j], d[k + j]);
            EXPECT_EQ(e[j], d[k + j]);
        }
    }
}

template <typename T>
class Robustness : public ::testing::Test {};
using SampleTypes = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Robustness, SampleTypes);

TYPED_TEST(Robustness, RandomAbsurdGesturesStayFiniteAndBounded) { test::randomGestureRun<TypeParam>(1.0, 1234u); }

