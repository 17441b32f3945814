// Calibration pieces of the diagnosis: covariances from the local curvature (Eigen) and the
// rig's steady-sliding curve fitted to its steady_sliding.csv.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>

#include <tbb/parallel_for.h>

#include "DiagnoseEngine.h"
#include "rosin/lab/Classifier.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Resample.h"

namespace rosin::lab::diag {

/// Covariance of x by the local curvature: residuals r(x) (one per stroke), Jacobian by central
/// differences with the given steps, s^2 (J^T J)^-1 with s^2 = |r|^2 / (n - p).
Eigen::MatrixXd curvatureCovariance(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& residuals, const Eigen::VectorXd& x,
                                    const Eigen::VectorXd& steps)
{
    const Eigen::VectorXd r0 = residuals(x);
    const auto n = r0.size(), p = x.size();
    Eigen::MatrixXd J(n, p);
    for (Eigen::Index k = 0; k < p; ++k) {
        Eigen::VectorXd up = x, down = x;
        up[k] += steps[k];
        down[k] -= steps[k];
        J.col(k) = (residuals(up) - residuals(down)) / (2.0 * steps[k]);
    }
    const double s2 = r0.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, n - p));
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    // A direction the data do not constrain has no curvature: its variance is unbounded.
    Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(p, p, 0.0);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(JtJ);
    const double top = eig.eigenvalues().maxCoeff();
    for (Eigen::Index k = 0; k < p; ++k) {
        const double l = eig.eigenvalues()[k];
        const Eigen::VectorXd v = eig.eigenvectors().col(k);
        cov += (l > 1e-10 * top && l > 0 ? s2 / l : 1e12) * v * v.transpose();
    }
    return cov;
}

Eigen::VectorXd gaussNewtonShift(const Eigen::MatrixXd& J, const Eigen::VectorXd& dr)
{
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(JtJ);
    const double top = eig.eigenvalues().maxCoeff();
    const Eigen::VectorXd g = J.transpose() * dr;
    Eigen::VectorXd shift = Eigen::VectorXd::Zero(J.cols());
    for (Eigen::Index k = 0; k < J.cols(); ++k) {
        const double l = eig.eigenvalues()[k];
        if (!(l > 1e-10 * top && l > 0)) continue;
        const Eigen::VectorXd v = eig.eigenvectors().col(k);
        shift -= (v.dot(g) / l) * v;
    }
    return shift;
}

// Each rig property is set to an end of its prior with the parameters held; the Gauss-Newton move
// on the metric's signed parts (first-slip time, pre-slip force, jump, transient length: simulated
// - measured, per stroke) that takes up the change is how far the parameters would go. A refit
// would say the same where the error surface is smooth; on this chaotic one it mostly stays where
// it starts.
std::vector<RigUnknownTrial> rigUnknownMoves(const Engine& engine, const EffectModel& final, const std::vector<std::string>& names,
                                             const Eigen::VectorXd& x, const Eigen::VectorXd& steps, const std::vector<std::size_t>& on)
{
    auto signedAt = [&](const EffectModel& base, const Eigen::VectorXd& y) {
        EffectModel m = base;
        for (std::size_t k = 0; k < names.size(); ++k) m.params[names[k]] = y[static_cast<Eigen::Index>(k)];
        return engine.signedResiduals(m, on);
    };
    Eigen::MatrixXd J(static_cast<Eigen::Index>(4 * on.size()), x.size());
    for (Eigen::Index k = 0; k < x.size(); ++k) {
        Eigen::VectorXd up = x, down = x;
        up[k] += steps[k];
        down[k] -= steps[k];
        J.col(k) = (signedAt(final, up) - signedAt(final, down)) / (2.0 * steps[k]);
    }
    const Eigen::VectorXd atFinal = signedAt(final, x);
    std::vector<RigUnknownTrial> trials;
    for (const RigUnknown& u : rigUnknowns(final)) {
        EffectModel rig = final;
        for (const auto& e : u.adds) rig.effects.push_back(e);
        for (const auto& [name, value] : u.params) rig.params[name] = value;
        const Eigen::VectorXd move = gaussNewtonShift(J, signedAt(rig, x) - atFinal);
        RigUnknownTrial trial{u.name, u.setting, {}};
        for (std::size_t k = 0; k < names.size(); ++k) trial.moves[names[k]] = move[static_cast<Eigen::Index>(k)];
        trials.push_back(std::move(trial));
    }
    return trials;
}

