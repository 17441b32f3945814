// Random-gesture robustness run shared by the quick test and the `long` soak.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "rosin/dsp.h"

namespace rosin::test {
using namespace rosin::dsp;

// Random gestures with abrupt jumps, absurd and non-finite values: the output stays finite and
// bounded in every model. A 60 s version of this runs under the `long` label.
template <typename T>
inline void randomGestureRun(double seconds, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uf(0.0, 10.0), us(-3.0, 3.0), ub(0.01, 0.5), u01(0.0, 1.0);
    std::uniform_int_distribution<int> len(1, 2000);
    for (FrictionModel model : {FrictionModel::FrictionCurve, FrictionModel::Thermal, FrictionModel::Enhanced}) {
        for (bool torsion : {false, true}) {
            BowedStringConfig c;
            c.friction.model = model;
            c.waveguide.torsion = torsion;
            c.waveguide.dispersion = true;
            c.waveguide.gaussianReflections = torsion; // both reflection designs take the abuse
            const double fs = 48000.0;
            BowedString<T> s;
            s.prepare(fs, c);
            const int n = static_cast<int>(seconds * fs);
            double force = 0, speed = 0, beta = 0.1, peak = 0, hottest = 0;
            int left = 0;
            for (int i = 0; i < n; ++i) {
                if (left-- <= 0) {
                    left = len(rng);
                    force = uf(rng);
                    speed = us(rng);
                    beta = ub(rng);
                    const double r = u01(rng);
                    if (r < 0.02) force = std::numeric_limits<double>::quiet_NaN();
                    else if (r < 0.04) speed = std::numeric_limits<double>::infinity();
                    else if (r < 0.06) force = 1e9;
                    else if (r < 0.08) force = -5.0;
                    else if (r < 0.10) beta = std::numeric_limits<double>::quiet_NaN();
                }
                BowFrame<T> fr;
                const T out = s.processSample(T(force), T(speed), T(beta), &fr);
                ASSERT_TRUE(std::isfinite(double(out))) << "sample " << i;
                ASSERT_TRUE(std::isfinite(double(fr.temperature)));
                ASSERT_TRUE(std::isfinite(double(fr.velocity)));
                peak = std::max(peak, std::abs(double(out)));
                hottest = std::max(hottest, double(fr.temperature));
            }
            // Friction is at most mu_s * 20 N (the force clamp); the bridge force of a string
            // that is driven that hard stays within a few times that.
            EXPECT_LT(peak, 200.0);
            // Steady sliding at 10 N and 3 m/s settles near 260 K above ambient (PHYSICS.md 3.3).
            EXPECT_LT(hottest, 500.0);
        }
    }
}

} // namespace rosin::test
