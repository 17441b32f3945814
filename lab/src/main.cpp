// The `rosin` command: offline science on the bowed-string model.
#include <CLI/CLI.hpp>
#include <sndfile.h>

#include <fstream>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "rosin/dsp.h"
#include "rosin/lab/Bench.h"
#include "rosin/lab/Classifier.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Distributed.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/FigureSet.h"
#include "rosin/lab/Figures.h"
#include "rosin/lab/Guettler.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/Signal.h"
#include "rosin/lab/SynthData.h"
#include "rosin/lab/Gesture.h"
#include "rosin/lab/Output.h"
#include "rosin/lab/Presets.h"
#include "rosin/lab/Render.h"

namespace fs = std::filesystem;
using namespace rosin;
using namespace rosin::lab;

namespace {

/// CLI11's Range lets NaN through; every number we take must be finite and in range.
CLI::Validator finiteIn(double lo, double hi)
{
    return CLI::Validator(
        [lo, hi](std::string& s) -> std::string {
            double x = 0.0;
            try {
                std::size_t used = 0;
                x = std::stod(s, &used);
                if (used != s.size()) return "'" + s + "' is not a number";
            } catch (const std::exception&) {
                return "'" + s + "' is not a number";
            }
            if (!std::isfinite(x) || x < lo || x > hi)
                return "value " + s + " is outside " + std::to_string(lo) + ".." + std::to_string(hi);
            return {};
        },
        "FLOAT in [" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]");
}

/// Choices shared by every command that builds a model.
struct ModelOptions {
    std::string string = "cello-D";
    std::string model = "thermal";
    std::string fit = "auto";
    std::string speedFunction = "rod";
    std::string contact = "amontons";
    double contactExponent = 2.0 / 3.0;
    std::string rosin = "violin";
    double ambient = 20.0;
    double footprint = 1.0;
    bool noTorsion = false, noLosses = false, dispersion = false;
    std::string presets;
    std::vector<std::string> overrides;

    void add(CLI::App* app)
    {
        app->add_option("--string", string, "String preset id (see `rosin strings`), or FILE.json:NAME")
            ->capture_default_str();
        app->add_option("--model", model, "Friction model: friction-curve (mu of sliding speed), thermal (mu of "
                                          "contact temperature), enhanced (temperature and speed)")
            ->check(CLI::IsMember({"friction-curve", "thermal", "enhanced"}))
            ->capture_default_str();
        app->add_option("--fit", fit, "Steady-sliding fit the laws are built from: sw (Smith & Woodhouse "
                                      "exponentials), wg (Woodhouse & Galluzzo power law); auto = wg for "
                                      "the enhanced model, sw otherwise")
            ->check(CLI::IsMember({"auto", "sw", "wg"}))
            ->capture_default_str();
        app->add_option("--speed-function", speedFunction, "Enhanced model only: speed function of a rosined rod or of a real bow")
            ->check(CLI::IsMember({"rod", "bow"}))
            ->capture_default_str();
        app->add_option("--contact", contact, "Contact-area law: amontons (area ~ force, a bow's many "
                                              "hairs), hertz (area ~ force^(2/3), a smooth rod), power "
                                              "(area ~ force^n, n from --contact-exponent)")
            ->check(CLI::IsMember({"amontons", "hertz", "power"}))
            ->capture_default_str();
        app->add_option("--contact-exponent", contactExponent, "Exponent n for --contact power")
            ->check(finiteIn(0.1, 2.0));
        app->add_option("--rosin", rosin, "Rosin preset (violin: Tg 49 C, bass: Tg 16 C) or a rosin JSON file")
            ->capture_default_str();
        app->add_option("--ambient", ambient, "Ambient temperature (C)")->check(finiteIn(-30.0, 60.0))->capture_default_str();
        app->add_option("--footprint", footprint, "Footprint ratio r_A: contact area per newton relative to "
                                                  "the steady-sliding test (thermal models)")
            ->check(finiteIn(0.05, 20.0))
            ->capture_default_str();
        app->add_flag("--no-torsion", noTorsion, "Leave out torsional waves");
        app->add_flag("--no-losses", noLosses, "Lossless string (ideal rigid ends)");
        app->add_flag("--dispersion", dispersion, "Bending-stiffness dispersion from the string's inharmonicity B");
        app->add_option("--presets", presets, "Presets directory (default: $ROSIN_PRESETS or the source tree's presets/)");
        app->add_option("--set", overrides, "Override a parameter, NAME=VALUE (repeatable): contact_radius_m, layer_thickness_m, "
                                            "rosin_heat_capacity, string_effusivity, rod_effusivity, advection_width_factor, "
                                            "reference_load_n, poles_per_decade, tension_n, length_m, torsion_speed_ratio, "
                                            "torsion_impedance_ratio, q_low, q_high, q_torsion, inharmonicity");
    }

