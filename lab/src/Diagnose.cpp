#include "rosin/lab/Diagnose.h"

#include <nlopt.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <cmath>
#include <numeric>
#include <random>
#include <set>

#include "rosin/lab/Error.h"
#include "rosin/lab/Resample.h"
#include "rosin/lab/Schumacher.h"
#include "rosin/lab/SynthData.h"

namespace rosin::lab {

namespace {
bool has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }
} // namespace

std::string EffectModel::name() const
{
    std::string n = has(effects, "rate_dependence") ? "enhanced" : has(effects, "thermal_memory") ? "thermal" : "friction_curve";
    if (has(effects, "rosin_temperature_shift")) n += "+shift";
    if (has(effects, "hertzian_contact")) n += "+hertz";
    if (has(effects, "torsional_compliance")) n += "+torsion";
    return n;
}

namespace {

struct StringInfo {
    double f0, beta, z0, tension, length;
};

struct Prepared {
    std::string id;
    double a = 0, F = 0;
    std::vector<double> force; ///< N at the diagnosis rate, t = 0 at the gesture start
    StrokeFeatures feat;
};

constexpr double kCompareCutoff = 5000.0; // both signals see the same low-pass before comparison

/// Noise of a low-passed recording: the robust spread of its sample-to-sample steps.
double noiseLevel(const std::vector<double>& f)
{
    if (f.size() < 3) return 0.0;
    std::vector<double> d(f.size() - 1);
    for (std::size_t i = 1; i < f.size(); ++i) d[i - 1] = std::abs(f[i] - f[i - 1]);
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    return 1.4826 * d[d.size() / 2] / std::sqrt(2.0);
}

StrokeFeatures features(std::vector<double> f, double fs, double a, double F, const StringInfo& s, bool recorded = false)
{
    zeroPhaseLowPass(f, kCompareCutoff, fs);
    const ClassifierInput in = guettlerStrokeInput(f, fs, s.f0, s.beta, s.z0, s.tension, s.length, a);
    ClassifierSettings st;
    // A first slip drops the force by more than 2 % of the bow force, and in a recording by
    // clearly more than its noise can within 0.1 ms.
    st.slipFloor = std::max(0.02 * F, recorded ? 6.0 * noiseLevel(f) : 0.0);
    const Classification c = classify(in, st);
    StrokeFeatures r;
    r.firstSlip = c.firstSlipTime;
    r.forceBeforeSlip = c.forceBeforeSlip;
    r.firstDrop = c.firstDrop;
    r.transientPeriods = c.transientPeriods;
    r.regime = c.regime;
    if (c.firstSlipTime > 0) {
        const auto start = static_cast<std::size_t>(c.firstSlipTime * fs);
        const auto len = static_cast<std::size_t>(2.0 * fs / s.f0);
        for (std::size_t i = start; i < start + len && i < f.size(); ++i) r.wave.push_back(f[i]);
    }
    return r;
}

ErrorParts compare(const StrokeFeatures& m, const StrokeFeatures& s, double a, double F, const StringInfo& info)
{
    ErrorParts e;
    if (m.firstSlip < 0 && s.firstSlip < 0) return e;
    if (m.firstSlip < 0 || s.firstSlip < 0) return {1, 1, 1, 1, 1};
    e.firstSlip = std::min(1.0, std::abs(s.firstSlip - m.firstSlip) / m.firstSlip);
    e.forceBeforeSlip = std::min(1.0, std::abs(s.forceBeforeSlip - m.forceBeforeSlip) / F);
    e.jump = std::min(1.0, std::abs(s.firstDrop - m.firstDrop) / F);
    const double nm = m.transientPeriods < 0 ? 30 : m.transientPeriods, ns = s.transientPeriods < 0 ? 30 : s.transientPeriods;
    e.transient = std::min(1.0, std::abs(nm - ns) / 25.0);
    const std::size_t n = std::min(m.wave.size(), s.wave.size());
    if (n > 0) {
        double acc = 0;
        for (std::size_t i = 0; i < n; ++i) acc += (m.wave[i] - s.wave[i]) * (m.wave[i] - s.wave[i]);
        const double flyback = 2.0 * info.z0 * a * m.firstSlip / info.beta;
        e.waveform = std::min(1.0, std::sqrt(acc / static_cast<double>(n)) / std::max(flyback, 1e-9));
    }
    return e;
}

class Engine {
public:
    Engine(std::vector<Prepared>& strokes, const StringInfo& info, double fs) : strokes_(strokes), info_(info), fs_(fs) {}

