// rosin-host: the headless host on the command line. Renders MIDI through a built VST3 or LV2
// to WAV, lists parameters, and audits real-time safety (allocations, locks in processBlock).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "AuditCounter.h"
#include "PluginHost.h"
#include "Validate.h"
#include "rosin/presets/Presets.h"
#include "rosin/hid/HidInput.h"

#include <chrono>
#include <thread>

using namespace rosin::host;
namespace fs = std::filesystem;

namespace {
std::vector<Automation> readAutomation(const fs::path& file)
{
    std::ifstream in(file);
    if (!in) throw std::runtime_error(file.string() + ": cannot open automation file");
    std::vector<Automation> out;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        ++number;
        if (line.empty() || line[0] == '#' || line.rfind("seconds", 0) == 0) continue;
        std::istringstream s(line);
        std::string t, id, v;
        if (!std::getline(s, t, ',') || !std::getline(s, id, ',') || !std::getline(s, v))
            throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": expected seconds,param_id,normalised_value");
        Automation a;
        try {
            a.seconds = std::stod(t);
            a.normalised = std::stof(v);
        } catch (...) {
            throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": seconds and value must be numbers");
        }
        if (!(a.normalised >= 0.0f && a.normalised <= 1.0f))
            throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": value must be a normalised 0-1 number");
        a.paramId = id;
        out.push_back(a);
    }
    return out;
}

nlohmann::json auditJson(const rosin::host::audit::Tally& t)
{
    return {{"allocations", t.allocations}, {"frees", t.frees}, {"locks", t.locks}, {"waits", t.waits}, {"blocking_calls", t.blocking}};
}

std::string auditText(const rosin::host::audit::Tally& t)
{
    return std::to_string(t.allocations) + " allocations, " + std::to_string(t.frees) + " frees, " + std::to_string(t.locks) + " locks, " +
           std::to_string(t.waits) + " condition/semaphore calls, " + std::to_string(t.blocking) + " blocking calls";
}

/// The Rosin VST3 next to this program (the build tree's layout), else the user's ~/.vst3 one.
std::string defaultBundle()
{
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (!ec)
        for (const char* config : {"Release", "RelWithDebInfo", "Debug"}) {
            const fs::path built = self.parent_path() / "RosinPlugin_artefacts" / config / "VST3" / "Rosin.vst3";
            if (fs::exists(built)) return built.string();
        }
    if (const char* home = std::getenv("HOME"); home && fs::exists(fs::path(home) / ".vst3" / "Rosin.vst3"))
        return (fs::path(home) / ".vst3" / "Rosin.vst3").string();
    throw std::runtime_error("no Rosin.vst3 beside rosin-host or in ~/.vst3: give --plugin");
}