    dsp::BowedStringConfig build() const
    {
        const fs::path dir = presetDirectory(presets);
        dsp::BowedStringConfig c;
        c.string = findString(dir, string).params;
        const std::map<std::string, dsp::FrictionModel> models{{"friction-curve", dsp::FrictionModel::FrictionCurve},
                                                               {"thermal", dsp::FrictionModel::Thermal},
                                                               {"enhanced", dsp::FrictionModel::Enhanced}};
        c.friction.model = models.at(model);
        const std::string f = fit == "auto" ? (model == "enhanced" ? "wg" : "sw") : fit;
        c.friction.fit = f == "wg" ? dsp::SteadyFit::WoodhouseGalluzzo : dsp::SteadyFit::SmithWoodhouse;
        c.friction.speedFunction = speedFunction == "bow" ? dsp::SpeedFunction::Bow : dsp::SpeedFunction::Rod;
        c.friction.contactLaw = contact == "amontons" ? dsp::ContactLaw::Amontons : dsp::ContactLaw::PowerLaw;
        c.friction.contactExponent = contact == "hertz" ? 2.0 / 3.0 : contactExponent;
        c.friction.thermal.glassTransitionCelsius = findRosin(dir, rosin).glassTransitionCelsius;
        c.friction.thermal.ambientCelsius = ambient;
        c.friction.thermal.footprintRatio = footprint;
        c.waveguide.torsion = !noTorsion;
        c.waveguide.losses = !noLosses;
        c.waveguide.dispersion = dispersion;
        auto& t = c.friction.thermal;
        auto& st = c.string;
        const double f0 = st.fundamental();
        const std::map<std::string, double*> fields{
            {"contact_radius_m", &t.contactRadiusAtRef}, {"layer_thickness_m", &t.layerThickness},
            {"rosin_heat_capacity", &t.rosinHeatCapacity}, {"string_effusivity", &t.stringEffusivity},
            {"rod_effusivity", &t.rodEffusivity}, {"advection_width_factor", &t.advectionWidthFactor},
            {"reference_load_n", &t.referenceLoad}, {"poles_per_decade", &t.polesPerDecade},
            {"tension_n", &st.tension}, {"length_m", &st.length}, {"torsion_speed_ratio", &st.torsionSpeedRatio},
            {"torsion_impedance_ratio", &st.torsionImpedanceRatio}, {"q_low", &st.qLow}, {"q_high", &st.qHigh},
            {"q_torsion", &st.qTorsion}, {"inharmonicity", &st.inharmonicity}};
        bool keepPitch = false;
        for (const auto& kv : overrides) {
            const auto eq = kv.find('=');
            const std::string name = kv.substr(0, eq);
            const auto it = fields.find(name);
            if (eq == std::string::npos || it == fields.end()) throw LabError("--set: unknown parameter '" + name + "'");
            double v = 0;
            try {
                std::size_t used = 0;
                v = std::stod(kv.substr(eq + 1), &used);
                if (used != kv.size() - eq - 1) throw std::invalid_argument("trailing");
            } catch (const std::exception&) {
                throw LabError("--set " + name + ": '" + kv.substr(eq + 1) + "' is not a number");
            }
            if (!std::isfinite(v) || v < 0 || (v == 0 && name != "inharmonicity")) throw LabError("--set " + name + ": must be a positive number");
            *it->second = v;
            keepPitch |= name == "tension_n" || name == "length_m";
        }
        // A new tension or length keeps the string's pitch: its mass per length follows.
        if (keepPitch) st.massPerLength = st.tension / std::pow(2.0 * st.length * f0, 2.0);
        if (const std::string problem = st.validate(); !problem.empty()) throw LabError("--set: " + problem);
        return c;
    }
};

int runRender(const ModelOptions& m, const std::string& gestureName, const Gesture& g0, const std::string& gestureFile,
              double duration, double sampleRate, const std::string& out, bool noCsv, bool listen, bool quiet)
{
    RenderSpec spec;
    spec.config = m.build();
    spec.gesture = g0;
    spec.gesture.kind = gestureFile.empty() ? parseGestureKind(gestureName) : GestureKind::File;
    if (spec.gesture.kind == GestureKind::File) {
        if (gestureFile.empty()) throw LabError("--gesture file needs --gesture-file FILE");
        spec.gesture.rows = loadGestureFile(gestureFile);
    }
    spec.sampleRate = sampleRate;
    spec.duration = duration > 0 ? duration : (spec.gesture.kind == GestureKind::File ? spec.gesture.naturalDuration() : 0.3);

    OutputSet outputs;
    const fs::path wavPath = out + ".wav", csvPath = out + ".csv";
    const fs::path wavTmp = outputs.add(wavPath);
    const fs::path csvTmp = noCsv ? fs::path() : outputs.add(csvPath);

    Progress progress("rendering", !quiet);
    const RenderResult result = render(spec, [&](double x) { progress.update(x); });
    progress.finish();

    std::vector<double> bridge(result.frames.size());
    for (std::size_t i = 0; i < bridge.size(); ++i) bridge[i] = result.frames[i].bridgeForce;
    writeWav(wavTmp, bridge, result.sampleRate, listen ? WavEncoding::Pcm24Normalized : WavEncoding::Float32);
    if (!noCsv) writeRenderCsv(csvTmp, result);
    outputs.commit();

    if (!quiet) {
        const RenderSummary s = summarise(result);
        std::printf("string %s (f0 %.2f Hz, Z0 %.3f kg/s), model %s, %.0f Hz, %.3f s\n", spec.config.string.name.c_str(),
                    spec.config.string.fundamental(), spec.config.string.impedance(), m.model.c_str(), spec.sampleRate,
                    spec.duration);
        if (s.firstSlipTime >= 0)
            std::printf("first slip at %.2f ms (bridge force before it %.3f N)\n", 1e3 * s.firstSlipTime,
                        s.bridgeForceBeforeSlip);
        else
            std::printf("the bow never slipped\n");
        std::printf("peak bridge force %.3f N, peak contact rise %.1f K, slipping %.1f %% of the time\n",
                    s.peakBridgeForce, s.peakTemperatureRise, 100.0 * s.slipFraction);
        std::printf("wrote %s%s%s\n", wavPath.c_str(), noCsv ? "" : " and ", noCsv ? "" : csvPath.c_str());
    }
    return 0;
}

struct GuettlerCli {
    double aMin = 0.15, aMax = 3.0, fMin = 0.15, fMax = 3.0;
    int aCount = 20, fCount = 20, variants = 1;
    std::vector<double> betas{0.0899};
    std::uint64_t seed = 1;
    double sampleRate = 48000.0;
    std::string out = "guettler";
    bool noBounds = false, noFit = false, quiet = false;
};

int runGuettler(const ModelOptions& m, const GuettlerCli& g)
{
    SweepSpec spec;
    spec.config = m.build();
    spec.label = m.model + (m.model == "enhanced" ? " (" + m.speedFunction + ")" : "") + ", " +
                 (spec.config.friction.fit == dsp::SteadyFit::WoodhouseGalluzzo ? "WG" : "SW") + " fit, " + m.contact;
    spec.sampleRate = g.sampleRate;
    spec.accelerations = SweepSpec::grid(g.aMin, g.aMax, g.aCount);
    spec.forces = SweepSpec::grid(g.fMin, g.fMax, g.fCount);
    spec.betas = g.betas;
    spec.variants = g.variants;
    spec.seed = g.seed;
    const Distributed& dist = Distributed::instance();
    OutputSet outputs;
    fs::path csv, json, png;
    if (dist.isRoot()) {
        csv = outputs.add(g.out + ".csv");
        json = outputs.add(g.out + ".json");
        png = outputs.add(g.out + ".png");
    }
    Progress progress("sweep", !g.quiet && dist.isRoot());
    const SweepResult r = runSweep(spec, [&](double x) { progress.update(x); });
    progress.finish();
    if (!dist.isRoot()) return 0;
    writeSweepCsv(csv, r);
    writeSweepJson(json, r);
    DiagramOptions o;
    o.bounds = !g.noBounds;
    o.fit = !g.noFit;
    o.muS = dsp::steadySliding(spec.config.friction.fit, 0.0).mu;
    writeGuettlerPng(png, r, o);
    outputs.commit();
    if (!g.quiet) {
        const std::size_t cells = r.cells.size();
        std::printf("%s on %s: %d of %zu cells reach Helmholtz within 25 periods%s\n", spec.label.c_str(),
                    spec.config.string.name.c_str(), r.successCount(), cells,
                    g.variants > 1 ? (" (min over " + std::to_string(g.variants) + " variants)").c_str() : "");
        for (std::size_t ib = 0; ib < spec.betas.size(); ++ib) {
            const BoundaryFit fit = fitLowerBoundary(r, ib);
            if (fit.valid)
                std::printf("beta %.4g: lower boundary F = %.3f a^p, p = %.3f (95%% CI %.3f..%.3f, %zu columns)\n", spec.betas[ib],
                            fit.c, fit.p, fit.pLow, fit.pHigh, fit.accelerations.size());
            else
                std::printf("beta %.4g: too few boundary points for a fit\n", spec.betas[ib]);
        }
        std::printf("%.2f s wall, %.0f strokes/s, %.1f M samples/s on %d process(es); wrote %s.{csv,json,png}\n", r.wallSeconds,
                    double(cells * static_cast<std::size_t>(g.variants)) / r.wallSeconds, double(r.simulatedSamples) / r.wallSeconds / 1e6,
                    dist.size(), g.out.c_str());
    }
    return 0;
}

int runClassify(const ModelOptions& m, const std::vector<std::string>& files, const std::string& gestureName,
                const Gesture& g0, bool measured, int channel, const std::string& out, bool quiet)
{
    const dsp::BowedStringConfig config = m.build();
    Gesture gesture = g0;
    gesture.kind = parseGestureKind(gestureName);
    if (gesture.kind == GestureKind::File) throw LabError("--gesture file is not supported by classify");
    std::vector<std::pair<std::string, Classification>> records;
    for (const auto& f : files) {
        const Signal sig = readSignal(f, channel);
        ClassifierInput in;
        in.bridgeForce = sig.samples;
        in.sampleRate = sig.sampleRate;
        in.f0 = config.string.fundamental();
        in.beta = gesture.beta;
        in.z0 = config.string.impedance();
        in.tension = config.string.tension;
        in.length = config.string.length;
        in.bowSpeed = [gesture](double t) { return t < 0 ? 0.0 : gesture.at(t).speed; };
        in.measured = measured;
        records.emplace_back(f, classify(in));
    }
    OutputSet outputs;
    const fs::path csvTmp = outputs.add(out + ".csv");
    const fs::path jsonTmp = outputs.add(out + ".json");
    {
        std::unique_ptr<FILE, int (*)(FILE*)> csv(std::fopen(csvTmp.c_str(), "w"), &std::fclose);
        if (!csv) throw LabError(out + ".csv: cannot write");
        std::fprintf(csv.get(), "file,regime,success,transient_periods,first_slip_s,bridge_force_before_slip,first_drop,gain,trigger_s,hum_hz,labels\n");
        nlohmann::json all = nlohmann::json::array();
        for (const auto& [file, c] : records) {
            std::fprintf(csv.get(), "%s,%s,%d,%d,%.9g,%.9g,%.9g,%.6g,%.6g,%.0f,%s\n", file.c_str(), regimeName(c.regime), c.success ? 1 : 0,
                         c.transientPeriods, c.firstSlipTime, c.forceBeforeSlip, c.firstDrop, c.gain, c.triggerTime,
                         c.humFrequency, c.labels.c_str());
            all.push_back({{"file", file}, {"regime", regimeName(c.regime)}, {"success", c.success},
                           {"transient_periods", c.transientPeriods}, {"first_slip_s", c.firstSlipTime},
                           {"bridge_force_before_slip", c.forceBeforeSlip}, {"first_drop", c.firstDrop}, {"gain", c.gain},
                           {"trigger_s", c.triggerTime}, {"hum_hz", c.humFrequency}, {"period_labels", c.labels},
                           {"flybacks_s", c.flybacks}});
            if (!quiet)
                std::printf("%s: %s, %s%s, first slip %.2f ms, labels %s\n", file.c_str(), regimeName(c.regime),
                            c.success ? "Helmholtz after " : "no Helmholtz within 25 periods",
                            c.success ? (std::to_string(c.transientPeriods) + " periods").c_str() : "", 1e3 * c.firstSlipTime,
                            c.labels.c_str());
        }
        std::unique_ptr<FILE, int (*)(FILE*)> js(std::fopen(jsonTmp.c_str(), "w"), &std::fclose);
        if (!js) throw LabError(out + ".json: cannot write");
        const std::string text = nlohmann::json{{"format", "rosin-classify/1"}, {"records", all}}.dump(1);
        std::fwrite(text.data(), 1, text.size(), js.get());
    }
    outputs.commit();
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"rosin: bowed-string physics from rosin friction (Woodhouse, Euphonics 9.6).\n"
                 "Simulates bow strokes on a string with a chosen friction model and writes what a\n"
                 "researcher measures: the bridge force, and the bow-point velocity, friction force\n"
                 "and contact temperature behind it. All quantities are SI units."};
    app.require_subcommand(1);
    app.footer("Examples:\n"
               "  rosin render --force 1 --accel 1 --out stroke      Guettler stroke on the cello D\n"
               "  rosin render --gesture-file presets/gestures/demo-phrase.csv --listen --out phrase\n"
               "  rosin render --model enhanced --contact hertz --gesture constant --speed 0.1\n"
               "  rosin strings                                      list the string presets\n"
               "Run `rosin COMMAND --help` for each command's options.");