std::map<std::string, std::array<double, 2>> movesBySide(const std::vector<RigUnknownTrial>& trials)
{
    // the largest move per property and side (a property's two ends may move a parameter the same way)
    std::map<std::string, std::map<std::string, std::array<double, 2>>> largest; // parameter -> property -> {down, up}
    for (const auto& t : trials)
        for (const auto& [name, m] : t.moves) {
            auto& side = largest[name][t.unknown];
            side[0] = std::max(side[0], -m);
            side[1] = std::max(side[1], m);
        }
    // properties are independent: their moves add in quadrature, per side
    std::map<std::string, std::array<double, 2>> out;
    for (const auto& [name, byProperty] : largest) {
        double down = 0, up = 0;
        for (const auto& [property, side] : byProperty) {
            down += side[0] * side[0];
            up += side[1] * side[1];
        }
        out[name] = {std::sqrt(down), std::sqrt(up)};
    }
    return out;
}

SteadyFitResult fitSteadySliding(const std::vector<SteadySlidingPoint>& pts)
{
    auto curve = [](const Eigen::VectorXd& q) {
        return dsp::SteadyCurve::exponentials(0.4 * q[0], 0.01 * q[1], 0.45 * q[0], 0.1 * q[2], 0.35 * q[0] * q[3]);
    };
    auto residuals = [&](const Eigen::VectorXd& q) {
        const dsp::SteadyCurve c = curve(q);
        Eigen::VectorXd r(static_cast<Eigen::Index>(pts.size()));
        for (std::size_t i = 0; i < pts.size(); ++i) r[static_cast<Eigen::Index>(i)] = c(pts[i].speed).mu / pts[i].mu - 1.0;
        return r;
    };
    Eigen::VectorXd q = Eigen::VectorXd::Ones(4);
    const Eigen::VectorXd steps = Eigen::VectorXd::Constant(4, 1e-5);
    double lambda = 1e-3;
    for (int it = 0; it < 100; ++it) {
        const Eigen::VectorXd r = residuals(q);
        Eigen::MatrixXd J(r.size(), 4);
        for (int k = 0; k < 4; ++k) {
            Eigen::VectorXd up = q;
            up[k] += steps[k];
            J.col(k) = (residuals(up) - r) / steps[k];
        }
        Eigen::MatrixXd A = J.transpose() * J;
        A.diagonal() *= 1.0 + lambda;
        Eigen::VectorXd next = q - A.ldlt().solve(J.transpose() * r);
        next[1] = std::clamp(next[1], 0.2, 5.0);
        next[2] = std::clamp(next[2], 0.2, 5.0);
        next[3] = std::clamp(next[3], 0.2, 3.0);
        next[0] = std::clamp(next[0], 0.2, 3.0);
        if (residuals(next).squaredNorm() < r.squaredNorm()) {
            const bool done = (next - q).norm() < 1e-10;
            q = next;
            lambda *= 0.3;
            if (done) break;
        } else {
            lambda *= 10.0;
        }
    }
    SteadyFitResult out;
    out.curve = curve(q);
    out.muStatic = out.curve(0.0).mu;
    out.rms = std::sqrt(residuals(q).squaredNorm() / static_cast<double>(pts.size()));
    const Eigen::MatrixXd cov = curvatureCovariance(residuals, q, Eigen::VectorXd::Constant(4, 1e-4));
    // mu(0) = q0 (0.4 + 0.45 + 0.35 q3)
    Eigen::VectorXd g(4);
    g << 0.85 + 0.35 * q[3], 0.0, 0.0, 0.35 * q[0];
    out.muStaticSd = std::sqrt(std::max(0.0, static_cast<double>(g.transpose() * cov * g)));
    return out;
}