std::vector<char> readBytes(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) throw std::runtime_error(file.string() + ": cannot open state file");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"rosin-host: play MIDI through a built Rosin VST3 or LV2 without a DAW or a sound card"};
    app.require_subcommand(1);
    std::string plugin;

    auto* render = app.add_subcommand("render", "render MIDI (a .mid file or an event list) to a stereo WAV");
    std::string out, midiFile, eventsFile, automationFile, stateIn, stateOut, report;
    double rate = 48000.0, seconds = 0.0, tail = 2.0;
    int block = 512;
    bool audit = false;
    std::vector<std::string> sets;
    render->add_option("--plugin", plugin, "the plugin bundle (.vst3 or .lv2); default: the Rosin.vst3 built beside this program, else ~/.vst3/Rosin.vst3");
    render->add_option("--out", out, "WAV file to write (32-bit float, stereo)")->required();
    render->add_option("--midi", midiFile, "standard MIDI file (type 0 or 1)");
    render->add_option("--events", eventsFile, "event list: 'seconds hexbytes...' per line");
    render->add_option("--rate", rate, "sample rate (Hz)")->check(CLI::Range(8000.0, 768000.0));
    render->add_option("--block", block, "block size (samples)")->check(CLI::Range(1, 65536));
    render->add_option("--seconds", seconds, "length (default: last event + tail)")->check(CLI::Range(0.0, 3600.0));
    render->add_option("--tail", tail, "seconds after the last event")->check(CLI::Range(0.0, 60.0));
    std::string preset;
    render->add_option("--preset", preset, "instrument preset: violin, viola, cello or double-bass (with its bow and rosin)");
    render->add_option("--set", sets, "parameter before playing: ID=VALUE in its units, or ID=@0.5 normalised (repeatable)");
    render->add_option("--automation", automationFile, "CSV seconds,param_id,normalised (applied per block)");
    render->add_option("--state-in", stateIn, "plugin state to load first (from --state-out)");
    render->add_option("--state-out", stateOut, "write the plugin state after the render");
    render->add_flag("--audit", audit, "count heap allocations and mutex locks inside processBlock");
    render->add_option("--report", report, "JSON report (format, blocks, audit counts, peak)");

    auto* bench = app.add_subcommand("bench", "time one held note through the plugin (the shared/bench/peers protocol): "
                                              "prints RESULT <name> <ns_per_sample> <rt_factor> <rms>");
    double benchSeconds = 10.0, benchSr = 48000.0, warmup = 0.5, freq = 440.0;
    int benchBlock = 256, reps = 5, voices = 1;
    std::string benchName = "rosin_plugin", benchPreset = "violin";
    bench->add_option("--plugin", plugin, "the built plugin bundle (.vst3 or .lv2)")->required();
    bench->add_option("--seconds", benchSeconds, "audio seconds per timed pass")->check(CLI::Range(0.01, 3600.0));
    bench->add_option("--sr", benchSr, "sample rate")->check(CLI::Range(8000.0, 768000.0));
    bench->add_option("--block", benchBlock, "block size")->check(CLI::Range(1, 65536));
    bench->add_option("--reps", reps, "timed passes (best is reported)")->check(CLI::Range(1, 1000));
    bench->add_option("--warmup", warmup, "untimed seconds first")->check(CLI::Range(0.0, 60.0));
    bench->add_option("--name", benchName, "name in the RESULT line")->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    bench->add_option("--freq", freq, "pitch of the held note (Hz), rounded to a MIDI note")->check(CLI::Range(20.0, 5000.0));
    bench->add_option("--voices", voices, "notes held at once (a chord spread over the range)")->check(CLI::Range(1, 16));
    bench->add_option("--preset", benchPreset, "instrument preset");

    auto* validateCmd = app.add_subcommand("validate", "a validation pass like pluginval's: open/close, parameters moved from another "
                                                       "thread, state mid-note, rates and block sizes, mono/stereo, offline, "
                                                       "denormals, and the real-time audit; exit status = failed checks");
    rosin::host::ValidateOptions validateOptions;
    std::string hidReplay;
    validateCmd->add_option("--plugin", plugin, "the built plugin bundle (.vst3 or .lv2)")->required();
    validateCmd->add_option("--cycles", validateOptions.openCloseCycles, "open/close cycles")->check(CLI::Range(1, 1000));
    validateCmd->add_option("--walk-seconds", validateOptions.walkSeconds, "audio while parameters random-walk")->check(CLI::Range(0.1, 600.0));
    validateCmd->add_option("--hid-replay", hidReplay, "a hid-recorder capture played as a controller while the audit runs");

    auto* presetsCmd = app.add_subcommand("presets", "list the instrument presets the plugin carries (from inside its bundle)");
    presetsCmd->add_option("--plugin", plugin, "the built plugin bundle (.vst3 or .lv2)")->required();

    auto* params = app.add_subcommand("params", "list the plugin's parameters (ID, name, value)");
    params->add_option("--plugin", plugin, "the built plugin bundle (.vst3 or .lv2)")->required();

    auto* hidCmd = app.add_subcommand("hid", "list HID devices and whether Rosin can play them; --seconds S also prints "
                                             "the bow the first controller plays (no plugin needed)");
    double hidSeconds = 0.0;
    hidCmd->add_option("--seconds", hidSeconds, "watch the controller this long")->check(CLI::Range(0.0, 3600.0));
    bool udevRulesOnly = false, supportedOnly = false;
    hidCmd->add_flag("--udev-rules", udevRulesOnly, "print the udev rules file for the supported controllers (one line per product)");
    hidCmd->add_flag("--supported", supportedOnly, "list the controllers Rosin knows by vendor and product id");

    CLI11_PARSE(app, argc, argv);
    if (hidCmd->parsed()) {
        using namespace rosin::hid;
        if (udevRulesOnly) {
            std::fputs(udevRules().c_str(), stdout);
            return 0;
        }
        if (supportedOnly) {
            for (const auto& d : supportedDevices())
                std::printf("%04x:%04x  %-9s %-11s %s\n", d.vendor, d.product, d.bus == Bus::Bluetooth ? "Bluetooth" : "USB", kindName(d.kind), d.name);
            return 0;
        }
        // One scan through the same code the plugin runs, then the verdict per device.
        {
            HidInput scan(makeHidapiBackend(), makeLibusbWatcher());
            scan.hotplugRescanSeconds = 60.0;
            scan.start();
            std::this_thread::sleep_for(std::chrono::milliseconds(300));
            const auto devices = scan.devices();
            if (devices.empty()) std::printf("no HID devices (hidraw) found\n");
            for (const auto& d : devices)
                std::printf("%04x:%04x  %-9s %-40s %s%s%s\n", d.vendor, d.product, d.bus == Bus::Bluetooth ? "Bluetooth" : "USB", d.name.c_str(),
                            stateName(d.state), d.kind.empty() ? "" : (" (" + d.kind + ")").c_str(),
                            d.detail.empty() ? "" : ("\n           " + d.detail).c_str());
            std::printf("hot-plug: %s\n", scan.hotplug() ? "libusb tells arrivals and departures" : "not available, polling");
        }
        if (hidSeconds > 0.0) {
            HidInput input(makeHidapiBackend(), makeLibusbWatcher());
            input.start();
            const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(hidSeconds);
            Event e, last;
            while (std::chrono::steady_clock::now() < end) {
                bool got = false;
                while (input.queue().pop(e)) {
                    if (e.kind == Event::Kind::Bow) {
                        last = e;
                        got = true;
                    } else if (e.kind != Event::Kind::Released) {
                        std::printf("note %s %d\n", e.kind == Event::Kind::NoteOn ? "on " : "off", e.note);
                    }
                }
                if (got) // normalised: 0.5 is the instrument's nominal bow
                    std::printf("%-40s force %4.2f  speed %+5.2f  position %4.2f  string %d%s\n", input.status().c_str(), last.force,
                                last.speed, last.position, last.string, last.bowChange ? "  bow change" : "");
                std::this_thread::sleep_for(std::chrono::milliseconds(100));
            }
            std::printf("%s; %llu reports\n", input.status().c_str(), static_cast<unsigned long long>(input.reportsRead()));
        }
        return 0;
    }
    if (validateCmd->parsed()) {
        try {
            validateOptions.hidReplay = hidReplay;
            const int failed = rosin::host::validate(plugin, validateOptions, std::cout);
            std::printf("%s: %s\n", plugin.c_str(), failed == 0 ? "passed every check" : (std::to_string(failed) + " check(s) failed").c_str());
            return failed == 0 ? 0 : 4;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "rosin-host: %s\n", e.what());
            return 1;
        }
    }
    if (plugin.empty()) plugin = defaultBundle();
    try {
        PluginHost host(plugin);
        if (presetsCmd->parsed()) {
            // The instrument choices are the instrument presets compiled into the plugin.
            for (const auto& name : host.choices("instrument")) std::printf("%s\n", name.c_str());
            return 0;
        }
        if (bench->parsed()) {
            host.setParameter("instrument", benchPreset);
            std::vector<TimedMidi> notes;
            const int root = static_cast<int>(std::lround(69.0 + 12.0 * std::log2(freq / 440.0)));
            for (int v = 0; v < voices; ++v) notes.push_back({0.0, {0x90, static_cast<std::uint8_t>(std::clamp(root - 5 * v, 0, 127)), 100}});
            const BenchResult b = host.bench(benchSr, benchBlock, benchSeconds, reps, warmup, notes);
            const double ns = 1e9 * b.bestPassSeconds / static_cast<double>(b.samplesPerPass);
            const double rt = static_cast<double>(b.samplesPerPass) / benchSr / b.bestPassSeconds;
            std::printf("%s through %s, %d voice(s) of %s at %.0f Hz, block %d: best %.3f s, median %.3f s per %.1f s pass; "
                        "%.1f ns per sample per voice; %.0f voices would fit in real time on this core\n",
                        host.pluginName().c_str(), host.formatName().c_str(), voices, benchPreset.c_str(), benchSr, benchBlock,
                        b.bestPassSeconds, b.medianPassSeconds, static_cast<double>(b.samplesPerPass) / benchSr, ns / voices,
                        1e9 / benchSr / (ns / voices));
            std::printf("RESULT %s %.3f %.1f %.6g\n", benchName.c_str(), ns, rt, b.rms);
            return b.rms > 1e-6 ? 0 : 1;
        }
        if (params->parsed()) {
            for (const auto& p : host.parameters())
                std::printf("%-18s %-28s %s\n", p.id.c_str(), p.name.c_str(), p.text.c_str());
            return 0;
        }
        RenderRequest req;
        req.sampleRate = rate;
        req.blockSize = block;
        req.audit = audit;
        if (!midiFile.empty() && !eventsFile.empty()) throw std::runtime_error("give --midi or --events, not both");
        if (!midiFile.empty()) req.midi = readMidiFile(midiFile);
        if (!eventsFile.empty()) req.midi = readEventList(eventsFile);
        if (!automationFile.empty()) req.automation = readAutomation(automationFile);
        if (!stateIn.empty()) host.setState(readBytes(stateIn));
        if (!preset.empty()) {
            // As a player choosing the preset: the instrument, and the bow and rosin it suggests.
            const auto p = rosin::presets::loadInstrument(rosin::presets::Library::standard(), preset);
            host.setParameter("instrument", preset);
            if (host.parameter("instrument").text != preset)
                throw std::runtime_error("--preset " + preset + ": the plugin has no such instrument (it shows '" +
                                         host.parameter("instrument").text + "')");
            host.setParameter("bow_force", std::to_string(p.bowForce));
            host.setParameter("bow_speed", std::to_string(p.bowSpeed));
            host.setParameter("bow_position", std::to_string(p.bowPosition));
            host.setParameter("attack_accel", std::to_string(p.attackAccel));
            host.setParameter("rosin_tg", std::to_string(p.rosinTg));
        }
        for (const auto& s : sets) {
            const auto eq = s.find('=');
            if (eq == std::string::npos) throw std::runtime_error("--set " + s + ": expected ID=VALUE");
            host.setParameter(s.substr(0, eq), s.substr(eq + 1));
        }
        double last = 0.0;
        for (const auto& m : req.midi) last = std::max(last, m.seconds);
        for (const auto& a : req.automation) last = std::max(last, a.seconds);
        req.seconds = seconds > 0.0 ? seconds : last + tail;
        if (audit && !rosin::host::audit::selfTest()) throw std::runtime_error("the allocation counter is not live");
        const RenderResult r = host.render(req);
        writeWav(out, r.left, r.right, rate);
        if (!stateOut.empty()) {
            const auto state = host.getState();
            std::ofstream(stateOut, std::ios::binary).write(state.data(), static_cast<std::streamsize>(state.size()));
        }
        double peak = 0.0;
        for (std::size_t i = 0; i < r.left.size(); ++i) peak = std::max({peak, std::abs(double(r.left[i])), std::abs(double(r.right[i]))});
        nlohmann::json j{{"format", host.formatName()}, {"plugin", host.pluginName()}, {"rate", rate}, {"block", block},
                         {"seconds", req.seconds}, {"blocks", r.audit.blocks}, {"peak", peak}};
        if (audit)
            j["audit"] = {{"in_processBlock", auditJson(r.audit.plugin)},
                          {"in_host_call", auditJson(r.audit.call)},
                          {"plugin_reported_scope", r.audit.pluginScopeSeen}};
        if (!report.empty()) std::ofstream(report) << j.dump(2) << "\n";
        std::fprintf(stderr, "rosin-host: %s %s, %.2f s at %.0f Hz in blocks of %d -> %s (peak %.3f)\n", host.formatName().c_str(),
                     host.pluginName().c_str(), req.seconds, rate, block, out.c_str(), peak);
        if (audit)
            std::fprintf(stderr, "rosin-host: processBlock over %llu blocks: %s\n", static_cast<unsigned long long>(r.audit.blocks),
                         auditText(r.audit.plugin).c_str());
        return audit && r.audit.plugin.total() > 0 ? 3 : 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rosin-host: %s\n", e.what());
        return 1;
    }
}