    // ---- render
    CLI::App* renderCmd = app.add_subcommand("render", "Simulate one bow gesture; write the bridge force as WAV and "
                                                       "every simulated quantity as CSV");
    renderCmd->footer(
        "Gestures (PHYSICS.md 6.1):\n"
        "  guettler   force F constant, speed a*t from rest (--force, --accel)\n"
        "  constant   force F and speed v from t = 0 (--force, --speed)\n"
        "  exp-speed  speed v (1 - exp(-t/tau)), force F (--speed, --time-constant, --force)\n"
        "  exp-force  force F (1 - exp(-t/tau)), speed v (--force, --time-constant, --speed)\n"
        "  file       rows time,force,speed,beta from --gesture-file, linear in between\n"
        "Outputs: OUT.wav (bridge force in newtons as 32-bit float, or normalised 24-bit with\n"
        "--listen) and OUT.csv (time_s, bridge_force_N, bow_point_velocity_m_s, friction_force_N,\n"
        "contact_temperature_C, temperature_rise_K, stick, bow_force_N, bow_speed_m_s, beta).\n"
        "Nothing is written unless the whole render succeeds.");
    ModelOptions renderModel;
    renderModel.add(renderCmd);
    std::string gestureName = "guettler", gestureFile, out = "rosin-render";
    Gesture gesture;
    double duration = 0.0, sampleRate = 192000.0;
    bool noCsv = false, listen = false, quiet = false;
    renderCmd->add_option("--gesture", gestureName, "guettler, constant, exp-speed, exp-force or file")
        ->check(CLI::IsMember({"guettler", "constant", "exp-speed", "exp-force", "file"}))
        ->capture_default_str();
    renderCmd->add_option("--gesture-file", gestureFile, "CSV of time,force,speed,beta rows (implies --gesture file)")
        ->check(CLI::ExistingFile);
    renderCmd->add_option("--force", gesture.force, "Bow force F (N)")->check(finiteIn(0.0, 20.0))->capture_default_str();
    renderCmd->add_option("--accel", gesture.acceleration, "Bow acceleration a (m/s^2)")->check(finiteIn(-100.0, 100.0))->capture_default_str();
    renderCmd->add_option("--speed", gesture.speed, "Bow speed v (m/s; negative = up bow)")->check(finiteIn(-10.0, 10.0))->capture_default_str();
    renderCmd->add_option("--time-constant", gesture.timeConstant, "tau of the exponential gestures (s)")
        ->check(finiteIn(1e-4, 10.0))
        ->capture_default_str();
    renderCmd->add_option("--beta", gesture.beta, "Bow position: distance from the bridge / string length")
        ->check(finiteIn(dsp::config::minBeta, dsp::config::maxBeta))
        ->capture_default_str();
    renderCmd->add_option("--duration", duration, "Seconds to simulate (default: 0.3, or the gesture file's length)")
        ->check(finiteIn(1e-3, 600.0));
    renderCmd->add_option("--sample-rate", sampleRate, "Simulation rate (Hz); research default 192 kHz")
        ->check(finiteIn(8000.0, 1.0e6))
        ->capture_default_str();
    renderCmd->add_option("-o,--out", out, "Output path prefix: writes OUT.wav and OUT.csv")->capture_default_str();
    renderCmd->add_flag("--no-csv", noCsv, "Write only the WAV");
    renderCmd->add_flag("--listen", listen, "Normalised 24-bit WAV for listening instead of newtons");
    renderCmd->add_flag("-q,--quiet", quiet, "No progress and no summary");

