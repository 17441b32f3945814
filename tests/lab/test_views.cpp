// The editor's live views and playability maps, tested where they are computed (lab/): the maps
// against Schelleng's and Guettler's physics and against the lab's own sweeps, the history's
// scope, loop, temperature and gesture against a render whose answers are known.
#include <gtest/gtest.h>

#include <cairo.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "rosin/lab/Error.h"
#include "rosin/lab/Guettler.h"
#include "rosin/presets/Presets.h"
#include "rosin/lab/Render.h"
#include "rosin/lab/ViewFigures.h"

using namespace rosin;
using namespace rosin::lab;
namespace fs = std::filesystem;

namespace {
dsp::BowedStringConfig celloD(dsp::FrictionModel model)
{
    dsp::BowedStringConfig c;
    c.string = presets::findString(presets::Library(), "cello-D").params;
    c.friction.model = model;
    return c;
}

PlayabilitySpec schelleng(dsp::FrictionModel model)
{
    PlayabilitySpec s;
    s.kind = MapKind::Schelleng;
    s.config = celloD(model);
    s.speed = 0.1;
    return s;
}
} // namespace

TEST(PlayabilityMap, SchellengHelmholtzBetweenTheForceLimits)
{
    const PlayabilitySpec s = schelleng(dsp::FrictionModel::Thermal);
    const double fMax = schellengMaxForce(s.config.string.impedance(), 0.1, 0.0899, 1.2, 0.35);
    EXPECT_NEAR(fMax, 1.33, 0.05); // PHYSICS.md 2.4's example
    for (double F : {0.8, 1.0}) EXPECT_EQ(playabilityCell(s, 0.0899, F).regime, Regime::Helmholtz) << F;
    const PlayabilityCell heavy = playabilityCell(s, 0.0899, 6.0 * fMax);
    EXPECT_FALSE(heavy.success);
    EXPECT_EQ(heavy.regime, Regime::Irregular); // raucous
    const PlayabilityCell light = playabilityCell(s, 0.0899, 0.05);
    EXPECT_FALSE(light.success);
    EXPECT_GT(light.slipsPerPeriod, 1.5); // the string slips more than once a period
}

TEST(PlayabilityMap, FrictionCurveMaximumForceNearSchellengsFormula)
{
    PlayabilitySpec s = schelleng(dsp::FrictionModel::FrictionCurve);
    s.columns = {0.0899};
    for (int i = 0; i <= 24; ++i) s.forces.push_back(0.4 * std::pow(10.0, i / 24.0)); // 0.4-4 N
    const PlayabilityMap map = computePlayability(s);
    double highest = 0.0;
    for (std::size_t r = 0; r < s.forces.size(); ++r)
        if (map.at(0, r).success) highest = s.forces[r];
    const double formula = schellengMaxForce(map.z0, 0.1, 0.0899, 1.2, 0.35);
    EXPECT_NEAR(highest / formula, 1.0, 0.30) << "highest Helmholtz force " << highest << " N, formula " << formula << " N";
}

TEST(PlayabilityMap, GuettlerCellsAreTheLabSweepsCells)
{
    PlayabilitySpec p;
    p.kind = MapKind::Guettler;
    p.config = celloD(dsp::FrictionModel::Thermal);
    p.beta = 0.0899;
    p.columns = {0.3, 1.0, 2.5};
    p.forces = {0.4, 1.2, 2.4};
    std::atomic<bool> cancel{false};
    int rows = 0;
    const PlayabilityMap map = computePlayability(p, &cancel, [&](const PlayabilityMap& m) {
        ++rows;
        EXPECT_EQ(m.completed(), static_cast<std::size_t>(3 * rows));
    });
    EXPECT_EQ(rows, 3);
    SweepSpec s;
    s.config = p.config;
    s.accelerations = p.columns;
    s.forces = p.forces;
    s.betas = {0.0899};
    const SweepResult sweep = runSweep(s);
    int successes = 0;
    for (std::size_t a = 0; a < 3; ++a)
        for (std::size_t f = 0; f < 3; ++f) {
            EXPECT_EQ(map.at(a, f).regime, sweep.at(a, f).regime) << a << "," << f;
            EXPECT_EQ(map.at(a, f).transientPeriods, sweep.at(a, f).transientPeriods) << a << "," << f;
            successes += map.at(a, f).success;
        }
    EXPECT_GT(successes, 0);
    EXPECT_LT(successes, 9);

    cancel = true; // a cancelled map stops before its first cell
    EXPECT_EQ(computePlayability(p, &cancel).completed(), 0u);
}

