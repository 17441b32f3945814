#include "rosin/lab/ReferenceData.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numbers>
#include <optional>
#include <random>

#include "rosin/lab/Error.h"
#include "rosin/lab/Resample.h"
#include "rosin/reference/Simulator.h"

namespace rosin::lab {

namespace {
bool has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }
constexpr double kPi = std::numbers::pi;

// What the manifest says: the lab's nominal cello D (PHYSICS.md 1.6), tuned to pitch.
constexpr double kManifestF0 = 146.83, kManifestLength = 0.69, kManifestTension = 102.6;

/// A piezo force sensor and its charge amplifier: a mechanical resonance above the band and
/// a slow high-pass (the amplifier's time constant), run at the simulation rate.
struct Sensor {
    double b0, b1, b2, a1, a2, hp;
    Sensor(double resonanceHz, double q, double highpassHz, double fs)
    {
        const double w = 2.0 * kPi * resonanceHz / fs, cw = std::cos(w), alpha = std::sin(w) / (2.0 * q), a0 = 1.0 + alpha;
        b0 = b2 = (1.0 - cw) / 2.0 / a0;
        b1 = (1.0 - cw) / a0;
        a1 = -2.0 * cw / a0;
        a2 = (1.0 - alpha) / a0;
        hp = 1.0 / (1.0 + 2.0 * kPi * highpassHz / fs);
    }
    void apply(std::vector<double>& x) const
    {
        double x1 = 0, x2 = 0, y1 = 0, y2 = 0, hx = 0, hy = 0;
        for (double& v : x) {
            const double y = b0 * v + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
            x2 = x1;
            x1 = v;
            y2 = y1;
            y1 = y;
            hy = hp * (hy + y - hx);
            hx = y;
            v = hy;
        }
    }
};
} // namespace

const std::vector<RigPrior>& referenceRigPriors()
{
    static const std::vector<RigPrior> p{
        {"tension_error", -0.04, 0.04, false, "true tension / manifest tension - 1"},
        {"beta_error", -0.03, 0.03, false, "true bow position / manifest beta - 1"},
        {"mu_level", 0.93, 1.07, false, "the rig's steady-sliding friction (and static friction) / the SW00 fit"},
        {"mu_v1_scale", 0.8, 1.25, true, "speed scale of the fast exponential / 0.01 m/s"},
        {"mu_v2_scale", 0.8, 1.25, true, "speed scale of the slow exponential / 0.1 m/s"},
        {"mu_floor_scale", 0.9, 1.1, false, "high-speed friction / 0.35"},
        {"contact_radius_um", 150.0, 350.0, false, "contact radius at 1 N (um)"},
        {"layer_um", 0.5, 2.0, true, "rosin layer thickness (um)"},
        {"rosin_heat", 1.4e6, 1.8e6, false, "rosin rho c (J m^-3 K^-1)"},
        {"string_effusivity", 1600.0, 2500.0, false, "string side (W s^1/2 m^-2 K^-1)"},
        {"rod_effusivity", 300.0, 600.0, false, "rod side (W s^1/2 m^-2 K^-1)"},
        {"inharmonicity", 5e-6, 1e-4, true, "string stiffness B"},
        {"q_low", 300.0, 800.0, true, "transverse Q at f0"},
        {"q_high", 80.0, 250.0, true, "transverse Q at 5 kHz"},
        {"bridge_hz", 800.0, 3000.0, true, "bridge resonance (Hz)"},
        {"bridge_q", 8.0, 30.0, true, "bridge resonance Q"},
        {"bridge_z0y", 0.005, 0.05, true, "Z0 x the bridge resonance's peak admittance"},
        {"body_hz", 150.0, 500.0, true, "body resonance seen at the bridge (Hz)"},
        {"body_q", 10.0, 40.0, true, "body resonance Q"},
        {"body_z0y", 0.002, 0.02, true, "Z0 x the body resonance's peak admittance"},
        {"torsion_speed_ratio", 4.5, 6.0, false, "c_t / c (used when torsion is a hidden effect)"},
        {"q_torsion", 15.0, 60.0, true, "torsional Q"},
        {"sensor_hz", 8000.0, 20000.0, true, "force sensor resonance (Hz)"},
        {"sensor_q", 0.7, 4.0, true, "force sensor resonance Q"},
        {"highpass_hz", 0.005, 0.2, true, "charge amplifier high-pass corner (Hz)"},
        {"hum_hz", 0.0, 60.0, false, "mains: 0 (none, 20 %), 50 or 60 Hz"},
        {"hum_n", 0.002, 0.05, true, "hum amplitude at the mains frequency (N)"},
        {"dc_n", -0.3, 0.3, false, "DC offset (N)"},
        {"noise_n", 1e-4, 0.03, true, "white noise, rms (N): clean to poor"},
        {"headroom", 0.3, 1.4, false, "loudest stroke / full scale (V sets): above 1 clips (20 % of sets)"},
        {"calibration_error", -0.02, 0.02, false, "recorded N / true N - 1: a calibrated sensor's error (N sets only)"},
    };
    return p;
}

