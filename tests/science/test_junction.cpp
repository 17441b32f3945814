// The load line v = vh + f / (2 Zeff) and the friction law hold every sample, in every model.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
                                           Case{FrictionModel::Enhanced, true, ContactLaw::PowerLaw}));

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

template <typename T>
class Robustness : public ::testing::Test {};
using SampleTypes = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Robustness, SampleTypes);

TYPED_TEST(Robustness, RandomAbsurdGesturesStayFiniteAndBounded) { test::randomGestureRun<TypeParam>(1.0, 1234u); }

