// The diagnosis's figures and the per-stroke table beside them: maps.png (the measured,
// baseline and final Guettler maps) with strokes.csv, overlays.png, jumps.png and loops.png.
// report.md links them; writeDiagnosis (DiagnoseReport.cpp) calls these.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>

#include "DiagnoseEngine.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Figures.h"
#include "rosin/lab/Guettler.h"
#include "rosin/lab/Plot.h"

namespace rosin::lab::diag {
namespace fs = std::filesystem;

namespace {

/// The gesture the maps show: Guettler strokes when the set has them, else its commonest kind.
std::string mapGesture(const Diagnosis& d)
{
    std::map<std::string, int> count;
    for (const auto& g : d.gestures) ++count[g];
    if (count.count("guettler")) return "guettler";
    std::string best;
    for (const auto& [g, c] : count)
        if (best.empty() || c > count[best]) best = g;
    return best;
}

/// The verdicts of the strokes of one gesture as a Guettler map (axes = their distinct drives
/// and forces).
SweepResult asMap(const Diagnosis& d, const std::vector<StrokeFeatures>& feats, const std::string& label, const std::string& gesture)
{
    SweepResult r;
    std::set<double> A, F;
    for (std::size_t i = 0; i < d.drive.size(); ++i)
        if (d.gestures[i] == gesture) {
            A.insert(d.drive[i]);
            F.insert(d.force[i]);
        }
    r.spec.accelerations.assign(A.begin(), A.end());
    r.spec.forces.assign(F.begin(), F.end());
    r.spec.label = label;
    r.cells.resize(A.size() * F.size());
    for (auto& c : r.cells) c.regime = Regime::NoSlip;
    for (std::size_t i = 0; i < feats.size(); ++i) {
        if (d.gestures[i] != gesture) continue;
        const auto ia = static_cast<std::size_t>(std::distance(r.spec.accelerations.begin(), std::find(r.spec.accelerations.begin(), r.spec.accelerations.end(), d.drive[i])));
        const auto iF = static_cast<std::size_t>(std::distance(r.spec.forces.begin(), std::find(r.spec.forces.begin(), r.spec.forces.end(), d.force[i])));
        CellResult& c = r.cells[iF * A.size() + ia];
        c.acceleration = d.drive[i];
        c.force = d.force[i];
        c.transientPeriods = feats[i].transientPeriods;
        c.regime = feats[i].regime;
    }
    return r;
}

void overlays(const fs::path& file, const Diagnosis& d)
{
    // Three strokes that slipped in the data, low, middle and high force.
    std::vector<std::size_t> slipped;
    for (std::size_t i = 0; i < d.measured.size(); ++i)
        if (d.measured[i].firstSlip > 0) slipped.push_back(i);
    std::sort(slipped.begin(), slipped.end(), [&](std::size_t a, std::size_t b) { return d.force[a] < d.force[b]; });
    std::vector<std::size_t> pick;
    if (!slipped.empty())
        for (double q : {0.15, 0.5, 0.85}) pick.push_back(slipped[static_cast<std::size_t>(q * (slipped.size() - 1))]);
    Canvas canvas(1100, 260 * static_cast<int>(std::max<std::size_t>(1, pick.size())) + 40);
    for (std::size_t k = 0; k < pick.size(); ++k) {
        const std::size_t i = pick[k];
        const auto& m = d.measuredForce[i];
        const double fs = 48000.0;
        std::vector<double> t(m.size());
        for (std::size_t n = 0; n < t.size(); ++n) t[n] = 1e3 * n / fs;
        double lo = 0, hi = 0;
        for (const auto* v : {&m, &d.baselineForce[i], &d.finalForce[i]})
            for (double x : *v) { lo = std::min(lo, x); hi = std::max(hi, x); }
        Axes ax(canvas, 90, 40 + 260.0 * k, 960, 180, 0, t.empty() ? 1 : t.back(), lo - 0.1, hi + 0.1);
        ax.line(t, d.baselineForce[i], colors::red, 1.0);
        ax.line(t, d.finalForce[i], colors::blue, 1.0);
        ax.line(t, m, colors::black, 1.2);
        char title[160];
        if (d.gestures[i] == "exp_speed")
            std::snprintf(title, sizeof title, "stroke %s: v0/tv = %.2f m/s2, F = %.2f N", d.ids[i].c_str(), d.drive[i], d.force[i]);
        else if (d.gestures[i] == "exp_force")
            std::snprintf(title, sizeof title, "stroke %s: v = %.2f m/s, F0 = %.2f N", d.ids[i].c_str(), d.drive[i], d.force[i]);
        else
            std::snprintf(title, sizeof title, "stroke %s: a = %.2f m/s2, F = %.2f N", d.ids[i].c_str(), d.drive[i], d.force[i]);
        ax.frame(title, "time from the gesture start (ms)", "bridge force (N)");
        if (k == 0) ax.legend({{"measured", colors::black}, {"baseline: " + d.baseline.name(), colors::red}, {"final: " + d.final.name(), colors::blue}});
    }
    canvas.save(file);
}

void jumps(const fs::path& file, const Diagnosis& d)
{
    std::vector<double> fm, jm, jb, jf;
    double top = 0.1;
    for (std::size_t i = 0; i < d.measured.size(); ++i) {
        if (d.measured[i].firstSlip < 0) continue;
        fm.push_back(d.force[i]);
        jm.push_back(d.measured[i].firstDrop);
        jb.push_back(d.baselineSim[i].firstDrop);
        jf.push_back(d.finalSim[i].firstDrop);
        top = std::max({top, jm.back(), jb.back(), jf.back()});
    }
    Canvas canvas(760, 560);
    Axes ax(canvas, 90, 50, 620, 420, 0, *std::max_element(d.force.begin(), d.force.end()) * 1.05, 0, top * 1.1);
    ax.points(fm, jb, colors::red, 3.0);
    ax.points(fm, jf, colors::blue, 3.0);
    ax.points(fm, jm, colors::black, 2.5);
    ax.frame("Bridge-force drop at the first slip", "bow force (N)", "drop within 0.1 ms (N)");
    ax.legend({{"measured", colors::black}, {"baseline: " + d.baseline.name(), colors::red}, {"final: " + d.final.name(), colors::blue}}, false);
    canvas.save(file);
}

// The data of maps.png: every stroke's place, role in the split, features as recorded and as the
// baseline and the final model play it, and its disagreement part by part (uncapped parts are
// not kept: the metric caps each at 1).
void writeStrokeTable(const fs::path& file, const Diagnosis& d)
{
    std::map<std::string, const char*> role;
    for (const auto& id : d.fitIds) role[id] = "fit";
    for (const auto& id : d.validationIds) role[id] = "validation";
    for (const auto& id : d.heldoutIds) role[id] = "test";
    std::ofstream out(file);
    out << "id,gesture,drive,bow_force_n,role";
    for (const char* who : {"measured", "baseline", "final"})
        out << ',' << who << "_first_slip_s," << who << "_force_before_slip_n," << who << "_jump_n," << who << "_transient_periods," << who << "_regime";
    for (const char* who : {"baseline", "final"})
        out << ',' << who << "_error," << who << "_first_slip_part," << who << "_force_before_slip_part," << who << "_jump_part," << who
            << "_transient_part," << who << "_waveform_part";
    out << '\n';
    auto number = [](double x) { return fmt(x, "%.9g"); };
    for (std::size_t i = 0; i < d.ids.size(); ++i) {
        const auto r = role.find(d.ids[i]);
        out << d.ids[i] << ',' << d.gestures[i] << ',' << number(d.drive[i]) << ',' << number(d.force[i]) << ',' << (r == role.end() ? "none" : r->second);
        for (const auto* f : {&d.measured[i], &d.baselineSim[i], &d.finalSim[i]})
            out << ',' << number(f->firstSlip) << ',' << number(f->forceBeforeSlip) << ',' << number(f->firstDrop) << ',' << f->transientPeriods << ','
                << regimeName(f->regime);
        for (const auto* e : {&d.baselineParts[i], &d.finalParts[i]})
            out << ',' << number(e->total()) << ',' << number(e->firstSlip) << ',' << number(e->forceBeforeSlip) << ',' << number(e->jump) << ','
                << number(e->transient) << ',' << number(e->waveform);
        out << '\n';
    }
}

} // namespace

void writeLoopsFigure(const fs::path& file, const Diagnosis& d)
{
    Canvas canvas(560 * static_cast<int>(d.loops.size()), 520);
    for (std::size_t k = 0; k < d.loops.size(); ++k) {
        const auto& l = d.loops[k];
        double vlo = -0.2, vhi = 0.2, fhi = 0.2, flo = 0.0;
        for (const auto* v : {&l.measuredV, &l.finalV}) for (double x : *v) { vlo = std::min(vlo, x); vhi = std::max(vhi, x); }
        for (const auto* v : {&l.measuredF, &l.finalF}) for (double x : *v) { flo = std::min(flo, x); fhi = std::max(fhi, x); }
        Axes ax(canvas, 90 + 560.0 * k, 50, 440, 380, vlo - 0.05, vhi + 0.05, flo - 0.05, fhi * 1.1);
        ax.line(l.finalV, l.finalF, colors::blue, 1.2);
        ax.line(l.measuredV, l.measuredF, colors::black, 1.2);
        ax.frame(l.id + ": friction against bow-point velocity", "string velocity at the bow (m/s)", "friction force (N)");
        ax.legend({{std::string("measured, ") + (l.measuredArea > 0 ? "anticlockwise" : "clockwise"), colors::black},
                   {"final model, " + std::string(l.finalArea > 0 ? "anticlockwise" : "clockwise"), colors::blue}}, false);
    }
    canvas.save(file);
}

ShownMaps writeStrokeFigures(const fs::path& dir, const Diagnosis& d)
{
    ShownMaps maps;
    maps.gesture = mapGesture(d);
    maps.measured = asMap(d, d.measured, "measured", maps.gesture);
    maps.baseline = asMap(d, d.baselineSim, "baseline: " + d.baseline.name(), maps.gesture);
    maps.final = asMap(d, d.finalSim, "final: " + d.final.name(), maps.gesture);
    DiagramOptions dopt;
    dopt.bounds = false;
    if (maps.gesture == "exp_speed") dopt.xLabel = "initial bow acceleration v0/tv (m/s\u00b2)";
    if (maps.gesture == "exp_force") dopt.xLabel = "bow speed (m/s)";
    writePanelPng(dir / "maps.png", {maps.measured, maps.baseline, maps.final}, {"measured", "baseline: " + d.baseline.name(), "final: " + d.final.name()}, 3,
                  dopt);
    overlays(dir / "overlays.png", d);
    jumps(dir / "jumps.png", d);
    if (d.baselineParts.size() == d.ids.size() && d.finalParts.size() == d.ids.size()) writeStrokeTable(dir / "strokes.csv", d);
    return maps;
}

} // namespace rosin::lab::diag
