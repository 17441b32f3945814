#include "rosin/lab/FigureSet.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rosin/dsp.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Figures.h"
#include "rosin/lab/Guettler.h"
#include "rosin/lab/Output.h"
#include "rosin/lab/Plot.h"

namespace rosin::lab {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Csv {
    std::unique_ptr<FILE, int (*)(FILE*)> f;
    explicit Csv(const fs::path& p) : f(std::fopen(p.c_str(), "w"), &std::fclose)
    {
        if (!f) throw LabError(p.string() + ": cannot write CSV");
    }
    template <typename... Args>
    void row(const char* fmt, Args... args) { std::fprintf(f.get(), fmt, args...); }
};

void writeJson(const fs::path& p, const json& j)
{
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(p.c_str(), "w"), &std::fclose);
    if (!f) throw LabError(p.string() + ": cannot write JSON");
    const std::string s = j.dump(1);
    std::fwrite(s.data(), 1, s.size(), f.get());
}

dsp::BowedStringConfig model(dsp::FrictionModel m, dsp::SteadyFit fit, dsp::SpeedFunction h = dsp::SpeedFunction::Rod,
                             dsp::ContactLaw law = dsp::ContactLaw::Amontons)
{
    dsp::BowedStringConfig c; // cello D reference string, torsion on (PHYSICS.md 1.6)
    c.friction.model = m;
    c.friction.fit = fit;
    c.friction.speedFunction = h;
    c.friction.contactLaw = law;
    return c;
}

SweepSpec sweepSpec(const FigureSetOptions& o, const dsp::BowedStringConfig& c, const std::string& label, int variants)
{
    SweepSpec s;
    s.config = c;
    s.label = label;
    s.sampleRate = o.sweepRate;
    s.accelerations = SweepSpec::grid(0.15, 3.0, o.grid);
    s.forces = SweepSpec::grid(0.15, 3.0, o.grid);
    s.variants = variants;
    s.seed = o.seed;
    return s;
}

void saveSweep(const fs::path& dir, const std::string& name, const SweepResult& r)
{
    writeSweepCsv(dir / (name + ".csv"), r);
    writeSweepJson(dir / (name + ".json"), r);
}

/// Fig. 18 style: the two steady-sliding fits and the two speed functions.
std::string frictionCurves(const fs::path& dir)
{
    Csv csv(dir / "mu_of_speed.csv");
    csv.row("speed_m_s,mu_smith_woodhouse,mu_woodhouse_galluzzo,h_bow,h_rod\n");
    std::vector<double> v, sw, wg, hb, hr;
    for (int i = 0; i <= 400; ++i) {
        const double x = std::pow(10.0, -4.0 + 4.0 * i / 400.0);
        v.push_back(x);
        sw.push_back(dsp::steadySliding(dsp::SteadyFit::SmithWoodhouse, x).mu);
        wg.push_back(dsp::steadySliding(dsp::SteadyFit::WoodhouseGalluzzo, x).mu);
        hb.push_back(dsp::speedFunction(dsp::SpeedFunction::Bow, x).mu);
        hr.push_back(dsp::speedFunction(dsp::SpeedFunction::Rod, x).mu);
        csv.row("%.6g,%.6g,%.6g,%.6g,%.6g\n", x, sw.back(), wg.back(), hb.back(), hr.back());
    }
    Canvas canvas(1200, 520);
    Axes lin(canvas, 80, 50, 470, 380, 0.0, 1.0, 0.0, 1.4);
    Axes lg(canvas, 690, 50, 470, 380, 1e-4, 1.0, 0.0, 1.4, true);
    for (Axes* ax : {&lin, &lg}) {
        ax->line(v, sw, colors::blue, 2.0);
        ax->line(v, wg, colors::red, 2.0);
        ax->line(v, hb, colors::green, 1.5, true);
        ax->line(v, hr, colors::orange, 1.5, true);
    }
    lin.frame("Steady-sliding friction (linear speed)", "sliding speed (m/s)", "friction coefficient");
    lg.frame("Steady-sliding friction (log speed)", "sliding speed (m/s)", "friction coefficient");
    lin.legend({{"mu SW: 0.4e^-v/0.01+0.45e^-v/0.1+0.35", colors::blue},
                {"mu WG: 0.2 (v+0.011)^-0.4", colors::red},
                {"h bow (enhanced)", colors::green},
                {"h rod (enhanced)", colors::orange}});
    canvas.save(dir / "mu_of_speed.png");
    return "mu_of_speed.png: the two steady-sliding fits and the speed functions (Fig. 18 style)";
}