TEST(PlayabilityMap, BadAxesNameTheField)
{
    PlayabilitySpec s = schelleng(dsp::FrictionModel::Thermal);
    s.columns = {0.1};
    s.forces = {std::nan("")};
    EXPECT_THROW(computePlayability(s), LabError);
    s.forces = {1.0};
    s.columns = {0.9};
    try {
        computePlayability(s);
        FAIL();
    } catch (const LabError& e) {
        EXPECT_NE(std::string(e.what()).find("beta"), std::string::npos);
    }
}

TEST(LiveViews, ScopeLoopTemperatureAndGestureOfAKnownStroke)
{
    RenderSpec spec;
    spec.config = celloD(dsp::FrictionModel::Thermal);
    spec.sampleRate = 48000.0;
    spec.duration = 1.5;
    spec.gesture.kind = GestureKind::Constant; // steady Helmholtz motion (the Schelleng map's cell)
    spec.gesture.force = 0.8;
    spec.gesture.speed = 0.1;
    spec.gesture.beta = 0.0899;
    const RenderResult r = render(spec);
    const double f0 = spec.config.string.fundamental();
    const LiveHistory h = historyOf(r, f0);

    const auto scope = h.scope(3.0);
    ASSERT_TRUE(scope.triggered);
    EXPECT_EQ(scope.stick.front(), 0); // the window opens on a slip onset
    EXPECT_NEAR(scope.time.back(), 3.0 / f0, 1.5 / spec.sampleRate);
    // Helmholtz: two more long slips inside the window (the first opens it); short ripple slips
    // of the thermal law inside the sticking phase do not count.
    const auto minSlip = static_cast<std::size_t>(0.35 * 0.0899 * spec.sampleRate / f0);
    int onsets = 0;
    for (std::size_t i = 1; i < scope.stick.size(); ++i)
        if (scope.stick[i - 1] && !scope.stick[i]) {
            std::size_t j = i;
            while (j < scope.stick.size() && !scope.stick[j]) ++j;
            onsets += j - i >= minSlip;
        }
    EXPECT_EQ(onsets, 2);

    const auto loop = h.loop(1.0);
    double area = 0.0;
    for (std::size_t i = 0; i + 1 < loop.slide.size(); ++i) area += loop.slide[i] * loop.mu[i + 1] - loop.slide[i + 1] * loop.mu[i];
    EXPECT_GT(area, 0.0) << "the thermal loop runs anticlockwise";

    const auto trace = h.temperature(1.0, 100);
    ASSERT_EQ(trace.time.size(), 100u);
    double hottest = 0.0;
    for (double v : trace.high) hottest = std::max(hottest, v);
    EXPECT_GT(hottest, h.ambientCelsius + 10.0);
    EXPECT_LT(hottest, h.ambientCelsius + 100.0);

    spec.gesture.kind = GestureKind::Guettler; // the attack's constant acceleration is read back
    spec.gesture.acceleration = 0.5;
    spec.duration = 0.4;
    const auto g = historyOf(render(spec), f0).gesture();
    EXPECT_NEAR(g.acceleration, 0.5, 0.5 * 0.05);
    EXPECT_NEAR(g.force, 0.8, 1e-6);
    EXPECT_NEAR(g.beta, 0.0899, 1e-6);
}

TEST(LiveViews, RenderViewsFigureHasEveryPanelDrawn)
{
    const fs::path dir = fs::temp_directory_path() / "rosin-views-test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string cmd = std::string(ROSIN_CLI) + " render --gesture constant --speed 0.1 --force 1 --duration 0.8 " +
                            "--sample-rate 48000 --views -q -o " + (dir / "s").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    ASSERT_TRUE(fs::exists(dir / "s-views.json"));
    cairo_surface_t* img = cairo_image_surface_create_from_png((dir / "s-views.png").c_str());
    ASSERT_EQ(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    const int w = cairo_image_surface_get_width(img), hgt = cairo_image_surface_get_height(img);
    const int stride = cairo_image_surface_get_stride(img);
    const unsigned char* px = cairo_image_surface_get_data(img);
    // Each quadrant holds many colours (a trace, shading, cells), not an empty panel.
    for (int q = 0; q < 4; ++q) {
        const int x0 = (q % 2) * w / 2, y0 = (q / 2) * hgt / 2;
        int dark = 0, coloured = 0;
        for (int y = y0 + 80; y < y0 + hgt / 2 - 60; y += 2)
            for (int x = x0 + 80; x < x0 + w / 2 - 20; x += 2) {
                const unsigned char* p = px + y * stride + 4 * x;
                const int b = p[0], g = p[1], rr = p[2];
                dark += (b + g + rr) < 300;
                coloured += std::abs(rr - b) > 60 || std::abs(g - b) > 60;
            }
        EXPECT_GT(dark + coloured, 200) << "quadrant " << q;
    }
    cairo_surface_destroy(img);
}