StringInfo stringInfoOf(const MeasurementSet& set)
{
    const dsp::StringParams ref = dsp::StringParams::celloD();
    StringInfo info;
    info.f0 = set.f0;
    info.beta = set.beta;
    info.tension = set.tension.value_or(ref.tension);
    info.length = set.length.value_or(ref.length);
    info.z0 = set.z0.value_or(info.tension / (2.0 * info.length * info.f0));
    info.tensionPrior = set.tensionUncertainty;
    info.betaPrior = set.betaUncertainty;
    info.qAtF0 = set.qAtF0;
    info.qAt5kHz = set.qAt5kHz;
    info.torsionSpeedRatio = set.torsionSpeedRatio;
    info.qTorsion = set.qTorsion;
    return info;
}

std::vector<Prepared> prepareStrokes(const MeasurementSet& set, const StringInfo& info, const DiagnoseOptions& o, Diagnosis& d)
{
    // 1. Clean every recording and find its gesture start; one gain for the whole set.
    const std::size_t n = set.strokes.size();
    const bool anyStick = std::any_of(set.strokes.begin(), set.strokes.end(), [](const MeasuredStroke& s) { return s.gesture != "exp_force"; });
    if (set.units == "V" && !anyStick)
        throw LabError(set.folder.string() + ": rig.sensor.units is \"V\" but every transient is an exp_force stroke, whose pre-slip "
                       "force carries the friction level as well as the sensor's scale: calibrate the sensor (units \"N\") or "
                       "add guettler or exp_speed strokes, whose pre-slip ramps set the scale");

    std::vector<Calibration> cal(n);
    // knownGain 0: gain fitted per recording.
    auto recording = [&](std::size_t i, double knownGain) {
        const MeasuredStroke& s = set.strokes[i];
        ClassifierInput in = strokeInput(s.signal, set.sampleRate, strokeGesture(s, info.beta), info);
        in.measured = true;
        in.knownGain = knownGain;
        return in;
    };
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        cal[i] = calibrateRecording(recording(i, 0.0));
        if (set.strokes[i].trigger) cal[i].trigger = *set.strokes[i].trigger;
    });
    std::vector<double> gains, allGains;
    int unfitted = 0;
    bool shapesFitted = false;
    for (std::size_t i = 0; i < n; ++i) {
        if (cal[i].firstSlip < 0) continue;
        if (set.strokes[i].gesture == "exp_force") {
            if (!cal[i].rampFitted) ++unfitted;
            else shapesFitted = true;
            continue; // its ramp's factor is not a gain
        }
        if (!cal[i].rampFitted) {
            ++unfitted;
            continue;
        }
        allGains.push_back(cal[i].gain);
        // The ramp gives the gain only once the string is quasi-statically deflected.
        if (cal[i].firstSlip / set.sampleRate - cal[i].trigger > 4.0 / info.f0) gains.push_back(cal[i].gain);
    }
    // The gesture starts were estimated, not taken as the file starts, when any ramp fitted.
    d.triggersDetected = !allGains.empty() || shapesFitted;
    if (unfitted > 0)
        d.warnings.push_back(std::to_string(unfitted) + " stroke(s) slipped before a pre-slip ramp could be fitted: their gesture start is taken as the file start");
    const std::vector<double>& used = gains.size() >= 3 ? gains : allGains;
    double gain = median(used);
    // The median's own spread, from resampled strokes.
    double gainLow = gain, gainHigh = gain;
    if (used.size() >= 3) {
        constexpr int kResamples = 400;
        std::mt19937_64 rng(o.seed * 7919ull + 11ull);
        std::uniform_int_distribution<std::size_t> pick(0, used.size() - 1);
        std::vector<double> medians;
        for (int b = 0; b < kResamples; ++b) {
            std::vector<double> r(used.size());
            for (auto& x : r) x = used[pick(rng)];
            medians.push_back(median(std::move(r)));
        }
        std::sort(medians.begin(), medians.end());
        // the 2.5 % and 97.5 % points of the sorted medians (indices 10 and 389 of 400)
        auto at = [&](double q) { return medians[static_cast<std::size_t>(std::lround(q * (kResamples - 1)))]; };
        gainLow = at(0.025);
        gainHigh = at(0.975);
    }
    if (!(gain > 0)) gain = gainLow = gainHigh = 1.0;
    if (set.units == "N") {
        if (std::abs(gain - 1.0) > 0.2)
            d.warnings.push_back("calibrated in N, but the pre-slip ramps suggest a scale of " + std::to_string(gain) +
                                 " units per N: the string data may be off");
        gain = gainLow = gainHigh = 1.0;
    }
    d.scale = 1.0 / gain;
    // Mains hum: taken out of every recording only when most recordings show it.
    double setHum = 0.0;
    {
        int n50 = 0, n60 = 0, fitted = 0;
        for (std::size_t i = 0; i < n; ++i)
            if (cal[i].rampFitted) {
                ++fitted;
                n50 += cal[i].hum == 50.0;
                n60 += cal[i].hum == 60.0;
            }
        if (fitted > 0 && std::max(n50, n60) * 2 > fitted) setHum = n50 >= n60 ? 50.0 : 60.0;
    }
    // Second pass with the set's gain fixed: trigger, DC and hum of each stroke are then
    // well determined even when its ramp is short.
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        if (cal[i].firstSlip < 0) return;
        ClassifierInput in = recording(i, set.units == "N" ? 1.0 : gain);
        in.hum = setHum;
        Calibration again = calibrateRecording(in);
        if (again.rampFitted) cal[i] = std::move(again);
        if (set.strokes[i].trigger) cal[i].trigger = *set.strokes[i].trigger;
    });
    std::vector<Prepared> strokes(n);
    std::vector<std::vector<double>> rests(n); // restDifferences() of each stroke
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        const MeasuredStroke& s = set.strokes[i];
        Prepared& p = strokes[i];
        p.id = s.id;
        p.gesture = strokeGesture(s, info.beta);
        const auto from = std::min(cal[i].force.size(), static_cast<std::size_t>(std::max(0.0, cal[i].trigger) * set.sampleRate));
        std::vector<double> f, rest;
        // Unfitted strokes are in signal units: the set's gain converts them.
        const double toNewtons = cal[i].rampFitted ? cal[i].gain / gain : 1.0 / gain;
        for (std::size_t k = 0; k < from; ++k) rest.push_back(cal[i].force[k] * toNewtons);
        for (std::size_t k = from; k < cal[i].force.size(); ++k) f.push_back(cal[i].force[k] * toNewtons);
        rests[i] = restDifferences(resample(rest, set.sampleRate, o.simRate), o.simRate);
        f = resample(f, set.sampleRate, o.simRate);
        f.resize(std::min(f.size(), static_cast<std::size_t>(0.5 * o.simRate)));
        p.force = std::move(f);
        p.noise = noiseLevel(p.force);
    });
    // The first-slip detector's floor: the rig's noise is the same in every stroke, so the rests
    // before the gestures are pooled (a single rest is often only a few ms). Without 10 ms of rest
    // in the whole set each signal estimates its own, and the report says so.
    std::vector<double> pooled, single;
    for (const auto& r : rests) {
        pooled.insert(pooled.end(), r.begin(), r.end());
        if (r.size() >= static_cast<std::size_t>(1e-3 * o.simRate)) single.push_back(slipFloorOf(r));
    }
    std::optional<double> slipFloor;
    if (pooled.size() >= static_cast<std::size_t>(1e-2 * o.simRate)) {
        slipFloor = slipFloorOf(pooled);
        std::sort(single.begin(), single.end());
        const bool spread = single.size() >= 5;
        d.calibration.push_back({"slip_noise_floor_n",
                                 "least fall within 0.1 ms read as a first slip rather than noise: six standard deviations of the noise's fall, "
                                 "from the rests before the gestures (pooled); the interval is the range single strokes' rests give",
                                 *slipFloor, spread ? single[single.size() / 40] : *slipFloor,
                                 spread ? single[single.size() - 1 - single.size() / 40] : *slipFloor});
        // The noise the simulations carry comes from the rests too. Read from the stroke itself,
        // the steps of a bowed string's own waveform (its corners, a stiff string's ringing) count
        // as noise: 100 times the rig's on a quiet rig (250 with a far stiffer string), which blurs
        // the simulations and lifts the floor the residual is judged against.
        const double white = whiteNoiseOfRests(pooled, o.simRate);
        for (Prepared& p : strokes) p.noise = white;
        d.calibration.push_back({"noise_n", "the rig's noise as white noise at the simulation rate (rms), from the rests before the gestures; "
                                            "the simulations carry it", white, white, white});
    } else {
        d.warnings.push_back("less than 10 ms of rest before the gestures in the whole set: the first-slip detector and the "
                             "simulations read each stroke's noise from the stroke itself, which misses most of a low-passed noise "
                             "and counts the steps of the string's own waveform as noise");
    }
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        strokes[i].slipFloor = slipFloor;
        strokes[i].feat = features(strokes[i].force, o.simRate, strokes[i].gesture, info, slipFloor);
    });


    // A ramp measures the scale times the string's slope T / (beta L), and the
    // manifest's tension and bow position are known only within the priors the fits give them:
    // the interval carries that slope's range as well as the median's spread.
    if (set.units == "V") {
        const auto tension = boundsOf("tension_scale", info);
        const auto position = boundsOf("beta_scale", info);
        const double softest = relativeRampSlope(tension.first, position.second), stiffest = relativeRampSlope(tension.second, position.first);
        d.calibration.push_back({"scale_n_per_unit",
                                 "sensor scale (N per signal unit) from the pre-slip ramps; the interval spans the median's spread and the "
                                 "manifest tension and bow position within their priors",
                                 d.scale, softest / gainHigh, stiffest / gainLow});
    } else {
        d.calibration.push_back({"scale_n_per_unit", "sensor scale: the set is calibrated in N", 1.0, 1.0, 1.0});
    }
    {
        std::vector<double> dcs;
        for (const auto& c : cal) dcs.push_back(c.dc * d.scale);
        const double dc = median(dcs);
        d.calibration.push_back({"dc_n", "sensor offset taken out (median over strokes, N)", dc, dc, dc});
        d.calibration.push_back({"hum_hz", setHum > 0 ? "mains hum taken out (with 3 harmonics): most recordings show it"
                                                      : "no mains hum taken out: most recordings do not show it",
                                 setHum, setHum, setHum});
    }
    return strokes;
}