    // ---- strings
    CLI::App* stringsCmd = app.add_subcommand("strings", "List the string presets with their physical constants");
    std::string stringsPresets;
    stringsCmd->add_option("--presets", stringsPresets, "Presets directory");

    // ---- bench
    CLI::App* benchCmd = app.add_subcommand("bench", "Time one held note (the shared/bench/peers protocol): prints "
                                                     "RESULT name ns_per_sample rt_factor rms");
    BenchOptions bench;
    ModelOptions benchModel;
    benchModel.string = "violin-A";
    benchModel.add(benchCmd);
    std::string precision = "float";
    benchCmd->add_option("--seconds", bench.seconds, "Audio seconds per timed pass")->check(finiteIn(0.01, 3600.0))->capture_default_str();
    benchCmd->add_option("--warmup", bench.warmup, "Untimed seconds before timing")->check(finiteIn(0.0, 60.0))->capture_default_str();
    benchCmd->add_option("--sr", bench.sampleRate, "Sample rate (Hz)")->check(finiteIn(8000.0, 1.0e6))->capture_default_str();
    benchCmd->add_option("--block", bench.block, "Block size")->check(CLI::Range(1, 65536))->capture_default_str();
    benchCmd->add_option("--reps", bench.reps, "Timed passes (best is reported)")->check(CLI::Range(1, 1000))->capture_default_str();
    benchCmd->add_option("--name", bench.name, "Name in the RESULT line")->capture_default_str();
    benchCmd->add_option("--freq", bench.frequency, "Pitch of the held note (Hz): the string is stopped to it")
        ->check(finiteIn(20.0, 4000.0))
        ->capture_default_str();
    benchCmd->add_option("--precision", precision, "float (plugin voice) or double (research)")
        ->check(CLI::IsMember({"float", "double"}))
        ->capture_default_str();

