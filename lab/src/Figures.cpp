#include "rosin/lab/Figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "rosin/lab/Error.h"

namespace rosin::lab {

void drawGuettler(Canvas& canvas, double left, double top, double width, double height, const SweepResult& r,
                  std::size_t ib, const DiagramOptions& o)
{
    const auto& A = r.spec.accelerations;
    const auto& F = r.spec.forces;
    if (A.empty() || F.empty() || r.cells.size() < A.size() * F.size() * (ib + 1))
        throw LabError("a Guettler diagram needs a result for every bow acceleration and force of its grid (at least one of each)");
    const double da = A.size() > 1 ? A[1] - A[0] : A[0], dF = F.size() > 1 ? F[1] - F[0] : F[0];
    const double aMax = A.back() + da / 2, fMax = F.back() + dF / 2;
    Axes ax(canvas, left, top, width, height, 0.0, aMax, 0.0, fMax);
    for (std::size_t ia = 0; ia < A.size(); ++ia)
        for (std::size_t iF = 0; iF < F.size(); ++iF) {
            const CellResult& c = r.at(ia, iF, ib);
            const Color col = c.transientPeriods >= 0 ? transientColor(c.transientPeriods) : regimeColor(c.regime);
            ax.rect(A[ia] - da / 2, F[iF] - dF / 2, A[ia] + da / 2, F[iF] + dF / 2, col);
            if (c.regime == Regime::SMotion) ax.points({A[ia]}, {F[iF]}, colors::black, 1.6);
        }
    std::vector<std::pair<std::string, Color>> legend;
    if (o.bounds) {
        const GuettlerBounds b = guettlerBounds(r.spec.config.string, r.spec.betas[ib], o.muS, o.muD);
        ax.line({0, aMax}, {0, b.lowerPerAccel * aMax}, colors::magenta, 1.8, true);
        ax.line({0, aMax}, {0, b.upperPerAccel * aMax}, colors::purple, 1.8, true);
        char buf[96];
        std::snprintf(buf, sizeof buf, "Guettler bounds, mu %.2g/%.2g", o.muS, o.muD);
        legend.emplace_back(buf, colors::magenta);
    }
    if (o.fit) {
        const BoundaryFit fit = fitLowerBoundary(r, ib);
        if (fit.valid) {
            std::vector<double> xs, ys;
            for (int i = 0; i <= 60; ++i) {
                const double a = A.front() + (A.back() - A.front()) * i / 60.0;
                xs.push_back(a);
                ys.push_back(fit.c * std::pow(a, fit.p));
            }
            ax.line(xs, ys, colors::black, 2.2);
            ax.points(fit.accelerations, fit.forces, colors::black, 2.2);
            char buf[96];
            std::snprintf(buf, sizeof buf, "fit F = %.2f a^%.2f (p in %.2f..%.2f)", fit.c, fit.p, fit.pLow, fit.pHigh);
            legend.emplace_back(buf, colors::black);
        }
    }
    char title[160];
    std::snprintf(title, sizeof title, "%s  (beta %.4g, %d/%zu Helmholtz)", o.title.empty() ? r.spec.label.c_str() : o.title.c_str(),
                  r.spec.betas[ib], [&] {
                      int n = 0;
                      for (std::size_t ia = 0; ia < A.size(); ++ia)
                          for (std::size_t iF = 0; iF < F.size(); ++iF) n += r.at(ia, iF, ib).transientPeriods >= 0;
                      return n;
                  }(),
                  A.size() * F.size());
    ax.frame(title, o.xLabel, "bow force (N)");
    if (!legend.empty()) ax.legendBelow(legend);
}

void drawColorKey(Canvas& canvas, double left, double top, double height)
{
    const double w = 18, barH = height * 0.6;
    for (int i = 0; i < 100; ++i) {
        const double p = 25.0 * (99 - i) / 99.0;
        const Color c = transientColor(static_cast<int>(std::lround(p)));
        Axes dummy(canvas, left, top, w, barH, 0, 1, 0, 1);
        dummy.rect(0, 1.0 - (i + 1) / 100.0, 1, 1.0 - i / 100.0, c);
    }
    for (int p : {0, 5, 10, 15, 20, 25})
        canvas.text(left + w + 5, top + barH * (1.0 - p / 25.0), std::to_string(p), 11, colors::black, 0.0, 0.35);
    canvas.text(left - 4, top - 10, "periods to Helmholtz", 11, colors::black, 0.0, 0.0);
    const std::pair<const char*, Regime> fails[] = {{"double slip", Regime::DoubleSlip},
                                                    {"double flyback", Regime::DoubleFlyback},
                                                    {"irregular", Regime::Irregular},
                                                    {"no slip", Regime::NoSlip}};
    double y = top + barH + 20;
    for (const auto& [name, regime] : fails) {
        Axes box(canvas, left, y, w, 12, 0, 1, 0, 1);
        box.rect(0, 0, 1, 1, regimeColor(regime));
        canvas.text(left + w + 5, y + 10, name, 11);
        y += 18;
    }
    Axes dot(canvas, left, y, w, 12, 0, 1, 0, 1);
    dot.points({0.5}, {0.5}, colors::black, 2.0);
    canvas.text(left + w + 5, y + 10, "S-motion", 11);
}

void writeGuettlerPng(const std::filesystem::path& file, const SweepResult& r, const DiagramOptions& o)
{
    const int nb = static_cast<int>(r.spec.betas.size());
    const int cellW = 600, height = 600;
    Canvas canvas(cellW * nb + 170, height);
    for (int ib = 0; ib < nb; ++ib) drawGuettler(canvas, 80 + ib * cellW, 50, cellW - 120, height - 150, r, static_cast<std::size_t>(ib), o);
    drawColorKey(canvas, cellW * nb + 20, 90, height - 200);
    canvas.save(file);
}

void writePanelPng(const std::filesystem::path& file, const std::vector<SweepResult>& sweeps,
                   const std::vector<std::string>& titles, int columns, const DiagramOptions& o)
{
    if (sweeps.empty()) throw LabError("panel: nothing to draw");
    columns = std::max(1, std::min(columns, static_cast<int>(sweeps.size())));
    const int rows = (static_cast<int>(sweeps.size()) + columns - 1) / columns;
    const int cellW = 520, cellH = 520;
    Canvas canvas(cellW * columns + 170, cellH * rows);
    for (std::size_t i = 0; i < sweeps.size(); ++i) {
        const int col = static_cast<int>(i) % columns, row = static_cast<int>(i) / columns;
        DiagramOptions oi = o;
        if (i < titles.size()) oi.title = titles[i];
        drawGuettler(canvas, 80 + col * cellW, 45 + row * cellH, cellW - 115, cellH - 140, sweeps[i], 0, oi);
    }
    drawColorKey(canvas, cellW * columns + 20, 90, std::min(cellH, 600) - 200);
    canvas.save(file);
}

SweepResult readSweepJson(const std::filesystem::path& file)
{
    using nlohmann::json;
    std::ifstream in(file);
    if (!in) throw LabError(file.string() + ": cannot open sweep table");
    json doc;
    try {
        doc = json::parse(in);
    } catch (const json::exception& e) {
        throw LabError(file.string() + ": not valid JSON (" + e.what() + ")");
    }
    if (doc.value("format", "") != "rosin-guettler/1") throw LabError(file.string() + ": field 'format' must be \"rosin-guettler/1\"");
    SweepResult r;
    try {
        const json& s = doc.at("spec");
        r.spec.label = s.at("model").get<std::string>();
        r.spec.sampleRate = s.at("sample_rate_hz").get<double>();
        r.spec.accelerations = s.at("accelerations_m_s2").get<std::vector<double>>();
        r.spec.forces = s.at("forces_N").get<std::vector<double>>();
        r.spec.betas = s.at("betas").get<std::vector<double>>();
        r.spec.variants = s.at("variants").get<int>();
        const json& sp = s.at("string_params");
        r.spec.config.string.name = s.at("string").get<std::string>();
        r.spec.config.string.length = sp.at("length_m").get<double>();
        r.spec.config.string.tension = sp.at("tension_N").get<double>();
        r.spec.config.string.massPerLength = sp.at("mass_per_length_kg_m").get<double>();
        for (const json& c : doc.at("cells")) {
            CellResult cell;
            cell.beta = c.at("beta").get<double>();
            cell.acceleration = c.at("accel_m_s2").get<double>();
            cell.force = c.at("force_N").get<double>();
            cell.firstSlipTime = c.at("first_slip_s").get<double>();
            cell.forceBeforeSlip = c.at("bridge_force_before_slip_N").get<double>();
            cell.firstJump = c.at("first_jump_N").get<double>();
            cell.transientPeriods = c.at("transient_periods").get<int>();
            const std::string reg = c.at("regime").get<std::string>();
            cell.regime = Regime::Irregular;
            for (Regime x : {Regime::Helmholtz, Regime::SMotion, Regime::DoubleSlip, Regime::DoubleFlyback, Regime::Irregular, Regime::NoSlip})
                if (reg == regimeName(x)) cell.regime = x;
            cell.peakTemperature = c.at("peak_temperature_K").get<double>();
            cell.variant = c.at("variant").get<int>();
            r.cells.push_back(cell);
        }
    } catch (const json::exception& e) {
        throw LabError(file.string() + ": missing or malformed field (" + e.what() + ")");
    }
    if (r.cells.size() != r.spec.accelerations.size() * r.spec.forces.size() * r.spec.betas.size())
        throw LabError(file.string() + ": field 'cells' does not match the axes");
    return r;
}

} // namespace rosin::lab