const std::map<std::string, std::pair<double, double>>& referenceEffectPriors()
{
    static const std::map<std::string, std::pair<double, double>> p{
        {"r_A", {0.7, 1.4}}, {"h0", {0.45, 0.85}}, {"p", {0.1, 0.6}}, {"load_exponent", {0.55, 0.95}},
        {"shift_k", {1.0, 20.0}}, {"zt_ratio", {1.2, 8.0}}};
    return p;
}

namespace {
void checkRigValue(const std::string& key, double value)
{
    const auto& pr = referenceRigPriors();
    if (std::none_of(pr.begin(), pr.end(), [&](const RigPrior& r) { return r.key == key; }))
        throw LabError("--rig-param: unknown rig value '" + key + "' (rosin synth-data --help lists them)");
    if (!std::isfinite(value)) throw LabError("--rig-param: " + key + " must be a finite number");
}

/// One NAME=NUMBER argument of a flag, split and read: a clear error naming the flag when it has
/// no '=' (`form` says what was expected) or no number. The name is the caller's to check.
std::pair<std::string, double> nameAndNumber(const std::string& flag, const std::string& kv, const std::string& form)
{
    const auto eq = kv.find('=');
    if (eq == std::string::npos) throw LabError(flag + ": expected " + form + ", got '" + kv + "'");
    const std::optional<double> value = wholeNumber(kv.substr(eq + 1));
    if (!value) throw LabError(flag + ": '" + kv + "' has no number");
    return {kv.substr(0, eq), *value};
}
} // namespace

std::map<std::string, double> parseRigValues(const std::vector<std::string>& nameEqualsValue)
{
    std::map<std::string, double> rig;
    for (const auto& kv : nameEqualsValue) {
        const auto [key, value] = nameAndNumber("--rig-param", kv, "NAME=VALUE");
        checkRigValue(key, value);
        rig[key] = value;
    }
    return rig;
}

namespace {
void checkParamRange(const std::string& key, double lo, double hi)
{
    const auto& priors = referenceEffectPriors();
    const auto prior = priors.find(key);
    if (prior == priors.end()) throw LabError("--param-range: unknown parameter '" + key + "' (r_A, h0, p, load_exponent, shift_k, zt_ratio)");
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi))
        throw LabError("--param-range: " + key + " needs LO < HI, both finite");
    const auto [plo, phi] = prior->second;
    if (lo < plo || hi > phi)
    {
        char within[64];
        std::snprintf(within, sizeof within, "%g to %g", plo, phi);
        throw LabError("--param-range: " + key + " must lie within its prior, " + within);
    }
}
} // namespace

std::map<std::string, std::pair<double, double>> parseParamRanges(const std::vector<std::string>& nameEqualsRange)
{
    std::map<std::string, std::pair<double, double>> ranges;
    for (const auto& kv : nameEqualsRange) {
        const auto eq = kv.find('=');
        const auto colon = kv.find(':', eq == std::string::npos ? 0 : eq);
        if (eq == std::string::npos || colon == std::string::npos) throw LabError("--param-range: expected NAME=LO:HI, got '" + kv + "'");
        const std::optional<double> lo = wholeNumber(kv.substr(eq + 1, colon - eq - 1)), hi = wholeNumber(kv.substr(colon + 1));
        if (!lo || !hi) throw LabError("--param-range: '" + kv + "' needs two numbers, LO:HI");
        checkParamRange(kv.substr(0, eq), *lo, *hi);
        ranges[kv.substr(0, eq)] = {*lo, *hi};
    }
    return ranges;
}