    // ---- guettler
    CLI::App* guettlerCmd = app.add_subcommand("guettler", "Guettler diagram: a constant-acceleration stroke from rest for every "
                                                           "(acceleration, force) cell, classified; table (CSV, JSON) and PNG");
    guettlerCmd->footer("Colours: light = Helmholtz soon after the first slip, dark = late (25 periods); blue double slip,\n"
                        "cyan double flyback, red irregular, black no slip; a dot marks S-motion. Dashed lines: Guettler's\n"
                        "lossless-string bounds; black curve: the fitted lower boundary F = c a^p.\n"
                        "Runs on all cores; under `mpirun -np N rosin guettler ...` the grid is split over N processes\n"
                        "and the table is identical to a single-process run.");
    ModelOptions guettlerModel;
    guettlerModel.add(guettlerCmd);
    GuettlerCli gcli;
    guettlerCmd->add_option("--accel-min", gcli.aMin, "Lowest acceleration (m/s^2)")->check(finiteIn(0.001, 100))->capture_default_str();
    guettlerCmd->add_option("--accel-max", gcli.aMax, "Highest acceleration (m/s^2)")->check(finiteIn(0.001, 100))->capture_default_str();
    guettlerCmd->add_option("--accel-count", gcli.aCount, "Accelerations")->check(CLI::Range(1, 400))->capture_default_str();
    guettlerCmd->add_option("--force-min", gcli.fMin, "Lowest bow force (N)")->check(finiteIn(0.001, 20))->capture_default_str();
    guettlerCmd->add_option("--force-max", gcli.fMax, "Highest bow force (N)")->check(finiteIn(0.001, 20))->capture_default_str();
    guettlerCmd->add_option("--force-count", gcli.fCount, "Forces")->check(CLI::Range(1, 400))->capture_default_str();
    guettlerCmd->add_option("--beta", gcli.betas, "Bow position(s); repeat for several diagrams")
        ->check(finiteIn(dsp::config::minBeta, dsp::config::maxBeta))
        ->capture_default_str();
    guettlerCmd->add_option("--variants", gcli.variants, "1 = plain; N = minimum transient over N perturbed runs (PHYSICS.md 6.7)")
        ->check(CLI::Range(1, 64))
        ->capture_default_str();
    guettlerCmd->add_option("--seed", gcli.seed, "Seed of the perturbations (results are deterministic per seed)")->capture_default_str();
    guettlerCmd->add_option("--sample-rate", gcli.sampleRate, "Simulation rate (Hz); 48 kHz is converged for maps (see README)")
        ->check(finiteIn(8000.0, 1.0e6))
        ->capture_default_str();
    guettlerCmd->add_option("-o,--out", gcli.out, "Output prefix: OUT.csv, OUT.json, OUT.png")->capture_default_str();
    guettlerCmd->add_flag("--no-bounds", gcli.noBounds, "Leave out Guettler's theoretical bounds");
    guettlerCmd->add_flag("--no-fit", gcli.noFit, "Leave out the fitted lower boundary");
    guettlerCmd->add_flag("-q,--quiet", gcli.quiet, "No progress and no summary");