/// Fig. 13 style: mu(theta) from inverting steady sliding, and y(theta) of the enhanced model.
std::string temperatureLaws(const fs::path& dir)
{
    dsp::ThermalParams tp;
    dsp::TemperatureLaw sw, wg, yb, yr;
    sw.build(dsp::SteadyFit::SmithWoodhouse, std::nullopt, tp);
    wg.build(dsp::SteadyFit::WoodhouseGalluzzo, std::nullopt, tp);
    yb.build(dsp::SteadyFit::WoodhouseGalluzzo, dsp::SpeedFunction::Bow, tp);
    yr.build(dsp::SteadyFit::WoodhouseGalluzzo, dsp::SpeedFunction::Rod, tp);
    Csv csv(dir / "mu_of_temperature.csv");
    csv.row("temperature_rise_K,contact_temperature_C,mu_from_sw,mu_from_wg,y_bow,y_rod\n");
    std::vector<double> t, a, b, c, d;
    for (int i = 0; i <= 300; ++i) {
        const double th = 60.0 * i / 300.0;
        t.push_back(th);
        a.push_back(sw(th));
        b.push_back(wg(th));
        c.push_back(yb(th));
        d.push_back(yr(th));
        csv.row("%.4g,%.4g,%.6g,%.6g,%.6g,%.6g\n", th, 20.0 + th, a.back(), b.back(), c.back(), d.back());
    }
    Canvas canvas(760, 560);
    Axes ax(canvas, 90, 50, 620, 420, 0.0, 60.0, 0.0, 2.4);
    ax.line(t, a, colors::blue, 2.0);
    ax.line(t, b, colors::red, 2.0);
    ax.line(t, c, colors::green, 1.6, true);
    ax.line(t, d, colors::orange, 1.6, true);
    ax.hline(1.0, colors::grey);
    ax.frame("Friction against contact temperature, by inverting steady sliding", "temperature rise above 20 C (K)",
             "mu(theta)  /  y(theta)");
    ax.legend({{"mu from SW fit (thermal)", colors::blue},
               {"mu from WG fit (thermal)", colors::red},
               {"y, bow (enhanced, WG)", colors::green},
               {"y, rod (enhanced, WG)", colors::orange}});
    canvas.save(dir / "mu_of_temperature.png");
    char buf[200];
    std::snprintf(buf, sizeof buf, "mu_of_temperature.png: mu(theta) and y(theta) (Fig. 13 style); WG theta_ss peaks at %.1f K", wg.thetaMax());
    return buf;
}