namespace {
/// The curvature's residuals: each stroke's total error.
Eigen::VectorXd strokeTotals(const std::vector<ErrorParts>& e)
{
    Eigen::VectorXd r(static_cast<Eigen::Index>(e.size()));
    for (std::size_t i = 0; i < e.size(); ++i) r[static_cast<Eigen::Index>(i)] = e[i].total();
    return r;
}
} // namespace

std::vector<double> curvatureHalfWidths(const Engine& engine, const EffectModel& base, const Candidate& c, const std::vector<double>& x,
                                        const std::vector<std::size_t>& on)
{
    const Candidate searched = withinSetPriors(c, engine.info());
    const auto n = static_cast<Eigen::Index>(c.names.size());
    Eigen::VectorXd at(n), steps(n);
    for (Eigen::Index k = 0; k < n; ++k) {
        const auto i = static_cast<std::size_t>(k);
        at[k] = x[i];
        steps[k] = 0.03 * (searched.hi[i] - searched.lo[i]); // as the final model's curvature intervals
    }
    auto residuals = [&](const Eigen::VectorXd& y) {
        return strokeTotals(engine.errors(apply(base, c, std::vector<double>(y.data(), y.data() + y.size())), on));
    };
    const Eigen::MatrixXd cov = curvatureCovariance(residuals, at, steps);
    std::vector<double> hw(c.names.size());
    for (Eigen::Index k = 0; k < n; ++k) hw[static_cast<std::size_t>(k)] = 1.96 * std::sqrt(std::max(0.0, cov(k, k)));
    return hw;
}