namespace {
/// The rig error a stated uncertainty bounds: tension -> tension_error, beta -> beta_error.
const RigPrior& statedError(const std::string& name)
{
    const std::string key = name + "_error";
    const auto& pr = referenceRigPriors();
    const auto it = std::find_if(pr.begin(), pr.end(), [&](const RigPrior& r) { return r.key == key; });
    if ((name != "tension" && name != "beta") || it == pr.end())
        throw LabError("--stated-uncertainty: unknown rig value '" + name + "' (tension, beta, q, torsion)");
    return *it;
}

/// How far a lab's measured Q or torsional constants may stand off the string's (a decay or
/// resonance fit's error).
constexpr double kStringMeasurementSpreadMax = 0.3;

void checkStatedUncertainty(const std::string& name, double u)
{
    // Tension and beta bound the rig's own error, so no wider than the generator draws it; q and
    // torsion bound how far the manifest's values stand off the rig's.
    const bool measured = name == "q" || name == "torsion";
    const double widest = measured ? kStringMeasurementSpreadMax : statedError(name).hi;
    if (!std::isfinite(u) || u < 0.001 || u > widest) {
        char range[48];
        std::snprintf(range, sizeof range, "a fraction from 0.001 to %g", widest);
        throw LabError("--stated-uncertainty: " + name + " must be " + range +
                       (measured ? " (how far the stated value stands off the string's)" : " (the generator's own spread of its error)"));
    }
}
} // namespace

std::map<std::string, double> parseStatedUncertainties(const std::vector<std::string>& nameEqualsFraction)
{
    std::map<std::string, double> stated;
    for (const auto& kv : nameEqualsFraction) {
        const auto [name, u] = nameAndNumber("--stated-uncertainty", kv, "NAME=FRACTION (tension=0.01)");
        checkStatedUncertainty(name, u);
        stated[name] = u;
    }
    return stated;
}