/// Figs. 14-15 style: the thermal-model transient at pixel (10,14) and its temperature.
std::string pixelTransient(const fs::path& dir, const FigureSetOptions& o, json& summary)
{
    SweepSpec s = sweepSpec(o, model(dsp::FrictionModel::Thermal, dsp::SteadyFit::SmithWoodhouse), "thermal (SW)", 1);
    s.sampleRate = o.transientRate;
    const double a = SweepSpec::grid(0.15, 3.0, 20)[9], F = SweepSpec::grid(0.15, 3.0, 20)[13];
    std::vector<dsp::BowFrame<double>> tr;
    const CellResult cell = simulateCell(s, a, F, 0.0899, 0, &tr);
    const double fs = s.sampleRate, f0 = s.config.string.fundamental();
    const int P = static_cast<int>(fs / f0), n = static_cast<int>(tr.size());
    double mean = 0, swing = 0;
    for (int k = 0; k < 10; ++k) {
        double lo = 1e300, hi = -1e300;
        for (int i = n - (k + 1) * P; i < n - k * P; ++i) {
            mean += tr[i].temperature;
            lo = std::min(lo, double(tr[i].temperature));
            hi = std::max(hi, double(tr[i].temperature));
        }
        swing += hi - lo;
    }
    mean = 20.0 + mean / (10.0 * P);
    swing /= 10.0;
    Csv csv(dir / "transient_pixel_10_14.csv");
    csv.row("time_s,bridge_force_N,contact_temperature_C,friction_force_N,stick\n");
    std::vector<double> t, fb, th;
    for (int i = 0; i < n; ++i) {
        csv.row("%.7g,%.7g,%.5g,%.7g,%d\n", i / fs, tr[i].bridgeForce, 20.0 + tr[i].temperature, tr[i].friction, tr[i].stick ? 1 : 0);
        if (i % 4 == 0) {
            t.push_back(1e3 * i / fs);
            fb.push_back(tr[i].bridgeForce);
            th.push_back(20.0 + tr[i].temperature);
        }
    }
    const double tMax = 1e3 * n / fs;
    double fLo = 0, fHi = 0;
    for (double x : fb) { fLo = std::min(fLo, x); fHi = std::max(fHi, x); }
    Canvas canvas(1100, 760);
    Axes top(canvas, 90, 50, 960, 290, 0.0, tMax, fLo - 0.1, fHi + 0.1);
    top.line(t, fb, colors::red, 1.1);
    char title[200];
    std::snprintf(title, sizeof title, "Thermal model (SW fit), pixel (10,14): a = %.2f m/s2, F = %.2f N; %s after %d periods",
                  a, F, regimeName(cell.regime), cell.transientPeriods);
    top.frame(title, "time (ms)", "bridge force (N)");
    double tLo = 1e300, tHi = -1e300;
    for (double x : th) { tLo = std::min(tLo, x); tHi = std::max(tHi, x); }
    Axes bottom(canvas, 90, 420, 960, 260, 0.0, tMax, std::floor(tLo / 10) * 10, std::ceil(tHi / 10) * 10 + 5);
    bottom.line(t, th, colors::purple, 1.1);
    bottom.hline(mean, colors::black, 1.2);
    std::snprintf(title, sizeof title, "Contact temperature: mean %.0f C, swing %.0f K per cycle in Helmholtz motion (seed: ~70 C, ~30 K)", mean, swing);
    bottom.frame(title, "time (ms)", "contact temperature (C)");
    canvas.save(dir / "transient_pixel_10_14.png");
    summary["pixel_10_14"] = {{"acceleration_m_s2", a}, {"force_N", F}, {"regime", regimeName(cell.regime)},
                              {"transient_periods", cell.transientPeriods}, {"mean_temperature_C", mean},
                              {"swing_K", swing}, {"seed_mean_C", 70.0}, {"seed_swing_K", 30.0}};
    std::snprintf(title, sizeof title, "transient_pixel_10_14.png: %s, mean %.0f C, swing %.0f K (seed ~70 C, ~30 K)",
                  regimeName(cell.regime), mean, swing);
    return title;
}

/// Fig. 6 style: friction force against bow-point velocity over Helmholtz cycles.
std::string velocityForceLoop(const fs::path& dir, const FigureSetOptions& o, json& summary)
{
    auto c = model(dsp::FrictionModel::Thermal, dsp::SteadyFit::SmithWoodhouse);
    const double fs = o.transientRate, vb = 0.1, F = 0.8, beta = 0.0899;
    dsp::BowedString<double> s;
    s.prepare(fs, c);
    const int n = static_cast<int>(0.8 * fs), P = static_cast<int>(fs / c.string.fundamental());
    std::vector<dsp::BowFrame<double>> fr(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) s.processSample(F, vb * std::min(1.0, i / (0.05 * fs)), beta, &fr[i]);
    std::vector<double> v, f;
    double area = 0;
    Csv csv(dir / "velocity_force_loop.csv");
    csv.row("time_s,bow_point_velocity_m_s,friction_force_N,contact_temperature_C,stick\n");
    for (int i = n - 3 * P; i < n; ++i) {
        v.push_back(fr[i].velocity);
        f.push_back(fr[i].friction);
        if (i + 1 < n) area += fr[i].velocity * fr[i + 1].friction - fr[i + 1].velocity * fr[i].friction;
        csv.row("%.7g,%.7g,%.7g,%.5g,%d\n", i / fs, fr[i].velocity, fr[i].friction, 20.0 + fr[i].temperature, fr[i].stick ? 1 : 0);
    }
    std::vector<double> sv, sf;
    for (int i = 0; i <= 200; ++i) {
        const double x = -1.6 + (1.6 + vb) * i / 200.0; // string velocity up to the bow's
        sv.push_back(x);
        sf.push_back(F * dsp::steadySliding(dsp::SteadyFit::SmithWoodhouse, vb - x).mu);
    }
    Canvas canvas(760, 560);
    Axes ax(canvas, 90, 50, 620, 420, -1.6, 0.3, 0.0, 1.1);
    ax.line(sv, sf, colors::grey, 1.6, true);
    ax.line(v, f, colors::red, 1.4);
    ax.frame("Thermal model, steady bowing: friction against velocity", "string velocity at the bow (m/s)", "friction force (N)");
    ax.legend({{area > 0 ? "simulated loop (anticlockwise)" : "simulated loop (clockwise)", colors::red},
               {"steady-sliding curve F mu_SW", colors::grey}});
    canvas.save(dir / "velocity_force_loop.png");
    summary["velocity_force_loop"] = {{"signed_area_N_m_s", 0.5 * area}, {"anticlockwise", area > 0}};
    return std::string("velocity_force_loop.png: hysteresis loop runs ") + (area > 0 ? "anticlockwise" : "CLOCKWISE") + " (Fig. 6 style)";
}

} // namespace