    /// Simulated features of stroke i under model m (optionally the first 12 periods of force).
    StrokeFeatures simulate(const EffectModel& m, std::size_t i, std::vector<double>* head = nullptr) const
    {
        // One prepared voice per thread, kept while the model stays the same (all the strokes of
        // one evaluation): reset() restores it exactly, prepare() would rebuild its tables.
        Voice& v = voices_.local();
        if (!v.string || v.model.effects != m.effects || v.model.params != m.params) {
            dsp::BowedStringConfig c = modelWithEffects(m.effects, m.params);
            c.string.length = info_.length;
            c.string.tension = info_.tension;
            c.string.massPerLength = info_.tension / std::pow(2.0 * info_.length * info_.f0, 2.0);
            if (!v.string) v.string = std::make_unique<dsp::BowedString<double>>();
            v.string->prepare(fs_, c);
            v.model = m;
        } else {
            v.string->reset();
        }
        dsp::BowedString<double>& s = *v.string;
        const Prepared& p = strokes_[i];
        std::vector<double> out(p.force.size());
        for (std::size_t n = 0; n < out.size(); ++n) out[n] = s.processSample(p.F, p.a * static_cast<double>(n) / fs_, info_.beta);
        ++simulations_;
        if (head) head->assign(out.begin(), out.begin() + static_cast<long>(std::min(out.size(), static_cast<std::size_t>(12.0 * fs_ / info_.f0 + 0.02 * fs_))));
        return features(std::move(out), fs_, p.a, p.F, info_);
    }

    std::vector<ErrorParts> errors(const EffectModel& m, const std::vector<std::size_t>& which) const
    {
        std::vector<ErrorParts> e(which.size());
        tbb::parallel_for(std::size_t(0), which.size(), [&](std::size_t k) {
            const std::size_t i = which[k];
            e[k] = compare(strokes_[i].feat, simulate(m, i), strokes_[i].a, strokes_[i].F, info_);
        });
        return e;
    }

    static double mean(const std::vector<ErrorParts>& e)
    {
        double s = 0;
        for (const auto& x : e) s += x.total();
        return e.empty() ? 0.0 : s / static_cast<double>(e.size());
    }

