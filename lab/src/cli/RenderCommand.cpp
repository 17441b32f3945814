// `rosin render`.
#include "Cli.h"

#include <sndfile.h>
#include <unistd.h>

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
#include "rosin/lab/ViewFigures.h"

namespace rosin::cli {

namespace {

int runRender(const ModelOptions& m, const std::string& gestureName, const Gesture& g0, const std::string& gestureFile,
              double duration, double sampleRate, const std::string& out, bool noCsv, bool listen, bool quiet, bool views)
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
    const fs::path viewsPng = views ? outputs.add(out + "-views.png") : fs::path();
    const fs::path viewsJson = views ? outputs.add(out + "-views.json") : fs::path();

    Progress progress("rendering", !quiet);
    const RenderResult result = render(spec, [&](double x) { progress.update(x); });
    progress.finish();

    std::vector<double> bridge(result.frames.size());
    for (std::size_t i = 0; i < bridge.size(); ++i) bridge[i] = result.frames[i].bridgeForce;
    writeWav(wavTmp, bridge, result.sampleRate, listen ? WavEncoding::Pcm24Normalized : WavEncoding::Float32);
    if (!noCsv) writeRenderCsv(csvTmp, result);
    if (views) {
        // The plugin window's views at the end of this stroke, over a Schelleng map of the string.
        const LiveHistory h = historyOf(result, spec.config.string.fundamental());
        const auto g = h.gesture();
        PlayabilitySpec ps = PlayabilitySpec::around(MapKind::Schelleng, spec.config, std::max(0.05, g.force),
                                                     std::max(0.02, std::abs(g.speed)), g.beta, 1.0, 0.0, 14, 12);
        ps.sampleRate = std::min(spec.sampleRate, 96000.0);
        const PlayabilityMap map = computePlayability(ps);
        writeLiveViews(viewsPng, viewsJson, h, &map, spec.config.string.name + ", " + m.model + " model");
    }
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
        if (views) std::printf("wrote %s-views.png and %s-views.json\n", out.c_str(), out.c_str());
    }
    return 0;
}

} // namespace

namespace {

/// Options of `rosin render` (bound by add()) and what runs when it is chosen.
struct RenderCommand {
    ModelOptions renderModel;
    std::string gestureName = "guettler", gestureFile, out = "rosin-render";
    Gesture gesture;
    double duration = 0.0, sampleRate = 192000.0;
    bool noCsv = false, listen = false, quiet = false, views = false;
    CLI::Option* rateOption = nullptr;

    CLI::App* add(CLI::App& app)
    {
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
            "Nothing is written unless the whole render succeeds.\n"
            "A MIDI file is played by the instrument (the plugin) in its headless host:\n"
            "  rosin-host render --midi song.mid --preset cello --out song.wav");
        renderModel.add(renderCmd);
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
        rateOption = renderCmd->add_option("--sample-rate", sampleRate, "Simulation rate (Hz); research default 192 kHz")
            ->check(finiteIn(8000.0, 1.0e6))
            ->capture_default_str();
        renderCmd->add_option("-o,--out", out, "Output path prefix: writes OUT.wav and OUT.csv")->capture_default_str();
        renderCmd->add_flag("--no-csv", noCsv, "Write only the WAV");
        renderCmd->add_flag("--views", views, "Also draw the plugin window's live views at the stroke's end (scope, "
                                              "temperature, friction loop, Schelleng map) to OUT-views.png, data in OUT-views.json");
        renderCmd->add_flag("--listen", listen, "Normalised 24-bit WAV for listening instead of newtons");
        renderCmd->add_flag("-q,--quiet", quiet, "No progress and no summary");
        return renderCmd;
    }

    int run()
    {
        return runRender(renderModel, gestureName, gesture, gestureFile, duration, sampleRate, out, noCsv, listen, quiet, views);
    }
};

} // namespace

Command addRenderCommand(CLI::App& app)
{
    auto command = std::make_shared<RenderCommand>();
    CLI::App* sub = command->add(app);
    return {sub, [command] { return command->run(); }};
}

} // namespace rosin::cli
