// The two-ended steady strokes of a set: bow-point velocity and friction reconstructed from the
// forces at both ends of the string (Schumacher's method), measured and as a model shows them.
#include <algorithm>

#include "DiagnoseEngine.h"
#include "rosin/lab/Resample.h"
#include "rosin/lab/Schumacher.h"

namespace rosin::lab::diag {

std::vector<LoopComparison> compareTwoEnded(const MeasurementSet& set, const StringInfo& info, const Engine& engine, const EffectModel& final,
                                            double scale, const DiagnoseOptions& o, const std::function<void(const std::string&)>& say)
{
    std::vector<LoopComparison> out;
    for (const auto& rec : set.twoEnded) {
        say("two-ended " + rec.id);
        LoopComparison lc;
        lc.id = rec.id;
        const double c = 2.0 * info.length * info.f0, tb = info.beta * info.length / c, tn = (1.0 - info.beta) * info.length / c;
        const double toN = set.units == "V" ? scale : 1.0;
        auto clean = [&](std::vector<double> x) {
            std::vector<double> head(x.begin(), x.begin() + static_cast<long>(std::min<std::size_t>(x.size(), static_cast<std::size_t>(2e-3 * set.sampleRate) + 1)));
            const double dc = median(head); // the bow starts from rest: the first moments are the sensor's zero
            for (double& v : x) v = (v - dc) * toN;
            zeroPhaseLowPass(x, kCompareCutoff, set.sampleRate);
            return x;
        };
        const Reconstruction m = reconstruct(clean(rec.bridge), clean(rec.far), set.sampleRate, tb, tn, info.z0);
        const auto P = static_cast<std::size_t>(set.sampleRate / info.f0);
        if (m.velocity.size() > 4 * P) {
            lc.measuredV.assign(m.velocity.end() - static_cast<long>(3 * P), m.velocity.end());
            lc.measuredF.assign(m.friction.end() - static_cast<long>(3 * P), m.friction.end());
            lc.measuredArea = loopArea(lc.measuredV, lc.measuredF, 0, lc.measuredV.size());
        }
        dsp::BowedString<double> sim;
        sim.prepare(o.simRate, engine.config(final));
        std::vector<double> b(rec.bridge.size() * static_cast<std::size_t>(o.simRate) / static_cast<std::size_t>(set.sampleRate)), f(b.size());
        for (std::size_t i = 0; i < b.size(); ++i) {
            const double t = static_cast<double>(i) / o.simRate;
            b[i] = sim.processSample(rec.force, rec.bowSpeed * std::min(1.0, t / 0.03), engine.beta(final));
            f[i] = sim.waveguide().farEndForce();
        }
        zeroPhaseLowPass(b, kCompareCutoff, o.simRate);
        zeroPhaseLowPass(f, kCompareCutoff, o.simRate);
        const Reconstruction s2 = reconstruct(b, f, o.simRate, tb, tn, info.z0);
        const auto Ps = static_cast<std::size_t>(o.simRate / info.f0);
        if (s2.velocity.size() > 4 * Ps) {
            lc.finalV.assign(s2.velocity.end() - static_cast<long>(3 * Ps), s2.velocity.end());
            lc.finalF.assign(s2.friction.end() - static_cast<long>(3 * Ps), s2.friction.end());
            lc.finalArea = loopArea(lc.finalV, lc.finalF, 0, lc.finalV.size());
        }
        out.push_back(std::move(lc));
    }
    return out;
}

} // namespace rosin::lab::diag