    // ---- panel
    CLI::App* panelCmd = app.add_subcommand("panel", "Lay out Guettler diagrams from earlier `rosin guettler` tables side by side");
    std::vector<std::string> panelFiles, panelTitles;
    std::string panelOut = "panel.png";
    int panelColumns = 2;
    panelCmd->add_option("tables", panelFiles, "JSON tables written by rosin guettler")->required()->check(CLI::ExistingFile);
    panelCmd->add_option("--title", panelTitles, "Title per diagram, in order (default: the model)");
    panelCmd->add_option("--columns", panelColumns, "Diagrams per row")->check(CLI::Range(1, 8))->capture_default_str();
    panelCmd->add_option("-o,--out", panelOut, "PNG to write")->capture_default_str();

    // ---- classify
    CLI::App* classifyCmd = app.add_subcommand("classify", "Classify bow-stroke transients from bridge-force recordings or renders "
                                                           "(WAV of any format, or CSV with time_s and bridge_force_N)");
    classifyCmd->footer("Prints one line per file and writes OUT.csv and OUT.json with one record each: regime, periods to\n"
                        "Helmholtz, first-slip time, per-period labels (H Helmholtz, S double slip, F double flyback,\n"
                        "X irregular). --measured removes DC and mains hum, low-passes, and estimates the unknown gain\n"
                        "and trigger time from the pre-slip ramp of the given gesture.");
    ModelOptions classifyModel;
    classifyModel.add(classifyCmd);
    std::vector<std::string> classifyFiles;
    std::string classifyGesture = "guettler", classifyOut = "classify";
    Gesture classifyG;
    bool measured = false, classifyQuiet = false;
    int channel = 0;
    classifyCmd->add_option("files", classifyFiles, "Recordings or renders")->required()->check(CLI::ExistingFile);
    classifyCmd->add_option("--gesture", classifyGesture, "Gesture of the strokes: guettler, constant, exp-speed, exp-force")
        ->check(CLI::IsMember({"guettler", "constant", "exp-speed", "exp-force"}))
        ->capture_default_str();
    classifyCmd->add_option("--accel", classifyG.acceleration, "Bow acceleration (m/s^2)")->check(finiteIn(-100.0, 100.0))->capture_default_str();
    classifyCmd->add_option("--speed", classifyG.speed, "Bow speed (m/s)")->check(finiteIn(-10.0, 10.0))->capture_default_str();
    classifyCmd->add_option("--time-constant", classifyG.timeConstant, "tau of the exponential gestures (s)")->check(finiteIn(1e-4, 10.0));
    classifyCmd->add_option("--beta", classifyG.beta, "Bow position")->check(finiteIn(dsp::config::minBeta, dsp::config::maxBeta))->capture_default_str();
    classifyCmd->add_flag("--measured", measured, "Treat the files as recordings (DC, hum, noise, unknown gain and trigger)");
    classifyCmd->add_option("--channel", channel, "Channel of multi-channel files (0-based)")->check(CLI::Range(0, 64));
    classifyCmd->add_option("-o,--out", classifyOut, "Output prefix: OUT.csv and OUT.json")->capture_default_str();
    classifyCmd->add_flag("-q,--quiet", classifyQuiet, "No per-file lines");

    // ---- diagnose
    CLI::App* diagnoseCmd = app.add_subcommand("diagnose", "Compare a measurement set with the model, name what it gets wrong, "
                                                           "extend it, and measure the gain on held-out strokes");
    diagnoseCmd->footer("Writes OUT/diagnosis.json (shared/docs/DIAGNOSIS.md), OUT/report.md and its figures\n"
                        "(maps.png, overlays.png, jumps.png). A broken set is refused before anything is written.");
    std::string diagSet, diagOut = "diagnosis";
    DiagnoseOptions diagOptions;
    diagnoseCmd->add_option("set", diagSet, "Measurement set folder (rosin-measurement/1)")->required();
    diagnoseCmd->add_option("-o,--out", diagOut, "New output folder")->capture_default_str();
    diagnoseCmd->add_option("--seed", diagOptions.seed, "Seed of the fit/held-out split and the bootstraps")->capture_default_str();
    diagnoseCmd->add_option("--sim-rate", diagOptions.simRate, "Simulation rate (Hz)")->check(finiteIn(16000, 400000))->capture_default_str();
    diagnoseCmd->add_option("--max-evaluations", diagOptions.maxEvaluations, "Model evaluations per candidate fit")->check(CLI::Range(5, 500))->capture_default_str();
    diagnoseCmd->add_flag("-q,--quiet", diagOptions.quiet, "No progress and no summary");