std::string writeFigureSet(const fs::path& dir, const FigureSetOptions& o)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw LabError(dir.string() + ": cannot create the output directory");
    std::ostringstream report;
    json summary;
    const auto start = std::chrono::steady_clock::now();
    Progress progress("figures", !o.quiet);
    int step = 0;
    const int steps = 9;
    auto advance = [&](const std::string& line) {
        report << line << "\n";
        progress.update(static_cast<double>(++step) / steps);
    };
    advance(frictionCurves(dir));
    advance(temperatureLaws(dir));
    advance(pixelTransient(dir, o, summary));
    advance(velocityForceLoop(dir, o, summary));

    // Fig. 19 style: the three models with the WG fit (enhanced with rod and bow functions).
    const auto WG = dsp::SteadyFit::WoodhouseGalluzzo;
    struct Named { std::string file, title; dsp::BowedStringConfig config; };
    const std::vector<Named> models{
        {"guettler_friction_curve", "friction curve", model(dsp::FrictionModel::FrictionCurve, WG)},
        {"guettler_thermal", "thermal", model(dsp::FrictionModel::Thermal, WG)},
        {"guettler_enhanced_rod", "enhanced, rod", model(dsp::FrictionModel::Enhanced, WG, dsp::SpeedFunction::Rod)},
        {"guettler_enhanced_bow", "enhanced, bow", model(dsp::FrictionModel::Enhanced, WG, dsp::SpeedFunction::Bow)}};
    std::vector<SweepResult> plain;
    std::vector<std::string> titles;
    DiagramOptions diag;
    diag.muS = 1.215;
    diag.muD = 0.35;
    for (const auto& m : models) {
        plain.push_back(runSweep(sweepSpec(o, m.config, m.title, 1)));
        saveSweep(dir, m.file, plain.back());
        titles.push_back(m.title);
        summary["success_cells"][m.file] = plain.back().successCount();
    }
    writePanelPng(dir / "guettler_models.png", plain, titles, 2, diag);
    advance("guettler_models.png: friction curve / thermal / enhanced rod / enhanced bow, WG fit (Fig. 19 style)");

    // Figs. 20-21 style: the minimum over five perturbed variants, for the three models.
    std::vector<SweepResult> minimum;
    std::vector<std::string> minTitles;
    double minSeconds = 0;
    for (std::size_t i : {std::size_t(0), std::size_t(1), std::size_t(3)}) {
        minimum.push_back(runSweep(sweepSpec(o, models[i].config, models[i].title, o.variants)));
        minSeconds += minimum.back().wallSeconds;
        saveSweep(dir, models[i].file + "_min" + std::to_string(o.variants), minimum.back());
        minTitles.push_back(models[i].title + ", min over " + std::to_string(o.variants));
        summary["success_cells"][models[i].file + "_min" + std::to_string(o.variants)] = minimum.back().successCount();
    }
    writePanelPng(dir / "guettler_min_over_variants.png", minimum, minTitles, 3, diag);
    summary["min_over_variants_seconds"] = minSeconds;
    char line[240];
    std::snprintf(line, sizeof line, "guettler_min_over_variants.png: three models, min over %d variants (Fig. 21 style), %.2f s",
                  o.variants, minSeconds);
    advance(line);

    // Amontons against Hertz with the fitted lower boundaries (min over variants: the speckle
    // of single runs blurs the boundary).
    std::vector<SweepResult> contact;
    for (auto law : {dsp::ContactLaw::Amontons, dsp::ContactLaw::PowerLaw}) {
        contact.push_back(runSweep(sweepSpec(o, model(dsp::FrictionModel::FrictionCurve, WG, dsp::SpeedFunction::Rod, law),
                                             law == dsp::ContactLaw::Amontons ? "Amontons" : "Hertz", o.variants)));
        const BoundaryFit fit = fitLowerBoundary(contact.back());
        const std::string name = law == dsp::ContactLaw::Amontons ? "amontons" : "hertz";
        saveSweep(dir, "guettler_" + name, contact.back());
        summary["boundary_exponent"][name] = {{"p", fit.p}, {"p_low", fit.pLow}, {"p_high", fit.pHigh}, {"c", fit.c}, {"valid", fit.valid}};
    }
    writePanelPng(dir / "guettler_amontons_vs_hertz.png", contact,
                  {"friction curve, Amontons", "friction curve, Hertz"}, 2, diag);
    std::snprintf(line, sizeof line, "guettler_amontons_vs_hertz.png: lower-boundary exponent p = %.2f (Amontons), %.2f (Hertz)",
                  summary["boundary_exponent"]["amontons"]["p"].get<double>(), summary["boundary_exponent"]["hertz"]["p"].get<double>());
    advance(line);

    // Time-step convergence: a 5x5 sub-grid at the sweep rate and at twice it.
    {
        Csv csv(dir / "convergence.csv");
        csv.row("model,rate_hz,rate2_hz,cells,success,success2,agreement,mean_abs_dNT,max_first_slip_rel_diff\n");
        for (std::size_t i : {std::size_t(0), std::size_t(1), std::size_t(3)}) {
            SweepSpec s1 = sweepSpec(o, models[i].config, models[i].title, o.variants);
            s1.accelerations = SweepSpec::grid(0.15, 3.0, 5);
            s1.forces = SweepSpec::grid(0.15, 3.0, 5);
            SweepSpec s2 = s1;
            s2.sampleRate = 2.0 * s1.sampleRate;
            const SweepResult r1 = runSweep(s1), r2 = runSweep(s2);
            int agree = 0, both = 0;
            double dNT = 0, dt1 = 0;
            for (std::size_t c = 0; c < r1.cells.size(); ++c) {
                const auto &x = r1.cells[c], &y = r2.cells[c];
                agree += (x.transientPeriods >= 0) == (y.transientPeriods >= 0);
                if (x.transientPeriods >= 0 && y.transientPeriods >= 0) { ++both; dNT += std::abs(x.transientPeriods - y.transientPeriods); }
                if (x.firstSlipTime > 0 && y.firstSlipTime > 0) dt1 = std::max(dt1, std::abs(x.firstSlipTime / y.firstSlipTime - 1.0));
            }
            const double agreement = double(agree) / double(r1.cells.size());
            csv.row("%s,%.0f,%.0f,%zu,%d,%d,%.3f,%.3f,%.5f\n", models[i].file.c_str(), s1.sampleRate, s2.sampleRate,
                    r1.cells.size(), r1.successCount(), r2.successCount(), agreement, both ? dNT / both : 0.0, dt1);
            summary["convergence"][models[i].file] = {{"agreement", agreement}, {"mean_abs_dNT", both ? dNT / both : 0.0},
                                                      {"max_first_slip_rel_diff", dt1}};
        }
    }
    advance("convergence.csv: 5x5 sub-grid at the sweep rate and twice it");
    summary["sweep_rate_hz"] = o.sweepRate;
    summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    writeJson(dir / "summary.json", summary);
    advance("summary.json: the numbers behind the figures");
    progress.finish();
    return report.str();
}

} // namespace rosin::lab
