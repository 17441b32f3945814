// `rosin classify`.
#include "Cli.h"

#include <sndfile.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "rosin/lab/Bench.h"
#include "rosin/lab/Classifier.h"
#include "rosin/lab/Diagnose.h"
#include "rosin/lab/Distributed.h"
#include "rosin/lab/FigureSet.h"
#include "rosin/lab/Figures.h"
#include "rosin/lab/Gesture.h"
#include "rosin/lab/Guettler.h"
#include "rosin/lab/Measurement.h"
#include "rosin/lab/Output.h"
#include "rosin/lab/Render.h"
#include "rosin/lab/Signal.h"
#include "rosin/lab/SynthData.h"

namespace rosin::cli {

namespace {

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

namespace {

/// Options of `rosin classify` (bound by add()) and what runs when it is chosen.
struct ClassifyCommand {
    ModelOptions classifyModel;
    std::vector<std::string> classifyFiles;
    std::string classifyGesture = "guettler", classifyOut = "classify";
    Gesture classifyG;
    bool measured = false, classifyQuiet = false;
    int channel = 0;

    CLI::App* add(CLI::App& app)
    {
        CLI::App* classifyCmd = app.add_subcommand("classify", "Classify bow-stroke transients from bridge-force recordings or renders "
                                                               "(WAV of any format, or CSV with time_s and bridge_force_N)");
        classifyCmd->footer("Prints one line per file and writes OUT.csv and OUT.json with one record each: regime, periods to\n"
                            "Helmholtz, first-slip time, per-period labels (H Helmholtz, S double slip, F double flyback,\n"
                            "X irregular). --measured removes DC and mains hum, low-passes, and estimates the unknown gain\n"
                            "and trigger time from the pre-slip ramp of the given gesture.");
        classifyModel.add(classifyCmd);
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
        return classifyCmd;
    }

    int run()
    {
        return runClassify(classifyModel, classifyFiles, classifyGesture, classifyG, measured, channel, classifyOut, classifyQuiet);
    }
};

} // namespace

Command addClassifyCommand(CLI::App& app)
{
    auto command = std::make_shared<ClassifyCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