    // ---- synth-data
    CLI::App* synthCmd = app.add_subcommand("synth-data", "Write a measurement set (rosin-measurement/1) simulated with hidden "
                                                          "effects and a real rig's artefacts");
    synthCmd->footer("Effects (shared/docs/DIAGNOSIS.md): thermal_memory, rate_dependence, hertzian_contact,\n"
                     "rosin_temperature_shift, torsional_compliance; none given = the baseline (friction curve,\n"
                     "Amontons, no torsion, reference rosin). Their parameters are drawn from the seed unless\n"
                     "given, and written with the gain to OUT.truth.json beside the set, never inside it.");
    SynthSpec synth;
    std::string synthOut = "set", wavKind = "pcm24";
    std::vector<std::string> synthParams;
    synthCmd->add_option("-o,--out", synthOut, "New folder for the set (must not exist)")->capture_default_str();
    synthCmd->add_option("--effect", synth.effects, "Hidden effect; repeat for several")->check(CLI::IsMember(effectIds()));
    synthCmd->add_option("--param", synthParams, "Hidden parameter NAME=VALUE (r_A, h0, p, load_exponent, shift_k, zt_ratio)");
    synthCmd->add_option("--seed", synth.seed, "Seed of parameters, jitter and artefacts")->capture_default_str();
    synthCmd->add_option("--grid", synth.grid, "Strokes per axis of the Guettler grid")->check(CLI::Range(2, 60))->capture_default_str();
    synthCmd->add_option("--rate", synth.outRate, "Sample rate of the files (Hz)")->check(finiteIn(8000, 384000))->capture_default_str();
    synthCmd->add_option("--sim-rate", synth.simRate, "Rate of the simulation behind them (Hz)")->check(finiteIn(8000, 1e6))->capture_default_str();
    synthCmd->add_option("--units", synth.units, "V (unknown gain) or N (calibrated)")->check(CLI::IsMember({"V", "N"}))->capture_default_str();
    synthCmd->add_option("--noise", synth.noise, "White noise (N rms)")->check(finiteIn(0, 1))->capture_default_str();
    synthCmd->add_option("--hum", synth.humHz, "Mains frequency (Hz; 0 = no hum)")->check(CLI::IsMember({"0", "50", "60"}))->capture_default_str();
    synthCmd->add_option("--hum-level", synth.humLevel, "Hum amplitude (N)")->check(finiteIn(0, 1))->capture_default_str();
    synthCmd->add_option("--dc", synth.dcLevel, "DC offset (N)")->check(finiteIn(-10, 10))->capture_default_str();
    synthCmd->add_option("--trigger-max", synth.triggerMax, "Gesture starts up to this late in each file (s)")->check(finiteIn(0, 1))->capture_default_str();
    synthCmd->add_option("--jitter", synth.jitter, "Per-stroke relative jitter of force and acceleration")->check(finiteIn(0, 0.2))->capture_default_str();
    synthCmd->add_option("--wav", wavKind, "Sample format: pcm16, pcm24, pcm32, float, double")
        ->check(CLI::IsMember({"pcm16", "pcm24", "pcm32", "float", "double"}))
        ->capture_default_str();
    synthCmd->add_flag("--gaussian-reflections", synth.gaussianReflections, "Simulate with MSW83 Gaussian-pulse reflections");
    synthCmd->add_option("--two-ended", synth.twoEnded, "Steady strokes recorded at both string ends")->check(CLI::Range(0, 20))->capture_default_str();
    bool synthQuiet = false;
    synthCmd->add_flag("-q,--quiet", synthQuiet, "No progress and no summary");

    // ---- figures
    CLI::App* figuresCmd = app.add_subcommand("figures", "Regenerate the Euphonics 9.6 figure set from scratch (PNG + CSV/JSON)");
    FigureSetOptions figOptions;
    std::string figDir = "figures";
    figuresCmd->add_option("-o,--out", figDir, "Output directory")->capture_default_str();
    figuresCmd->add_option("--sample-rate", figOptions.sweepRate, "Rate of the Guettler sweeps (Hz)")->check(finiteIn(8000.0, 1.0e6))->capture_default_str();
    figuresCmd->add_option("--variants", figOptions.variants, "Variants of the min-over-N maps")->check(CLI::Range(2, 64))->capture_default_str();
    figuresCmd->add_option("--grid", figOptions.grid, "Cells per axis")->check(CLI::Range(5, 100))->capture_default_str();
    figuresCmd->add_option("--seed", figOptions.seed, "Perturbation seed")->capture_default_str();
    figuresCmd->add_flag("-q,--quiet", figOptions.quiet, "No progress and no summary");