void addCurvatureIntervals(Diagnosis& d, const Engine& engine, const EffectModel& current, const std::vector<std::size_t>& fitSet,
                           const StringInfo& info, const DiagnoseOptions& o, const std::function<void(const std::string&)>& say)
{
    std::vector<std::string> names;
    for (const auto& [name, value] : current.params) names.push_back(name);
    if (names.empty()) return;
    say("curvature intervals");
    Eigen::VectorXd x(static_cast<Eigen::Index>(names.size())), steps(x.size());
    for (std::size_t k = 0; k < names.size(); ++k) {
        x[static_cast<Eigen::Index>(k)] = current.params.at(names[k]);
        const auto [lo, hi] = boundsOf(names[k], info);
        steps[static_cast<Eigen::Index>(k)] = 0.03 * (hi - lo);
    }
    auto residuals = [&](const Eigen::VectorXd& y) {
        EffectModel m = current;
        for (std::size_t k = 0; k < names.size(); ++k) m.params[names[k]] = y[static_cast<Eigen::Index>(k)];
        return strokeTotals(engine.errors(m, fitSet));
    };
    const Eigen::MatrixXd cov = curvatureCovariance(residuals, x, steps);
    for (std::size_t k = 0; k < names.size(); ++k) {
        const auto kk = static_cast<Eigen::Index>(k);
        const double v = x[kk], hw = 1.96 * std::sqrt(std::max(0.0, cov(kk, kk)));
        // The fits never leave the search range, so neither does the interval; one that
        // spans all of it (a direction with no curvature) marks a parameter not identified.
        const auto [bottom, top] = boundsOf(names[k], info);
        // (a parameter that cancels out of the model gets its whole range, whatever the curvature)
        const bool canFix = identifiable(names[k]);
        const double lo = canFix ? std::max(v - hw, bottom) : bottom, hi = canFix ? std::min(v + hw, top) : top;
        if (isNuisance(names[k])) {
            // What the fit needed is the model's value, which stands off the rig's by more
            // than the curvature says (calibrationDiscrepancy): widened in quadrature.
            const auto sd = o.calibrationDiscrepancy.find(names[k]);
            const double wide = std::hypot(hw, sd == o.calibrationDiscrepancy.end() ? 0.0 : 1.96 * sd->second);
            const double wideLo = std::max(v - wide, bottom), wideHi = std::min(v + wide, top);
            std::string meaning = nuisanceMeaning(names[k]);
            if (wideHi - wideLo >= 0.9 * (top - bottom)) meaning += "; the data do not narrow its prior: the value is what the model needed";
            d.calibration.push_back({names[k], meaning, v, wideLo, wideHi, {lo, hi}});
        }
        for (auto& f : d.findings)
            if (f.parameters.count(names[k])) {
                // the bootstrap's normal interval and the moved halves stay inside the range too
                for (auto* m : {&f.parameters, &f.halves})
                    if (m->count(names[k]))
                        for (double& x2 : m->at(names[k])) x2 = std::clamp(x2, bottom, top);
                f.curvature[names[k]] = {lo, hi};
                if (lo <= bottom && hi >= top) f.unidentified.insert(names[k]);
            }
    }
    // The systematic part: what the rig may be that neither the fits nor the metric can fix.
    if (!d.findings.empty()) {
        say("systematic: rig unknowns");
        d.rigUnknowns = rigUnknownMoves(engine, current, names, x, steps, fitSet);
        const auto sides = movesBySide(d.rigUnknowns);
        for (auto& f : d.findings)
            for (const auto& [name, v] : f.parameters) {
                const auto side = sides.find(name);
                f.systematic[name] = side != sides.end() ? std::vector<double>{side->second[0], side->second[1]} : std::vector<double>{0.0, 0.0};
            }
    }
}

} // namespace rosin::lab::diag