    long long simulations() const { return simulations_.load(); }

private:
    struct Voice {
        EffectModel model;
        std::unique_ptr<dsp::BowedString<double>> string;
    };
    std::vector<Prepared>& strokes_;
    StringInfo info_;
    double fs_;
    mutable std::atomic<long long> simulations_{0};
    mutable tbb::enumerable_thread_specific<Voice> voices_;
};

struct Candidate {
    std::string effect;
    std::vector<std::string> adds, names;
    std::vector<double> lo, hi, start;
};

std::vector<Candidate> candidates(const EffectModel& m)
{
    std::vector<Candidate> out;
    const bool thermal = has(m.effects, "thermal_memory");
    auto withRA = [&](Candidate c) {
        if (!thermal) {
            c.adds.insert(c.adds.begin(), "thermal_memory");
            c.names.insert(c.names.begin(), "r_A");
            c.lo.insert(c.lo.begin(), 0.5);
            c.hi.insert(c.hi.begin(), 2.0);
            c.start.insert(c.start.begin(), 1.0);
        }
        return c;
    };
    if (!thermal) out.push_back({"thermal_memory", {"thermal_memory"}, {"r_A"}, {0.5}, {2.0}, {1.0}});
    if (!has(m.effects, "rate_dependence"))
        out.push_back(withRA({"rate_dependence", {"rate_dependence"}, {"h0", "p"}, {0.3, 0.1}, {1.2, 0.8}, {0.563, 0.4}}));
    if (!has(m.effects, "hertzian_contact")) out.push_back({"hertzian_contact", {"hertzian_contact"}, {"load_exponent"}, {0.4}, {1.1}, {0.8}});
    if (!has(m.effects, "rosin_temperature_shift"))
        out.push_back(withRA({"rosin_temperature_shift", {"rosin_temperature_shift"}, {"shift_k"}, {-30.0}, {30.0}, {0.0}}));
    if (!has(m.effects, "torsional_compliance")) out.push_back({"torsional_compliance", {"torsional_compliance"}, {"zt_ratio"}, {0.7}, {8.0}, {2.0}});
    return out;
}

/// Bounds of every parameter any extension has (for the joint refit).
const std::map<std::string, std::pair<double, double>>& parameterBounds()
{
    static const std::map<std::string, std::pair<double, double>> b{{"r_A", {0.5, 2.0}},          {"h0", {0.3, 1.2}},
                                                                      {"p", {0.1, 0.8}},            {"load_exponent", {0.4, 1.1}},
                                                                      {"shift_k", {-30.0, 30.0}},   {"zt_ratio", {0.7, 8.0}}};
    return b;
}

/// True when the fitted parameters put the effect at its own absence (Hertz exponent 1 is
/// Amontons, a shift of 0 K is the reference rosin, a very stiff torsion is no torsion): any
/// held-out "gain" it shows is then the chaos of transients, not physics.
bool atNull(const std::string& effect, const std::map<std::string, double>& p)
{
    auto get = [&](const char* k) { return p.count(k) ? p.at(k) : std::nan(""); };
    if (effect == "hertzian_contact") return std::abs(get("load_exponent") - 1.0) < 0.05;
    if (effect == "rosin_temperature_shift") return std::abs(get("shift_k")) < 2.0;
    if (effect == "torsional_compliance") return get("zt_ratio") > 7.0;
    if (effect == "rate_dependence") return get("p") < 0.12;
    return false;
}

/// Which parameters belong to which effect (for splitting a two-effect step into findings).
std::string effectOf(const std::string& parameter)
{
    if (parameter == "r_A") return "thermal_memory";
    if (parameter == "h0" || parameter == "p") return "rate_dependence";
    if (parameter == "load_exponent") return "hertzian_contact";
    if (parameter == "shift_k") return "rosin_temperature_shift";
    return "torsional_compliance";
}

EffectModel apply(const EffectModel& base, const Candidate& c, const std::vector<double>& x)
{
    EffectModel m = base;
    for (const auto& e : c.adds)
        if (!has(m.effects, e)) m.effects.push_back(e);
    for (std::size_t k = 0; k < c.names.size(); ++k) m.params[c.names[k]] = x[k];
    return m;
}

/// Fits the candidate's parameters on the given strokes. The error surface is rough (transients
/// are chaotic), so a coarse grid over the bounds comes first and COBYLA refines from its best
/// point on [0, 1]-scaled variables. `scan` = false skips the grid (warm starts).
std::vector<double> fit(const Engine& engine, const EffectModel& base, const Candidate& c, const std::vector<std::size_t>& on,
                        std::vector<double> start, int maxEval, double step, double* best = nullptr, bool scan = true)
{
    const std::size_t n = c.names.size();
    std::vector<double> x(n);
    for (std::size_t k = 0; k < n; ++k) x[k] = (start[k] - c.lo[k]) / (c.hi[k] - c.lo[k]);
    if (scan) {
        const int per = n == 1 ? 7 : n == 2 ? 5 : 3;
        int total = 1;
        for (std::size_t k = 0; k < n; ++k) total *= per;
        double bestGrid = 1e300;
        for (int g = 0; g < total; ++g) {
            std::vector<double> u(n), v(n);
            int rest = g;
            for (std::size_t k = 0; k < n; ++k) {
                u[k] = (rest % per + 0.5) / per;
                rest /= per;
                v[k] = c.lo[k] + u[k] * (c.hi[k] - c.lo[k]);
            }
            const double e = Engine::mean(engine.errors(apply(base, c, v), on));
            if (e < bestGrid) { bestGrid = e; x = u; }
        }
        step = 0.5 / per;
    }
    struct Ctx {
        const Engine* engine;
        const EffectModel* base;
        const Candidate* c;
        const std::vector<std::size_t>* on;
    } ctx{&engine, &base, &c, &on};
    auto objective = [](const std::vector<double>& u, std::vector<double>&, void* data) {
        const Ctx& k = *static_cast<Ctx*>(data);
        std::vector<double> v(u.size());
        for (std::size_t i = 0; i < u.size(); ++i) v[i] = k.c->lo[i] + std::clamp(u[i], 0.0, 1.0) * (k.c->hi[i] - k.c->lo[i]);
        return Engine::mean(k.engine->errors(apply(*k.base, *k.c, v), *k.on));
    };
    nlopt::opt opt(nlopt::LN_COBYLA, static_cast<unsigned>(n));
    opt.set_lower_bounds(std::vector<double>(n, 0.0));
    opt.set_upper_bounds(std::vector<double>(n, 1.0));
    opt.set_min_objective(objective, &ctx);
    opt.set_maxeval(maxEval);
    opt.set_xtol_abs(1e-3);
    opt.set_initial_step(step);
    double value = 0.0;
    try {
        opt.optimize(x, value);
    } catch (const std::exception&) {
        // COBYLA stops on its own criteria; the best point so far is in x either way
    }
    if (best) *best = value;
    std::vector<double> v(n);
    for (std::size_t k = 0; k < n; ++k) v[k] = c.lo[k] + std::clamp(x[k], 0.0, 1.0) * (c.hi[k] - c.lo[k]);
    return v;
}

/// Paired bootstrap of the mean of before - after: returns {mean, low, high} (95 %).
std::array<double, 3> pairedGain(const std::vector<ErrorParts>& before, const std::vector<ErrorParts>& after, int B, std::uint64_t seed)
{
    const std::size_t n = before.size();
    std::vector<double> d(n);
    for (std::size_t i = 0; i < n; ++i) d[i] = before[i].total() - after[i].total();
    const double mean = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(n);
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    std::vector<double> means(static_cast<std::size_t>(B));
    for (int b = 0; b < B; ++b) {
        double s = 0;
        for (std::size_t k = 0; k < n; ++k) s += d[pick(rng)];
        means[static_cast<std::size_t>(b)] = s / static_cast<double>(n);
    }
    std::sort(means.begin(), means.end());
    return {mean, means[static_cast<std::size_t>(0.025 * B)], means[static_cast<std::size_t>(0.975 * B)]};
}

std::string describe(const std::string& effect, const std::vector<ErrorParts>& before, const std::vector<ErrorParts>& after,
                     const std::vector<std::size_t>& ids, const EffectModel& from, double errBefore, double errAfter)
{
    // The part of the comparison the extension mended most, weighted as in the metric.
    const char* names[] = {"first-slip times", "bridge forces before the first slip", "first-slip jumps", "transient lengths",
                           "waveforms just after the first slip"};
    const double weights[] = {0.25, 0.25, 0.25, 0.10, 0.15};
    double b[5] = {0, 0, 0, 0, 0}, a[5] = {0, 0, 0, 0, 0};
    for (std::size_t i = 0; i < before.size(); ++i) {
        const double pb[] = {before[i].firstSlip, before[i].forceBeforeSlip, before[i].jump, before[i].transient, before[i].waveform};
        const double pa[] = {after[i].firstSlip, after[i].forceBeforeSlip, after[i].jump, after[i].transient, after[i].waveform};
        for (int k = 0; k < 5; ++k) { b[k] += pb[k]; a[k] += pa[k]; }
    }
    const double m = static_cast<double>(std::max<std::size_t>(1, before.size()));
    int top = 0;
    for (int k = 1; k < 5; ++k)
        if (weights[k] * (b[k] - a[k]) > weights[top] * (b[top] - a[top])) top = k;
    const char* unit[] = {" of the measured time", " of the bow force", " of the bow force", " of 25 periods", " of the ideal flyback"};
    static const std::map<std::string, std::string> meaning{
        {"thermal_memory", "friction follows the contact temperature, which remembers past slipping"},
        {"rate_dependence", "on top of temperature, friction falls with sliding speed"},
        {"hertzian_contact", "friction is not proportional to bow force: one smooth contact whose area grows slower than the force"},
        {"rosin_temperature_shift", "the rosin softens at another temperature than the reference violin rosin"},
        {"torsional_compliance", "the string rolls under the bow"}};
    char buf[700];
    std::snprintf(buf, sizeof buf,
                  "With the %s model the %s of the %zu held-out strokes were off by %.1f %%%s on average; they are off by %.1f %% "
                  "when %s. Held-out error %.3f -> %.3f.",
                  from.name().c_str(), names[top], ids.size(), 100.0 * b[top] / m, unit[top], 100.0 * a[top] / m,
                  meaning.at(effect).c_str(), errBefore, errAfter);
    return buf;
}

double median(std::vector<double> v)
{
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

} // namespace

Diagnosis diagnose(const MeasurementSet& set, const DiagnoseOptions& o, const std::function<void(const std::string&, double)>& progress)
{
    const auto start = std::chrono::steady_clock::now();
    auto say = [&](const std::string& what, double x) {
        if (progress) progress(what, x);
    };
    Diagnosis d;
    d.setName = set.folder.string();
    d.warnings = set.warnings;
    // The string: the manifest, completed from a preset of the same name or the cello D.
    const dsp::StringParams ref = dsp::StringParams::celloD();
    StringInfo info{set.f0, set.beta, 0, set.tension.value_or(ref.tension), set.length.value_or(ref.length)};
    if (!set.tension) d.warnings.push_back("rig.string.tension_n missing: assumed " + std::to_string(info.tension) + " N (cello D)");
    if (!set.length) d.warnings.push_back("rig.string.length_m missing: assumed " + std::to_string(info.length) + " m (cello D)");
    info.z0 = set.z0.value_or(info.tension / (2.0 * info.length * info.f0));
    if (set.gesture != "guettler") throw LabError(set.folder.string() + ": diagnose handles gesture.kind \"guettler\" sets for now");

    // 1. Clean every recording and find its gesture start; one gain for the whole set.
    say("preparing", 0.0);
    const std::size_t n = set.strokes.size();
    std::vector<Calibration> cal(n);
    // knownGain 0: gain fitted per recording.
    auto recording = [&](std::size_t i, double knownGain) {
        const MeasuredStroke& s = set.strokes[i];
        ClassifierInput in = guettlerStrokeInput(s.signal, set.sampleRate, info.f0, info.beta, info.z0, info.tension, info.length, s.accel);
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
    for (std::size_t i = 0; i < n; ++i) {
        if (cal[i].firstSlip < 0) continue;
        if (!cal[i].rampFitted) {
            ++unfitted;
            continue;
        }
        allGains.push_back(cal[i].gain);
        // The ramp gives the gain only once the string is quasi-statically deflected.
        if (cal[i].firstSlip / set.sampleRate - cal[i].trigger > 4.0 / info.f0) gains.push_back(cal[i].gain);
    }
    // The gesture starts were estimated, not taken as the file starts, when any ramp fitted.
    d.triggersDetected = !allGains.empty();
    if (unfitted > 0)
        d.warnings.push_back(std::to_string(unfitted) + " stroke(s) slipped before a pre-slip ramp could be fitted: their gesture start is taken as the file start");
    double gain = median(gains.size() >= 3 ? gains : allGains);
    if (!(gain > 0)) gain = 1.0;
    if (set.units == "N") {
        if (std::abs(gain - 1.0) > 0.2)
            d.warnings.push_back("calibrated in N, but the pre-slip ramps suggest a scale of " + std::to_string(gain) +
                                 " units per N: the string data may be off");
        gain = 1.0;
    }
    d.scale = 1.0 / gain;
    // Second pass with the set's gain fixed: trigger, DC and hum of each stroke are then
    // well determined even when its ramp is short.
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        if (cal[i].firstSlip < 0) return;
        Calibration again = calibrateRecording(recording(i, set.units == "N" ? 1.0 : gain));
        if (again.rampFitted) cal[i] = std::move(again);
        if (set.strokes[i].trigger) cal[i].trigger = *set.strokes[i].trigger;
    });
    std::vector<Prepared> strokes(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        const MeasuredStroke& s = set.strokes[i];
        Prepared& p = strokes[i];
        p.id = s.id;
        p.a = s.accel;
        p.F = s.force;
        const auto from = static_cast<std::size_t>(std::max(0.0, cal[i].trigger) * set.sampleRate);
        std::vector<double> f;
        // Unfitted strokes are in signal units: the set's gain converts them.
        const double toNewtons = cal[i].rampFitted ? cal[i].gain / gain : 1.0 / gain;
        for (std::size_t k = from; k < cal[i].force.size(); ++k) f.push_back(cal[i].force[k] * toNewtons);
        f = resample(f, set.sampleRate, o.simRate);
        f.resize(std::min(f.size(), static_cast<std::size_t>(0.5 * o.simRate)));
        p.force = std::move(f);
        p.feat = features(p.force, o.simRate, p.a, p.F, info, true);
    });

    // 2. Fit and held-out strokes, drawn from the seed before anything is fitted.
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::mt19937_64 rng(o.seed);
    std::shuffle(order.begin(), order.end(), rng);
    const auto nFit = static_cast<std::size_t>(std::lround(o.fitFraction * static_cast<double>(n)));
    if (nFit < 4 || n - nFit < 4) throw LabError(set.folder.string() + ": too few strokes to split into fit and held-out sets (need 8)");
    std::vector<std::size_t> fitSet(order.begin(), order.begin() + static_cast<long>(nFit)), held(order.begin() + static_cast<long>(nFit), order.end());
    std::sort(fitSet.begin(), fitSet.end());
    std::sort(held.begin(), held.end());
    for (auto i : fitSet) d.fitIds.push_back(strokes[i].id);
    for (auto i : held) d.heldoutIds.push_back(strokes[i].id);
    d.nFit = fitSet.size();
    d.nHeldout = held.size();

    // 3. From the baseline, add the extension that helps most on held-out strokes, if it
    //    helps significantly; repeat.
    Engine engine(strokes, info, o.simRate);
    EffectModel current;
    d.baseline = current;
    std::vector<ErrorParts> currentHeld = engine.errors(current, held);
    d.baselineError = Engine::mean(currentHeld);
    const std::vector<ErrorParts> baselineHeld = currentHeld;
    int round = 0;
    while (true) {
        ++round;
        const auto cands = candidates(current);
        if (cands.empty()) break;
        struct Tried {
            Candidate c;
            std::vector<double> x;
            std::vector<ErrorParts> held;
            std::array<double, 3> gain;
        };
        std::vector<Tried> tried;
        for (std::size_t k = 0; k < cands.size(); ++k) {
            say("round " + std::to_string(round) + ": " + cands[k].effect, static_cast<double>(k) / static_cast<double>(cands.size()));
            double fitError = 0;
            Tried t{cands[k], fit(engine, current, cands[k], fitSet, cands[k].start, o.maxEvaluations, 0.2, &fitError), {}, {}};
            t.held = engine.errors(apply(current, t.c, t.x), held);
            t.gain = pairedGain(currentHeld, t.held, o.bootstrap, o.seed + static_cast<std::uint64_t>(round * 100 + static_cast<int>(k)));
            Trial trial;
            trial.round = round;
            trial.effect = t.c.effect;
            for (std::size_t j = 0; j < t.c.names.size(); ++j) trial.parameters[t.c.names[j]] = t.x[j];
            trial.fitError = fitError;
            trial.gain = t.gain[0];
            trial.gainLow = t.gain[1];
            trial.gainHigh = t.gain[2];
            d.trials.push_back(trial);
            tried.push_back(std::move(t));
        }
        const double base = Engine::mean(currentHeld);
        const Tried* best = nullptr;
        for (const auto& t : tried) {
            std::map<std::string, double> fitted;
            for (std::size_t j = 0; j < t.c.names.size(); ++j) fitted[t.c.names[j]] = t.x[j];
            if (atNull(t.c.effect, fitted)) continue;
            if (t.gain[1] > 0.0 && t.gain[0] >= o.minRelativeGain * base && (!best || t.gain[0] > best->gain[0])) best = &t;
        }
        if (!best) break;
        for (auto& trial : d.trials)
            if (trial.round == round && trial.effect == best->c.effect) trial.kept = true;
        // Parameter uncertainty: refits on bootstrap resamples of the fit strokes.
        std::vector<std::vector<double>> refits;
        std::mt19937_64 prng(o.seed * 31ull + static_cast<std::uint64_t>(round));
        std::uniform_int_distribution<std::size_t> pick(0, fitSet.size() - 1);
        for (int b = 0; b < o.parameterBootstrap; ++b) {
            say("round " + std::to_string(round) + ": uncertainty of " + best->c.effect, static_cast<double>(b) / o.parameterBootstrap);
            std::vector<std::size_t> resample_;
            for (std::size_t k = 0; k < fitSet.size(); ++k) resample_.push_back(fitSet[pick(prng)]);
            refits.push_back(fit(engine, current, best->c, resample_, best->x, std::max(8, o.maxEvaluations / 2), 0.05, nullptr, false));
        }
        std::map<std::string, double> halfWidth;
        for (std::size_t k = 0; k < best->c.names.size(); ++k) {
            double mean = 0, var = 0;
            for (const auto& r : refits) mean += r[k];
            mean /= static_cast<double>(std::max<std::size_t>(1, refits.size()));
            for (const auto& r : refits) var += (r[k] - mean) * (r[k] - mean);
            halfWidth[best->c.names[k]] = refits.size() > 1 ? 1.96 * std::sqrt(var / static_cast<double>(refits.size() - 1)) : 0.0;
        }
        const double before = Engine::mean(currentHeld);
        const std::vector<ErrorParts> stepBefore = currentHeld;
        const EffectModel from = current;
        current = apply(current, best->c, best->x);
        currentHeld = best->held;
        // A parameter fitted before a later effect entered the model may have stood in for it:
        // refit all parameters together, and keep the refit if it does not do worse held out.
        if (current.params.size() > 1) {
            say("round " + std::to_string(round) + ": joint refit", 0.0);
            Candidate all;
            all.effect = "joint";
            for (const auto& [name, value] : current.params) {
                all.names.push_back(name);
                all.lo.push_back(parameterBounds().at(name).first);
                all.hi.push_back(parameterBounds().at(name).second);
                all.start.push_back(value);
            }
            const auto x = fit(engine, current, all, fitSet, all.start, o.maxEvaluations, 0.05, nullptr, false);
            const EffectModel refit = apply(current, all, x);
            const auto refitHeld = engine.errors(refit, held);
            if (Engine::mean(refitHeld) <= Engine::mean(currentHeld)) {
                current = refit;
                currentHeld = refitHeld;
                for (auto& f : d.findings)
                    for (auto& [name, v] : f.parameters) {
                        const double shift = current.params[name] - v[0];
                        for (double& x2 : v) x2 += shift; // same width, centred on the joint value
                    }
            }
        }
        // One finding per effect the step switched on (a rate dependence or a rosin shift on top of
        // a friction curve brings thermal memory with it).
        for (const auto& effect : best->c.adds) {
            if (has(from.effects, effect)) continue;
            Finding finding;
            finding.effect = effect;
            for (const auto& name : best->c.names)
                if (effectOf(name) == effect) {
                    const double v = current.params[name];
                    finding.parameters[name] = {v, v - halfWidth[name], v + halfWidth[name]};
                }
            finding.heldoutBefore = before;
            finding.heldoutAfter = Engine::mean(currentHeld);
            finding.evidence = describe(effect, stepBefore, currentHeld, held, from, before, finding.heldoutAfter);
            d.findings.push_back(std::move(finding));
        }
    }
    d.final = current;
    d.finalError = Engine::mean(currentHeld);
    const auto g = pairedGain(baselineHeld, currentHeld, o.bootstrap, o.seed + 999);
    d.relativeGain = d.baselineError > 0 ? g[0] / d.baselineError : 0.0;
    d.gainLow = d.baselineError > 0 ? g[1] / d.baselineError : 0.0;
    d.gainHigh = d.baselineError > 0 ? g[2] / d.baselineError : 0.0;

    // 4. What the report shows: every stroke under the baseline and the final model.
    say("report", 0.0);
    d.ids.resize(n);
    d.accel.resize(n);
    d.force.resize(n);
    d.measured.resize(n);
    d.baselineSim.resize(n);
    d.finalSim.resize(n);
    d.measuredForce.resize(n);
    d.baselineForce.resize(n);
    d.finalForce.resize(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        d.ids[i] = strokes[i].id;
        d.accel[i] = strokes[i].a;
        d.force[i] = strokes[i].F;
        d.measured[i] = strokes[i].feat;
        d.baselineSim[i] = engine.simulate(d.baseline, i, &d.baselineForce[i]);
        d.finalSim[i] = engine.simulate(d.final, i, &d.finalForce[i]);
        d.measuredForce[i].assign(strokes[i].force.begin(), strokes[i].force.begin() + static_cast<long>(std::min(strokes[i].force.size(), d.baselineForce[i].size())));
    });
    // 5. The scale again, now from the final model's own pre-slip ramps (with torsion, for one,
    //    part of the bow's travel rolls the string instead of deflecting it), over the strokes
    //    whose ramps are long enough to be quasi-static.
    {
        double ms = 0, ss = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const double t1 = d.measured[i].firstSlip;
            if (!(t1 > 4.0 / info.f0)) continue;
            const auto from = static_cast<std::size_t>(2.0 / info.f0 * o.simRate), to = static_cast<std::size_t>(0.6 * t1 * o.simRate);
            for (std::size_t k = from; k < to && k < d.measuredForce[i].size() && k < d.finalForce[i].size(); ++k) {
                ms += d.measuredForce[i][k] * d.finalForce[i][k];
                ss += d.finalForce[i][k] * d.finalForce[i][k];
            }
        }
        if (ss > 0 && ms > 0 && set.units == "V") d.scale /= ms / ss;
    }
    // 6. Two-ended steady strokes: bow-point velocity and friction reconstructed from the end
    //    forces, measured and as the final model would show them.
    for (const auto& rec : set.twoEnded) {
        say("two-ended " + rec.id, 0.0);
        LoopComparison lc;
        lc.id = rec.id;
        const double c = 2.0 * info.length * info.f0, tb = info.beta * info.length / c, tn = (1.0 - info.beta) * info.length / c;
        const double toN = set.units == "V" ? d.scale : 1.0;
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
        dsp::BowedStringConfig cfg = modelWithEffects(d.final.effects, d.final.params);
        cfg.string.length = info.length;
        cfg.string.tension = info.tension;
        cfg.string.massPerLength = info.tension / std::pow(2.0 * info.length * info.f0, 2.0);
        dsp::BowedString<double> sim;
        sim.prepare(o.simRate, cfg);
        std::vector<double> b(rec.bridge.size() * static_cast<std::size_t>(o.simRate) / static_cast<std::size_t>(set.sampleRate)), f(b.size());
        for (std::size_t i = 0; i < b.size(); ++i) {
            const double t = static_cast<double>(i) / o.simRate;
            b[i] = sim.processSample(rec.force, rec.bowSpeed * std::min(1.0, t / 0.03), info.beta);
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
        d.loops.push_back(std::move(lc));
    }
    d.simulations = engine.simulations();
    d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return d;
}

} // namespace rosin::lab
