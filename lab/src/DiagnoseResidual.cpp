// The diagnosis's floor (noise and chaos) and the residual the final model leaves above it.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

#include "DiagnoseEngine.h"

namespace rosin::lab::diag {


std::string usualResidualText(const Residual& r)
{
    if (r.usual <= 0.0) return "no usual residual was given to compare it with";
    // Only past kFirmlyBeyondUsual (Diagnose.h says why) does the wording claim the rig has
    // something the model lacks.
    const char* verdict = isFirmlyBeyondUsual(r.ratio, r.usual)
                              ? "more than the model's usual difference from a real string, by a margin that about one rig in a hundred with "
                                "nothing hidden reaches: something on this rig the model lacks"
                          : r.ratio > r.usual
                              ? "a little more than the model's usual difference from a real string (about one rig in twenty with nothing "
                                "hidden passes that bound, and those that do by up to 40 %): a hint that this rig has something the model "
                                "lacks, not a finding"
                              : "within the model's usual difference from a real string, and says no more than that";
    char buf[700];
    std::snprintf(buf, sizeof buf,
                  "on the studies' reference rigs with nothing hidden (strings, bridges and sensors that differ from the model's as a "
                  "lab's usually do) the final error stays within %.1f times the floor on about nineteen in twenty; %.1f times is %s",
                  r.usual, r.ratio, verdict);
    return buf;
}

Residual measureResidual(const Engine& engine, const EffectModel& current, const std::vector<std::size_t>& testSet,
                         const std::vector<ErrorParts>& currentTest, const std::vector<Prepared>& strokes, const DiagnoseOptions& o)
{
    // The floor: the final model against itself with the rig's 1 % stroke-to-stroke scatter of
    // force and acceleration (transients are chaotic), each run with its own noise draw.
        std::vector<ErrorParts> floorParts(testSet.size());
        tbb::parallel_for(std::size_t(0), testSet.size(), [&](std::size_t k) {
            const std::size_t i = testSet[k];
            std::mt19937_64 jr(o.seed * 977ull + i);
            std::uniform_real_distribution<double> j(-0.01, 0.01);
            const StrokeFeatures a = engine.simulate(current, i, nullptr, j(jr), j(jr), 1);
            const StrokeFeatures b = engine.simulate(current, i, nullptr, j(jr), j(jr), 2);
            floorParts[k] = compare(a, b, strokes[i].gesture, engine.info(), engine.metricWeights());
        });
        Residual r;
        r.error = mean(currentTest);
        r.floor = std::max(mean(floorParts), 0.01);
        r.ratio = r.error / r.floor;
        r.present = r.ratio > o.residualFactor;
        r.usual = o.usualResidualRatio;
        r.beyondUsual = r.present && r.usual > 0.0 && r.ratio > r.usual;
        const char* names[] = {"first-slip time", "bridge force before the first slip", "first-slip jump", "transient length", "waveform after the first slip"};
        const auto& w = engine.metricWeights();
        double partErr[5] = {0, 0, 0, 0, 0}, partFloor[5] = {0, 0, 0, 0, 0};
        for (std::size_t k = 0; k < testSet.size(); ++k) {
            const ErrorParts& e = currentTest[k];
            const ErrorParts& f = floorParts[k];
            const double pe[] = {e.firstSlip, e.forceBeforeSlip, e.jump, e.transient, e.waveform};
            const double pf[] = {f.firstSlip, f.forceBeforeSlip, f.jump, f.transient, f.waveform};
            for (int q = 0; q < 5; ++q) { partErr[q] += w[q] * pe[q]; partFloor[q] += w[q] * pf[q]; }
        }
        for (int q = 0; q < 5; ++q) {
            const double excess = (partErr[q] - partFloor[q]) / static_cast<double>(testSet.size());
            r.partError[names[q]] = partErr[q] / static_cast<double>(testSet.size());
            r.partFloor[names[q]] = partFloor[q] / static_cast<double>(testSet.size());
            if (excess > 0.005) r.parts[names[q]] = excess;
        }
        // Where: the quadrant of the Guettler plane (bow acceleration x force; for the other
        // gestures their drive x force) with the largest excess.
        const std::vector<bool> highDrive = upperDriveHalf(testSet, strokes);
        std::vector<double> fs;
        bool guettlerOnly = true;
        for (auto i : testSet) {
            fs.push_back(strokes[i].gesture.force);
            guettlerOnly = guettlerOnly && strokes[i].gesture.kind == GestureKind::Guettler;
        }
        const double fm = median(fs);
        double worst = -1;
        for (int qa = 0; qa < 2; ++qa)
            for (int qf = 0; qf < 2; ++qf) {
                double sum = 0;
                int cnt = 0;
                for (std::size_t k = 0; k < testSet.size(); ++k)
                    if (highDrive[k] == (qa == 1) && (strokes[testSet[k]].gesture.force >= fm) == (qf == 1)) {
                        sum += currentTest[k].total() - floorParts[k].total();
                        ++cnt;
                    }
                if (cnt > 0 && sum / cnt > worst) {
                    worst = sum / cnt;
                    r.where = std::string(qa ? "high" : "low") + (guettlerOnly ? " bow acceleration, " : " gesture drive (acceleration or speed), ") +
                              (qf ? "high" : "low") + " bow force";
                }
            }
        // What it looks like.
        double slipBias = 0, forceBias = 0;
        int cnt = 0;
        std::vector<double> logV, logF;
        for (auto i : testSet) {
            const StrokeFeatures& m = strokes[i].feat;
            // A rising-force stroke's bow speed is set, not reached: it says nothing here.
            if (m.firstSlip <= 0 || strokes[i].gesture.kind == GestureKind::ExpForce) continue;
            logV.push_back(std::log(strokes[i].gesture.at(m.firstSlip).speed));
            logF.push_back(std::log(strokes[i].gesture.force));
            ++cnt;
        }
        for (std::size_t k = 0; k < testSet.size(); ++k) {
            const std::size_t i = testSet[k];
            const StrokeFeatures sim = engine.simulate(current, i);
            if (strokes[i].feat.firstSlip > 0 && sim.firstSlip > 0) {
                slipBias += (sim.firstSlip - strokes[i].feat.firstSlip) / strokes[i].feat.firstSlip;
                forceBias += (sim.forceBeforeSlip - strokes[i].feat.forceBeforeSlip) / strokes[i].gesture.force;
            }
        }
        slipBias /= std::max<std::size_t>(1, testSet.size());
        forceBias /= std::max<std::size_t>(1, testSet.size());
        double slope = 0.5;
        if (logV.size() > 4) {
            const double mv = std::accumulate(logV.begin(), logV.end(), 0.0) / logV.size(), mf = std::accumulate(logF.begin(), logF.end(), 0.0) / logF.size();
            double sxy = 0, sxx = 0;
            for (std::size_t k = 0; k < logV.size(); ++k) { sxy += (logF[k] - mf) * (logV[k] - mv); sxx += (logF[k] - mf) * (logF[k] - mf); }
            if (sxx > 0) slope = sxy / sxx;
        }
        std::string look;
        char buf[240];
        if (slope < 0.15) {
            std::snprintf(buf, sizeof buf, "the first slip comes at a nearly fixed bow speed whatever the force (bow speed at slip ~ F^%.2f; a static-friction law gives about F^0.5)", slope);
            look = buf;
        } else if (r.parts.count("waveform after the first slip") || r.parts.count("transient length")) {
            const bool jump = r.parts.count("first-slip jump") > 0;
            look = std::string("the waveform and transients after the first slip disagree more than chaos allows") +
                   (jump ? ", and so does the first slip's jump" : "") +
                   (r.parts.count("first-slip time") ? "" : (jump ? ", while" : " while") + std::string(" the first slip comes when the model's does")) +
                   ": a period or waveform mismatch such as string stiffness or a compliant bridge gives";
        } else {
            std::snprintf(buf, sizeof buf, "the model's first slips come %.1f %% %s and its pre-slip bridge force is %.1f %% of the bow force %s on average",
                          100 * std::abs(slipBias), slipBias > 0 ? "late" : "early", 100 * std::abs(forceBias), forceBias > 0 ? "high" : "low");
            look = buf;
        }
        r.looksLike = look;
        return r;
}

std::string standInRuleText(double usualRatio)
{
    char usual[32];
    std::snprintf(usual, sizeof usual, "%.3g", usualRatio);
    return "(6) When the final model leaves a residual beyond the usual one (more than " + std::string(usual) +
           " times the set's floor), the model may lack something on this rig, and a rate dependence or a rosin shift (a further "
           "bend of the thermal law) or a rolling string (a softer bow point) can stand in for it: those are reported as possible "
           "stand-ins with their parameters, not as findings, while thermal memory and a contact law stay named.";
}

std::size_t setAsideStandIns(Diagnosis& d)
{
    if (!d.residual.beyondUsual) return 0;
    // Thermal memory and a contact law stay: neither was ever named where it was not hidden
    // (seeds 2044-2047, far stiffer strings, a far more compliant bridge). Thermal memory moves
    // first-slip jumps by tens of per cent of the bow force, a missing stiffness by a few; a
    // contact law sets how friction scales with the bow force, which no stiffness does (on two
    // studies of strings ten times stiffer than the prior's, every contact the rounds named was
    // hidden, five of six within 0.05 of its exponent). A rate law or a rosin shift bends the
    // thermal law and a rolling string softens the bow point, and those stood in: a +25 K shift
    // for a hidden rate law (seed 2101, 8.8 floors), a shift and a torsion beside a hidden rate
    // law (seed 2103, 9.0 floors).
    const auto standIn = [](const Finding& f) { return f.effect != "thermal_memory" && f.effect != "hertzian_contact"; };
    std::size_t moved = 0;
    for (const Finding& f : d.findings)
        if (standIn(f)) {
            d.standIns.push_back(f);
            ++moved;
        }
    d.findings.erase(std::remove_if(d.findings.begin(), d.findings.end(), standIn), d.findings.end());
    return moved;
}

} // namespace rosin::lab::diag