    if (argc > 1 && argv[1][0] != '-') {
        bool known = false;
        for (const CLI::App* sub : app.get_subcommands({})) known |= sub->get_name() == argv[1];
        if (!known) {
            std::fprintf(stderr, "rosin: unknown command '%s' (render, guettler, panel, classify, figures, synth-data, diagnose, strings, bench; see rosin --help)\n", argv[1]);
            return 2;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        if (*renderCmd)
            return runRender(renderModel, gestureName, gesture, gestureFile, duration, sampleRate, out, noCsv, listen, quiet);
        if (*stringsCmd) {
            std::printf("%-16s %-5s %9s %7s %7s %9s %8s %8s\n", "id", "note", "f0 (Hz)", "L (m)", "T (N)", "m (g/m)",
                        "Z0 (kg/s)", "c (m/s)");
            for (const auto& p : loadAllStrings(presetDirectory(stringsPresets))) {
                const auto& q = p.params;
                std::printf("%-16s %-5s %9.2f %7.3f %7.1f %9.3f %8.3f %8.1f\n", p.id.c_str(), p.note.c_str(),
                            q.fundamental(), q.length, q.tension, 1e3 * q.massPerLength, q.impedance(), q.waveSpeed());
            }
            return 0;
        }
        if (*guettlerCmd) {
            if (gcli.aMin > gcli.aMax) throw LabError("--accel-min must not exceed --accel-max");
            if (gcli.fMin > gcli.fMax) throw LabError("--force-min must not exceed --force-max");
            return runGuettler(guettlerModel, gcli);
        }
        if (*panelCmd) {
            std::vector<SweepResult> sweeps;
            for (const auto& f : panelFiles) sweeps.push_back(readSweepJson(f));
            OutputSet outputs;
            const fs::path tmp = outputs.add(panelOut);
            writePanelPng(tmp, sweeps, panelTitles, panelColumns, DiagramOptions{});
            outputs.commit();
            std::printf("wrote %s (%zu diagrams)\n", panelOut.c_str(), sweeps.size());
            return 0;
        }
        if (*classifyCmd) return runClassify(classifyModel, classifyFiles, classifyGesture, classifyG, measured, channel, classifyOut, classifyQuiet);
        if (*diagnoseCmd) {
            if (fs::exists(diagOut)) throw LabError(diagOut + ": already exists (choose a new folder)");
            const MeasurementSet set = readMeasurementSet(diagSet);
            Progress progress("diagnosing", !diagOptions.quiet);
            std::string stage;
            const Diagnosis dg = diagnose(set, diagOptions, [&](const std::string& what, double x) {
                (void)what;
                progress.update(x);
            });
            progress.finish();
            std::string hidden = ".";
            hidden += fs::path(diagOut).filename().string();
            hidden += ".partial";
            const fs::path tmp = (fs::path(diagOut).has_parent_path() ? fs::path(diagOut).parent_path() : fs::path(".")) / hidden;
            fs::remove_all(tmp);
            try {
                writeDiagnosis(tmp, dg, diagOptions);
                fs::rename(tmp, diagOut);
            } catch (...) {
                std::error_code ec;
                fs::remove_all(tmp, ec);
                throw;
            }
            if (!diagOptions.quiet) {
                for (const auto& w : dg.warnings) std::printf("warning: %s\n", w.c_str());
                for (const auto& t : dg.trials) {
                    std::printf("round %d: %-24s", t.round, t.effect.c_str());
                    for (const auto& [k, v] : t.parameters) std::printf(" %s=%.3g", k.c_str(), v);
                    std::printf("  held-out fall %.3f [%.3f, %.3f]%s\n", t.gain, t.gainLow, t.gainHigh, t.kept ? "  kept" : "");
                }
                if (dg.findings.empty()) std::printf("finding: none (the baseline explains the data)\n");
                for (const auto& f : dg.findings) {
                    std::printf("finding: %s", f.effect.c_str());
                    for (const auto& [name, v] : f.parameters) std::printf("  %s = %.3g [%.3g, %.3g]", name.c_str(), v[0], v[1], v[2]);
                    std::printf("\n  %s\n", f.evidence.c_str());
                }
                std::printf("held-out error %.3f -> %.3f (gain %.0f %%, CI %.0f..%.0f %%); %lld simulations in %.1f s; wrote %s/\n",
                            dg.baselineError, dg.finalError, 100 * dg.relativeGain, 100 * dg.gainLow, 100 * dg.gainHigh,
                            dg.simulations, dg.seconds, diagOut.c_str());
            }
            return 0;
        }
        if (*synthCmd) {
            for (const auto& kv : synthParams) {
                const auto eq = kv.find('=');
                if (eq == std::string::npos) throw LabError("--param: expected NAME=VALUE, got '" + kv + "'");
                const std::string key = kv.substr(0, eq);
                if (key != "r_A" && key != "load_exponent" && key != "shift_k" && key != "zt_ratio" && key != "h0" && key != "p")
                    throw LabError("--param: unknown parameter '" + key + "'");
                try {
                    synth.params[key] = std::stod(kv.substr(eq + 1));
                } catch (const std::exception&) {
                    throw LabError("--param: '" + kv + "' has no number");
                }
            }
            if (fs::exists(synthOut)) throw LabError(synthOut + ": already exists (choose a new folder)");
            const std::map<std::string, int> formats{{"pcm16", SF_FORMAT_PCM_16}, {"pcm24", SF_FORMAT_PCM_24},
                                                     {"pcm32", SF_FORMAT_PCM_32}, {"float", SF_FORMAT_FLOAT},
                                                     {"double", SF_FORMAT_DOUBLE}};
            Progress progress("synthesising", !synthQuiet);
            SynthTruth truth;
            const MeasurementSet set = synthesize(synth, truth, [&](double x) { progress.update(x); });
            progress.finish();
            OutputSet outputs;
            const fs::path truthTmp = outputs.add(synthOut + ".truth.json");
            {
                nlohmann::json t{{"format", "rosin-synth-truth/1"}, {"effects", truth.effects}, {"params", truth.params},
                                 {"gain_units_per_N", truth.gain}, {"seed", synth.seed},
                                 {"triggers_s", truth.triggers}};
                std::ofstream(truthTmp) << t.dump(1) << "\n";
            }
            writeMeasurementSet(synthOut, set, formats.at(wavKind));
            outputs.commit();
            if (!synthQuiet)
                std::printf("wrote %s (%zu strokes at %.0f Hz, units %s) and %s.truth.json\n", synthOut.c_str(), set.strokes.size(),
                            set.sampleRate, set.units.c_str(), synthOut.c_str());
            return 0;
        }
        if (*figuresCmd) {
            const std::string report = writeFigureSet(figDir, figOptions);
            if (!figOptions.quiet) std::printf("%s", report.c_str());
            return 0;
        }
        if (*benchCmd) {
            bench.config = benchModel.build();
            bench.useFloat = precision == "float";
            return runBench(bench);
        }
    } catch (const LabError& e) {
        std::fprintf(stderr, "rosin: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rosin: unexpected error: %s\n", e.what());
        return 3;
    }
    return 0;
}
