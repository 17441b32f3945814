// Pieces shared by the `rosin` commands: number validation, the model options every
// model-building command takes, and the command registry.
#pragma once
#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rosin/dsp.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Error.h"
#include "rosin/presets/Presets.h"

namespace rosin::cli {
using namespace rosin::lab;
namespace fs = std::filesystem;

/// CLI11's Range lets NaN through; every number we take must be finite and in range.
inline CLI::Validator finiteIn(double lo, double hi)
{
    return CLI::Validator(
        [lo, hi](std::string& s) -> std::string {
            const std::optional<double> number = wholeNumber(s);
            if (!number) return "'" + s + "' is not a number";
            const double x = *number;
            if (!std::isfinite(x) || x < lo || x > hi)
                return "value " + s + " is outside " + std::to_string(lo) + ".." + std::to_string(hi);
            return {};
        },
        "FLOAT in [" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]");
}

/// The diagnosis's two search switches, which `diagnose` and `study` both take. CLI11 shows a
/// two-way flag's spellings, not its default, so the text says the default, read from the options.
inline void addSearchFlags(CLI::App& cmd, DiagnoseOptions& o)
{
    const auto byDefault = [](bool on) { return std::string(on ? " (default: on)" : " (default: off)"); };
    cmd.add_flag("--pairs,!--no-pairs", o.tryPairs,
                 "When a round names nothing, try a Hertzian contact and a rolling string together as one candidate" + byDefault(o.tryPairs))
        ->capture_default_str();
    cmd.add_flag("--contact-restart,!--no-contact-restart", o.restartContact,
                 "A later round's Hertzian contact is searched again from where its first search ended, with a wider first step" +
                     byDefault(o.restartContact))
        ->capture_default_str();
    cmd.add_flag("--second-start,!--no-second-start", o.secondStart,
                 "Refine every fit gridded over two or more parameters also from the best grid point two steps from the grid's best, and keep the better end" +
                     byDefault(o.secondStart))
        ->capture_default_str();
    cmd.add_option_function<std::vector<double>>(
           "--metric-weights",
           [&o](const std::vector<double>& w) {
               if (w.size() != 5) throw CLI::ValidationError("--metric-weights", "give five weights: first-slip time, force before it, jump, transient length, waveform");
               std::array<double, 5> weights{};
               std::copy(w.begin(), w.end(), weights.begin());
               try {
                   checkMetricWeights(weights, "--metric-weights");
               } catch (const LabError& e) {
                   throw CLI::ValidationError(e.what());
               }
               o.metricWeights = weights;
           },
           "The metric's part weights: first-slip time, bridge force before it, jump, transient length, waveform, summing to 1 "
           "(default 0.25,0.25,0.25,0.1,0.15; the naming threshold and the studies' discrepancies were measured with the default)")
        ->delimiter(',')
        ->expected(5);
    cmd.add_flag("--stratified-split,!--random-split", o.stratifiedSplit,
                 "Deal fit, validation and test strokes so that every gesture, drive and bow force of the set gives each its share, "
                 "instead of a shuffle of the whole set" + byDefault(o.stratifiedSplit))
        ->capture_default_str();
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
        app->add_option("--presets", presets, "A presets folder searched before $ROSIN_PRESETS, ~/.local/share/rosin/presets and the built-in set");
        app->add_option("--set", overrides, "Override a parameter, NAME=VALUE (repeatable): contact_radius_m, layer_thickness_m, "
                                            "rosin_heat_capacity, string_effusivity, rod_effusivity, advection_width_factor, "
                                            "reference_load_n, poles_per_decade, tension_n, length_m, torsion_speed_ratio, "
                                            "torsion_impedance_ratio, q_low, q_high, q_torsion, inharmonicity");
    }

    dsp::BowedStringConfig build() const
    {
        presets::Library library = presets::Library::standard();
        if (!presets.empty()) library.addFolder(presets);
        dsp::BowedStringConfig c;
        c.string = presets::findString(library, string).params;
        const std::map<std::string, dsp::FrictionModel> models{{"friction-curve", dsp::FrictionModel::FrictionCurve},
                                                               {"thermal", dsp::FrictionModel::Thermal},
                                                               {"enhanced", dsp::FrictionModel::Enhanced}};
        c.friction.model = models.at(model);
        const std::string f = fit == "auto" ? (model == "enhanced" ? "wg" : "sw") : fit;
        c.friction.fit = f == "wg" ? dsp::SteadyFit::WoodhouseGalluzzo : dsp::SteadyFit::SmithWoodhouse;
        c.friction.speedFunction = speedFunction == "bow" ? dsp::SpeedFunction::Bow : dsp::SpeedFunction::Rod;
        c.friction.contactLaw = contact == "amontons" ? dsp::ContactLaw::Amontons : dsp::ContactLaw::PowerLaw;
        c.friction.contactExponent = contact == "hertz" ? 2.0 / 3.0 : contactExponent;
        c.friction.thermal.glassTransitionCelsius = presets::findRosin(library, rosin).glassTransitionCelsius;
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
            const std::optional<double> number = wholeNumber(kv.substr(eq + 1));
            if (!number) throw LabError("--set " + name + ": '" + kv.substr(eq + 1) + "' is not a number");
            const double v = *number;
            if (!std::isfinite(v) || v < 0 || (v == 0 && name != "inharmonicity")) throw LabError("--set " + name + ": must be a positive number");
            *it->second = v;
            keepPitch |= name == "tension_n" || name == "length_m";
        }
        // A new tension or length keeps the string's pitch: its mass per length follows.
        if (keepPitch) st.tuneTo(f0);
        if (const std::string problem = st.validate(); !problem.empty()) throw LabError("--set: " + problem);
        return c;
    }
};

/// A subcommand and what runs when it is chosen (returns the exit code; may throw LabError).
struct Command {
    CLI::App* app;
    std::function<int()> run;
};

Command addRenderCommand(CLI::App& app);
Command addStringsCommand(CLI::App& app);
Command addBenchCommand(CLI::App& app);
Command addGuettlerCommand(CLI::App& app);
Command addPanelCommand(CLI::App& app);
Command addClassifyCommand(CLI::App& app);
Command addDiagnoseCommand(CLI::App& app);
Command addSynthDataCommand(CLI::App& app);
Command addStudyCommand(CLI::App& app);
Command addFiguresCommand(CLI::App& app);
Command addPlayabilityCommand(CLI::App& app);

} // namespace rosin::cli