MeasurementSet synthesizeReference(const SynthSpec& spec, SynthTruth& truth, const std::function<void(double)>& progress)
{
    if (spec.grid < 2 || spec.grid > 60) throw LabError("--grid must be within 2..60");
    if (!(spec.outRate >= 8000 && spec.outRate <= 384000)) throw LabError("--rate must be within 8000..384000 Hz");
    if (spec.oversampling < 4 || spec.oversampling > 32) throw LabError("--oversampling must be within 4..32 (the reference runs at least 4x the file rate)");
    if (spec.units != "V" && spec.units != "N") throw LabError("--units must be V or N");
    for (const auto& [key, value] : spec.rig) checkRigValue(key, value);
    for (const auto& [key, range] : spec.paramRanges) checkParamRange(key, range.first, range.second);
    for (const auto& [name, u] : spec.statedUncertainty) checkStatedUncertainty(name, u);
    if (spec.generator != "reference" && spec.generator != "model-on-rig")
        throw LabError("--generator " + spec.generator + " does not draw a reference rig");
    std::mt19937_64 rng(spec.seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    truth = SynthTruth{};
    truth.generator = spec.generator;
    for (const auto& id : effectIds()) {
        const bool implied = id == "thermal_memory" && (has(spec.effects, "rosin_temperature_shift") || has(spec.effects, "rate_dependence"));
        if (has(spec.effects, id) || implied) truth.effects.push_back(id);
    }
    auto draw = [&](const char* key) {
        const auto narrowed = spec.paramRanges.find(key);
        const auto [lo, hi] = narrowed != spec.paramRanges.end() ? narrowed->second : referenceEffectPriors().at(key);
        const double x = lo + (hi - lo) * u(rng);
        const auto it = spec.params.find(key);
        truth.params[key] = it != spec.params.end() ? it->second : x;
    };
    if (has(truth.effects, "thermal_memory")) draw("r_A");
    if (has(truth.effects, "rate_dependence")) { draw("h0"); draw("p"); }
    if (has(truth.effects, "hertzian_contact")) draw("load_exponent");
    if (has(truth.effects, "rosin_temperature_shift")) {
        draw("shift_k");
        const bool negative = u(rng) < 0.5;
        if (!spec.params.count("shift_k") && negative) truth.params["shift_k"] = -truth.params["shift_k"];
    }
    if (has(truth.effects, "torsional_compliance")) draw("zt_ratio");
    // The rig: every value drawn in a fixed order (so a fixed value does not move the others).
    std::map<std::string, double>& rig = truth.rig;
    // A calibrated sensor's error is drawn from a stream of its own: added after the others,
    // it leaves every other draw (and so every earlier study's sets) as it was.
    std::mt19937_64 calibrationRng(spec.seed * 6364136223846793005ull + 1442695040888963407ull);
    for (const RigPrior& p : referenceRigPriors()) {
        std::mt19937_64& stream = p.key == "calibration_error" ? calibrationRng : rng;
        const double x = u(stream), y = u(stream);
        double v = p.logScale ? p.lo * std::pow(p.hi / p.lo, x) : p.lo + (p.hi - p.lo) * x;
        if (p.key == "hum_hz") v = x < 0.2 ? 0.0 : (y < 0.5 ? 50.0 : 60.0);
        if (p.key == "headroom") v = x < 0.2 ? 1.05 + 0.35 * y : 0.3 + 0.6 * y;
        // A lab that measured its tension or bow position to +-U: the same number of the
        // stream, mapped onto +-U, so every other draw stays that of the rig it did not measure.
        for (const auto& [name, stated] : spec.statedUncertainty)
            if (p.key == name + "_error") v = stated * (2.0 * x - 1.0);
        const auto it = spec.rig.find(p.key);
        rig[p.key] = it != spec.rig.end() ? it->second : v;
    }
    const auto param = [&](const char* key) { return truth.params.at(key); };

    // The true string: the lab tuned it to the manifest's pitch, but its tension is not the
    // string maker's figure, and the bow is not exactly where the lab measured it.
    reference::Rig r;
    const double tension = kManifestTension * (1.0 + rig["tension_error"]);
    const double B = rig["inharmonicity"];
    const double idealF0 = kManifestF0 / std::sqrt(1.0 + B);
    r.string.length = kManifestLength;
    r.string.tension = tension;
    r.string.massPerLength = tension / std::pow(2.0 * kManifestLength * idealF0, 2.0);
    r.string.inharmonicity = B;
    r.string.qLow = rig["q_low"];
    r.string.qHigh = rig["q_high"];
    const double z0 = r.string.impedance();
    r.bridge.push_back({rig["body_hz"], rig["body_q"], rig["body_z0y"] / z0});
    r.bridge.push_back({rig["bridge_hz"], rig["bridge_q"], rig["bridge_z0y"] / z0});
    reference::Friction& f = r.friction;
    f.steady.level = rig["mu_level"];
    f.steady.v1 *= rig["mu_v1_scale"];
    f.steady.v2 *= rig["mu_v2_scale"];
    f.steady.a3 *= rig["mu_floor_scale"];
    f.contact.radiusAtReference = rig["contact_radius_um"] * 1e-6;
    f.contact.layerThickness = rig["layer_um"] * 1e-6;
    f.contact.rosinVolumetricHeat = rig["rosin_heat"];
    f.contact.stringEffusivity = rig["string_effusivity"];
    f.contact.rodEffusivity = rig["rod_effusivity"];
    if (has(truth.effects, "thermal_memory")) {
        f.law = reference::FrictionLaw::Thermal;
        f.footprintRatio = param("r_A");
    }
    if (has(truth.effects, "rate_dependence")) {
        f.law = reference::FrictionLaw::Enhanced;
        f.speed = {param("h0"), 0.35, param("p")};
    }
    if (has(truth.effects, "hertzian_contact")) f.loadExponent = param("load_exponent");
    if (has(truth.effects, "rosin_temperature_shift")) f.temperatureShiftK = param("shift_k");
    if (has(truth.effects, "torsional_compliance")) {
        r.string.torsion = true;
        r.string.torsionImpedanceRatio = param("zt_ratio");
        r.string.torsionSpeedRatio = rig["torsion_speed_ratio"];
        r.string.qTorsion = rig["q_torsion"];
    }
    const double beta = spec.beta * (1.0 + rig["beta_error"]);
    const double simRate = spec.outRate * spec.oversampling;
    rig["tension_n"] = tension;
    rig["beta"] = beta;
    rig["z0_kg_per_s"] = z0;
    rig["sim_rate_hz"] = simRate;
    // The string that makes the strokes: the reference simulator on the rig, or (model-on-rig)
    // dsp/'s model, whose truth then records the values it really had where it holds its own.
    std::optional<reference::Simulator> prototype;
    std::optional<dsp::BowedStringConfig> model;
    if (spec.generator == "model-on-rig") {
        model = modelOnRig(truth.effects, truth.params, rig, kManifestF0);
        const dsp::ThermalParams& th = model->friction.thermal;
        const dsp::StringParams& st = model->string;
        for (auto [key, v] : {std::pair<const char*, double>{"inharmonicity", st.inharmonicity}, {"q_low", st.qLow}, {"q_high", st.qHigh},
                              {"bridge_z0y", 0.0}, {"body_z0y", 0.0}, {"contact_radius_um", th.contactRadiusAtRef * 1e6},
                              {"layer_um", th.layerThickness * 1e6}, {"rosin_heat", th.rosinHeatCapacity},
                              {"string_effusivity", th.stringEffusivity}, {"torsion_speed_ratio", st.torsionSpeedRatio},
                              {"q_torsion", st.qTorsion}, {"z0_kg_per_s", st.impedance()}})
            rig[key] = v;
    } else {
        try {
            prototype.emplace(r, beta, simRate);
        } catch (const std::invalid_argument& e) {
            throw LabError(std::string("synth-data: ") + e.what());
        }
        rig["cells"] = prototype->grid().cells;
    }
    // Bridge force (and far-end force) of a gesture, {force, speed} = at(t), at the simulation rate.
    auto play = [&](std::size_t length, const auto& at, std::vector<double>* far) {
        std::vector<double> bridge(length);
        if (far) far->assign(length, 0.0);
        if (model) {
            dsp::BowedString<double> s;
            s.prepare(simRate, *model);
            for (std::size_t i = 0; i < length; ++i) {
                const auto [force, speed] = at(static_cast<double>(i) / simRate);
                bridge[i] = s.processSample(force, speed, beta);
                if (far) (*far)[i] = s.waveguide().farEndForce();
            }
            return bridge;
        }
        reference::Simulator sim = *prototype;
        for (std::size_t i = 0; i < length; ++i) {
            const auto [force, speed] = at(static_cast<double>(i) / simRate);
            const reference::Sample x = sim.step(force, speed);
            bridge[i] = x.bridgeForce;
            if (far) (*far)[i] = x.farEndForce;
        }
        return bridge;
    };

    MeasurementSet set;
    set.description = "simulated by rosin synth-data --generator " + spec.generator + " (seed " + std::to_string(spec.seed) + ")";
    set.stringName = "cello-D";
    set.f0 = kManifestF0;
    set.length = kManifestLength;
    set.tension = kManifestTension;
    set.z0 = kManifestTension / (2.0 * kManifestLength * kManifestF0);
    set.beta = spec.beta;
    set.exciter = "rod";
    set.ambient = 20.0;
    set.units = spec.units;
    set.sampleRate = spec.outRate;
    set.gesture = spec.gesture;
    if (const auto t = spec.statedUncertainty.find("tension"); t != spec.statedUncertainty.end()) set.tensionUncertainty = t->second;
    if (const auto b = spec.statedUncertainty.find("beta"); b != spec.statedUncertainty.end()) set.betaUncertainty = b->second;
    // A lab that measured a pair of its string's constants to +-U (its Q from a pluck's decays, its
    // torsion from the torsional resonances' spacing and widths) states each off by its own error,
    // drawn from a stream of the pair's own, so the rig and every other draw stay those of the
    // unmeasured rig and one pair's statement does not move the other's.
    struct MeasuredPair {
        const char* name;
        std::uint64_t streamScale, streamOffset;
        std::array<const char*, 2> rigKeys, truthKeys;
        std::array<std::optional<double>*, 2> stated;
    };
    for (const MeasuredPair& p : {MeasuredPair{"q", 2862933555777941757ull, 3037000493ull, {"q_low", "q_high"}, {"q_f0_stated", "q_5khz_stated"},
                                               {&set.qAtF0, &set.qAt5kHz}},
                                  MeasuredPair{"torsion", 6364136223846793005ull, 1442695040888963407ull, {"torsion_speed_ratio", "q_torsion"},
                                               {"torsion_speed_ratio_stated", "q_torsion_stated"}, {&set.torsionSpeedRatio, &set.qTorsion}}}) {
        const auto fraction = spec.statedUncertainty.find(p.name);
        if (fraction == spec.statedUncertainty.end()) continue;
        std::mt19937_64 stream(spec.seed * p.streamScale + p.streamOffset);
        for (std::size_t k = 0; k < 2; ++k) {
            const double error = fraction->second * (2.0 * u(stream) - 1.0);
            *p.stated[k] = rig[p.rigKeys[k]] * (1.0 + error);
            rig[p.truthKeys[k]] = **p.stated[k];
        }
    }
    // The lab's own steady-sliding measurement of this rosin, 1 % scatter.
    {
        std::normal_distribution<double> g(0.0, 1.0);
        std::mt19937_64 sr(spec.seed * 15485863ull + 3);
        for (double v : {0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0})
            set.steady.push_back({v, f.steady.mu(v) * (1.0 + 0.01 * g(sr)), f.contact.referenceLoad});
    }
    const Sensor sensor(rig["sensor_hz"], rig["sensor_q"], rig["highpass_hz"], simRate);
    const double humPhase[3] = {2 * kPi * u(rng), 2 * kPi * u(rng), 2 * kPi * u(rng)};
    const double humWeight[3] = {1.0, 0.5 * u(rng), 0.3 * u(rng)};
    // Volts after the amplifier: the electrical artefacts come after the sensor.
    auto record = [&](std::vector<double> x, std::size_t pre, std::mt19937_64& noiseRng) {
        sensor.apply(x);
        antiAliasFilter(x, 0.45 * spec.outRate, simRate);
        const std::vector<double> y = resample(x, simRate, spec.outRate);
        std::normal_distribution<double> g(0.0, 1.0);
        std::vector<double> out(pre + y.size());
        for (std::size_t i = 0; i < out.size(); ++i) {
            const double t = static_cast<double>(i) / spec.outRate;
            double hum = 0.0;
            if (rig["hum_hz"] > 0)
                for (int h = 0; h < 3; ++h) hum += rig["hum_n"] * humWeight[h] * std::sin(2 * kPi * rig["hum_hz"] * (h + 1) * t + humPhase[h]);
            out[i] = (i < pre ? 0.0 : y[i - pre]) + hum + rig["dc_n"] + rig["noise_n"] * g(noiseRng);
        }
        return out;
    };

    const int n = spec.grid * spec.grid;
    set.strokes.resize(static_cast<std::size_t>(n));
    std::atomic<int> done{0};
    std::mutex progressLock, truthLock;
    tbb::parallel_for(0, n, [&](int k) {
        std::mt19937_64 sr(spec.seed * 7919ull + static_cast<std::uint64_t>(k) + 11);
        std::uniform_real_distribution<double> uu(0.0, 1.0);
        const int ia = k % spec.grid, iF = k / spec.grid;
        const double x = static_cast<double>(ia) / (spec.grid - 1);
        const double F = spec.fMin + (spec.fMax - spec.fMin) * iF / (spec.grid - 1);
        // The gesture the rig meant (in the manifest) and the one it made (jittered).
        MeasuredStroke& m = set.strokes[static_cast<std::size_t>(k)];
        static const char* kinds[3] = {"guettler", "exp_speed", "exp_force"};
        m.gesture = spec.gesture == "mixed" ? kinds[(ia + iF) % 3] : spec.gesture; // every kind on every column and row
        const double jitterDrive = 1.0 + spec.jitter * (2.0 * uu(sr) - 1.0);
        const double jitterForce = 1.0 + spec.jitter * (2.0 * uu(sr) - 1.0);
        char id[32];
        if (m.gesture == "exp_speed") {
            m.v0 = spec.expV0;
            m.tv = spec.expV0 / (spec.aMin + (spec.aMax - spec.aMin) * x); // initial acceleration v0/tv on the grid
            m.force = F;
            std::snprintf(id, sizeof id, "v%02d_f%02d", ia, iF);
        } else if (m.gesture == "exp_force") {
            m.speed = spec.vMin + (spec.vMax - spec.vMin) * x;
            m.f0 = F;
            m.tf = spec.expTf;
            std::snprintf(id, sizeof id, "c%02d_f%02d", ia, iF);
        } else {
            m.accel = spec.aMin + (spec.aMax - spec.aMin) * x;
            m.force = F;
            std::snprintf(id, sizeof id, "a%02d_f%02d", ia, iF);
        }
        m.id = id;
        MeasuredStroke made = m;
        made.accel *= jitterDrive;
        made.v0 *= jitterDrive;
        made.speed *= jitterDrive;
        made.force *= jitterForce;
        made.f0 *= jitterForce;
        const Gesture g = strokeGesture(made, beta);
        std::vector<double> bridge = play(static_cast<std::size_t>(spec.seconds * simRate), [&](double t) {
            const auto c = g.at(t);
            return std::pair{c.force, c.speed};
        }, nullptr);
        const double trigger = spec.triggerMax * uu(sr);
        const auto pre = static_cast<std::size_t>(trigger * spec.outRate);
        m.signal = record(std::move(bridge), pre, sr);
        {
            std::lock_guard<std::mutex> lock(truthLock);
            truth.triggers[m.id] = static_cast<double>(pre) / spec.outRate;
            truth.strokes[m.id] = {g.drive(), g.force};
        }
        const int finished = ++done;
        if (progress && progressLock.try_lock()) {
            progress(double(finished) / (n + spec.twoEnded));
            progressLock.unlock();
        }
    });
    set.twoEnded.resize(static_cast<std::size_t>(std::max(0, spec.twoEnded)));
    tbb::parallel_for(0, spec.twoEnded, [&](int k) {
        std::mt19937_64 sr(spec.seed * 104729ull + static_cast<std::uint64_t>(k) + 5);
        TwoEndedRecording& rec = set.twoEnded[static_cast<std::size_t>(k)];
        rec.id = "steady_" + std::to_string(k + 1);
        rec.bowSpeed = 0.05 + 0.05 * k;
        rec.force = 0.8;
        std::vector<double> far;
        std::vector<double> b = play(static_cast<std::size_t>(0.4 * simRate), [&](double t) {
            return std::pair{rec.force, rec.bowSpeed * std::min(1.0, t / 0.03)};
        }, &far);
        rec.bridge = record(std::move(b), 0, sr);
        rec.far = record(std::move(far), 0, sr);
    });
    // In volts the recordist set the gain from the loudest stroke, and above full scale the
    // converter clips; in newtons the sensor was calibrated, to within its calibration's error.
    const bool volts = spec.units == "V";
    if (volts) {
        double peak = 0.0;
        for (const auto& m : set.strokes)
            for (double v : m.signal) peak = std::max(peak, std::abs(v));
        truth.gain = rig["headroom"] / peak;
    } else {
        truth.gain = 1.0 + rig["calibration_error"];
    }
    std::size_t clipped = 0, total = 0;
    auto toSensor = [&](std::vector<double>& x) {
        for (double& v : x) {
            v *= truth.gain;
            if (volts && std::abs(v) >= 0.999) {
                v = std::copysign(0.999, v);
                ++clipped;
            }
            ++total;
        }
    };
    for (auto& m : set.strokes) toSensor(m.signal);
    truth.clippedFraction = total ? static_cast<double>(clipped) / static_cast<double>(total) : 0.0;
    for (auto& rec : set.twoEnded) {
        toSensor(rec.bridge);
        toSensor(rec.far);
    }
    return set;
}

} // namespace rosin::lab
