#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Figures.h"
#include "rosin/lab/Guettler.h"
#include "rosin/lab/Plot.h"

namespace rosin::lab {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// The strokes' verdicts as a Guettler map (axes = the distinct accelerations and forces).
SweepResult asMap(const Diagnosis& d, const std::vector<StrokeFeatures>& feats, const std::string& label)
{
    SweepResult r;
    std::set<double> A(d.accel.begin(), d.accel.end()), F(d.force.begin(), d.force.end());
    r.spec.accelerations.assign(A.begin(), A.end());
    r.spec.forces.assign(F.begin(), F.end());
    r.spec.label = label;
    r.cells.resize(A.size() * F.size());
    for (auto& c : r.cells) c.regime = Regime::NoSlip;
    for (std::size_t i = 0; i < feats.size(); ++i) {
        const auto ia = static_cast<std::size_t>(std::distance(r.spec.accelerations.begin(), std::find(r.spec.accelerations.begin(), r.spec.accelerations.end(), d.accel[i])));
        const auto iF = static_cast<std::size_t>(std::distance(r.spec.forces.begin(), std::find(r.spec.forces.begin(), r.spec.forces.end(), d.force[i])));
        CellResult& c = r.cells[iF * A.size() + ia];
        c.acceleration = d.accel[i];
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
        std::snprintf(title, sizeof title, "stroke %s: a = %.2f m/s2, F = %.2f N", d.ids[i].c_str(), d.accel[i], d.force[i]);
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

std::string fmt(double x, const char* f = "%.3g")
{
    char b[64];
    std::snprintf(b, sizeof b, f, x);
    return b;
}

} // namespace

void writeDiagnosis(const fs::path& dir, const Diagnosis& d, const DiagnoseOptions& o)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw LabError(dir.string() + ": cannot create the output directory");
    json findings = json::array();
    for (const auto& f : d.findings) {
        json params = json::object();
        for (const auto& [name, v] : f.parameters) params[name] = {{"value", v[0]}, {"ci95", {v[1], v[2]}}};
        findings.push_back({{"effect", f.effect}, {"evidence", f.evidence}, {"parameters", params},
                            {"heldout_error_before", f.heldoutBefore}, {"heldout_error_after", f.heldoutAfter}});
    }
    if (d.findings.empty())
        findings.push_back({{"effect", "none"}, {"evidence", "No extension lowered the held-out error significantly: the baseline explains the data within its scatter (held-out error " + fmt(d.baselineError) + ")."},
                            {"parameters", json::object()}, {"heldout_error_before", d.baselineError}, {"heldout_error_after", d.baselineError}});
    const json doc{
        {"format", "rosin-diagnosis/1"},
        {"set", d.setName},
        {"baseline_model", d.baseline.name()},
        {"findings", findings},
        {"final_model", d.final.name()},
        {"gain", {{"metric", "mean over held-out strokes of a weighted sum of five parts, each capped at 1: first-slip time "
                              "(relative, 0.25), bridge force before the first slip (per newton of bow force, 0.25), first-slip jump "
                              "(per newton, 0.25), transient length (per 25 periods, failures as 30; 0.10) and waveform rms over 2 "
                              "periods after the first slip (per ideal flyback, 0.15)"},
                  {"baseline", d.baselineError}, {"final", d.finalError}, {"relative", d.relativeGain},
                  {"ci95", {d.gainLow, d.gainHigh}}, {"n_fit", d.nFit}, {"n_heldout", d.nHeldout}}},
        {"calibration", {{"scale_n_per_unit", d.scale}, {"trigger_offsets_detected", d.triggersDetected}}},
        {"warnings", d.warnings}};
    std::ofstream(dir / "diagnosis.json") << doc.dump(1) << "\n";
    // The recorded split (reproducible from the seed), and the two-ended loops, beside it.
    std::ofstream(dir / "split.json") << json{{"seed", o.seed}, {"fit", d.fitIds}, {"heldout", d.heldoutIds}}.dump(1) << "\n";
    if (!d.loops.empty()) {
        json loops = json::array();
        for (const auto& l : d.loops)
            loops.push_back({{"id", l.id}, {"measured_area", l.measuredArea}, {"final_area", l.finalArea},
                             {"measured_orientation", l.measuredArea > 0 ? "anticlockwise" : "clockwise"},
                             {"final_orientation", l.finalArea > 0 ? "anticlockwise" : "clockwise"}});
        std::ofstream(dir / "two_ended.json") << json{{"method", "Schumacher reconstruction, ideal ends (PHYSICS.md 7.2 A)"}, {"loops", loops}}.dump(1) << "\n";
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
        canvas.save(dir / "loops.png");
    }

    const SweepResult measured = asMap(d, d.measured, "measured"), base = asMap(d, d.baselineSim, "baseline: " + d.baseline.name()),
                      fin = asMap(d, d.finalSim, "final: " + d.final.name());
    DiagramOptions dopt;
    dopt.bounds = false;
    writePanelPng(dir / "maps.png", {measured, base, fin}, {"measured", "baseline: " + d.baseline.name(), "final: " + d.final.name()}, 3, dopt);
    overlays(dir / "overlays.png", d);
    jumps(dir / "jumps.png", d);

    std::ofstream md(dir / "report.md");
    md << "# Diagnosis of " << d.setName << "\n\n";
    md << "Baseline: **" << d.baseline.name() << "** (friction curve, Amontons contact, no torsion, reference violin rosin). "
       << "Final: **" << d.final.name() << "**.\n\n";
    md << "Held-out error " << fmt(d.baselineError) << " → " << fmt(d.finalError) << ": relative gain " << fmt(100 * d.relativeGain, "%.0f")
       << " % (95 % CI " << fmt(100 * d.gainLow, "%.0f") << "–" << fmt(100 * d.gainHigh, "%.0f") << " %), on " << d.nHeldout
       << " strokes not used for fitting (" << d.nFit << " fitted; split from seed " << o.seed << ", listed in split.json).\n\n";
    md << "## Findings\n\n";
    if (d.findings.empty()) md << "None: no extension lowered the held-out error significantly.\n\n";
    for (const auto& f : d.findings) {
        md << "### " << f.effect << "\n\n" << f.evidence << "\n\n| parameter | value | 95 % CI |\n|---|---|---|\n";
        for (const auto& [name, v] : f.parameters) md << "| " << name << " | " << fmt(v[0]) << " | " << fmt(v[1]) << " – " << fmt(v[2]) << " |\n";
        md << "\n";
    }
    const BoundaryFit bm = fitLowerBoundary(measured), bb = fitLowerBoundary(base), bf = fitLowerBoundary(fin);
    md << "## Guettler maps\n\n![maps](maps.png)\n\nHelmholtz cells: measured " << measured.successCount() << ", baseline "
       << base.successCount() << ", final " << fin.successCount() << " of " << measured.cells.size() << ". Lower-boundary exponent p: measured "
       << (bm.valid ? fmt(bm.p) : "n/a") << ", baseline " << (bb.valid ? fmt(bb.p) : "n/a") << ", final " << (bf.valid ? fmt(bf.p) : "n/a") << ".\n\n";
    md << "## Waveforms\n\n![overlays](overlays.png)\n\n## First-slip jumps\n\n![jumps](jumps.png)\n\n";
    if (!d.loops.empty()) {
        md << "## Two-ended strokes (Schumacher)\n\n![loops](loops.png)\n\n| stroke | measured loop | final model |\n|---|---|---|\n";
        for (const auto& l : d.loops)
            md << "| " << l.id << " | " << (l.measuredArea > 0 ? "anticlockwise" : "clockwise") << " (" << fmt(l.measuredArea) << " N m/s) | "
               << (l.finalArea > 0 ? "anticlockwise" : "clockwise") << " (" << fmt(l.finalArea) << " N m/s) |\n";
        md << "\nAnticlockwise loops mean friction is lower on the way back from a slip than on the way out: the contact "
              "heated while slipping (PHYSICS.md 7.3). A friction-curve model only loops through its jump rule.\n\n";
    }
    md << "## What was tried\n\n| round | extension | fitted parameters | fit error | held-out fall | 95 % CI | kept |\n|---|---|---|---|---|---|---|\n";
    for (const auto& t : d.trials) {
        std::string ps;
        for (const auto& [k, v] : t.parameters) ps += (ps.empty() ? "" : ", ") + k + " = " + fmt(v);
        md << "| " << t.round << " | " << t.effect << " | " << ps << " | " << fmt(t.fitError) << " | " << fmt(t.gain) << " | "
           << fmt(t.gainLow) << " – " << fmt(t.gainHigh) << " | " << (t.kept ? "yes" : "") << " |\n";
    }
    md << "\n";
    md << "## Method\n\nEvery recording is low-passed, cleaned of DC and mains hum, and its gesture start found by fitting the "
          "quasi-static ramp T·x_b/(βL) before the first slip; one scale (the median over strokes whose first slip comes after "
          "4 periods) converts the whole set to newtons (" << fmt(d.scale) << " N per unit). Strokes are split into fit and held-out sets "
          "from the seed before any fitting. In each round every extension of DIAGNOSIS.md is fitted on the fit set (NLopt COBYLA); "
          "the one whose held-out error falls most is kept if the 95 % paired-bootstrap interval of the fall excludes 0, the fall is at least "
       << fmt(100 * o.minRelativeGain, "%.0f") << " % of the error, and its parameters are not at the effect's own absence "
          "(Hertz exponent within 0.05 of 1, rosin shift within 2 K of 0, Z_t/Z_0 above 7, speed exponent below 0.12): there a "
          "held-out gain is the chaos of transients, not physics. Parameter intervals come from " << o.parameterBootstrap
       << " refits on bootstrap resamples of the fit set. " << d.simulations << " simulations in " << fmt(d.seconds, "%.1f") << " s.\n";
    for (const auto& w : d.warnings) md << "\nWarning: " << w << "\n";
}

} // namespace rosin::lab
