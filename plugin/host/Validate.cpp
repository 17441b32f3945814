#include "Validate.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>
#include <regex>
#include <thread>
#include <vector>

#include "AuditCounter.h"
#include "PluginHost.h"

namespace rosin::host {
namespace {
using Midi = std::vector<std::pair<int, std::vector<std::uint8_t>>>;

struct Signal {
    double sumSquares = 0.0, peak = 0.0;
    long long samples = 0, nonFinite = 0, subnormal = 0;
    void add(const float* x, int n)
    {
        for (int i = 0; i < n; ++i) {
            if (!std::isfinite(x[i])) { ++nonFinite; continue; }
            if (std::fpclassify(x[i]) == FP_SUBNORMAL) ++subnormal;
            sumSquares += static_cast<double>(x[i]) * x[i];
            peak = std::max(peak, static_cast<double>(std::abs(x[i])));
            ++samples;
        }
    }
    double rms() const { return samples ? std::sqrt(sumSquares / static_cast<double>(samples)) : 0.0; }
};

/// The output limits a host can rely on: finite and within +-4 (the engine's own clamp, +12 dB).
constexpr double outputBound = 4.0;

struct Checker {
    std::ostream& log;
    int failed = 0;
    void report(bool ok, const std::string& name, const std::string& detail)
    {
        log << (ok ? "PASS  " : "FAIL  ") << name << ": " << detail << "\n";
        log.flush();
        failed += ok ? 0 : 1;
    }
};

std::string tally(const audit::Tally& t)
{
    return std::to_string(t.allocations) + " allocations, " + std::to_string(t.frees) + " frees, " + std::to_string(t.locks) + " locks, " +
           std::to_string(t.waits) + " condition/semaphore calls, " + std::to_string(t.blocking) + " blocking calls";
}

std::vector<std::uint8_t> bytes(std::initializer_list<int> b)
{
    std::vector<std::uint8_t> v;
    for (int x : b) v.push_back(static_cast<std::uint8_t>(x));
    return v;
}

/// Plays `seconds` in blocks of `block`; `events(blockIndex, n)` gives each block's MIDI.
void play(PluginHost& h, double rate, int block, double seconds, bool audited, Signal& out, const std::function<Midi(long long, int)>& events)
{
    std::vector<float> l(static_cast<std::size_t>(block)), r(static_cast<std::size_t>(block));
    const auto total = static_cast<long long>(seconds * rate);
    long long index = 0;
    for (long long done = 0; done < total; done += block, ++index) {
        const int n = static_cast<int>(std::min<long long>(block, total - done));
        h.processStream(n, events ? events(index, n) : Midi{}, l.data(), r.data(), audited);
        out.add(l.data(), n);
        out.add(r.data(), n);
    }
}

std::string number(double x)
{
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", x);
    return b;
}
} // namespace

int validate(const std::filesystem::path& plugin, const ValidateOptions& o, std::ostream& log)
{
    Checker check{log};
    if (!audit::selfTest()) {
        check.report(false, "audit counter", "the counter does not see calls made in front of it");
        return check.failed;
    }
    if (!o.hidReplay.empty()) ::setenv("ROSIN_HID_REPLAY", o.hidReplay.c_str(), 1); // read when the plugin is created

    // 1. Open and close many times, each time preparing and playing a block.
    {
        bool ok = true;
        std::string detail;
        for (int k = 0; k < o.openCloseCycles && ok; ++k) {
            try {
                PluginHost h(plugin);
                h.startStream(48000.0, 256, true, 2);
                Signal s;
                play(h, 48000.0, 256, 0.02, false, s, [](long long i, int) { return i == 0 ? Midi{{0, bytes({0x90, 50, 100})}} : Midi{}; });
                h.stopStream();
                ok = s.nonFinite == 0;
            } catch (const std::exception& e) {
                ok = false;
                detail = e.what();
            }
        }
        check.report(ok, "open/close", std::to_string(o.openCloseCycles) + " loads, each prepared and played" + (detail.empty() ? "" : ": " + detail));
    }

    // Checks 2 and 3 play one session on one instance.
    {
        PluginHost h(plugin);
        // A session with two learned controllers (what a player's MIDI learn saved) and the HID input on.
        try {
            h.setState(editRosinState(h.getState(), [](const std::string& xml) {
                return std::regex_replace(xml, std::regex("<Mappings/>|<Mappings>.*?</Mappings>"),
                                          "<Mappings><Map cc=\"21\" param=\"bow_force\" min=\"0.05\" max=\"3.0\" invert=\"0\"/>"
                                          "<Map cc=\"22\" param=\"bow_position\" min=\"0.03\" max=\"0.25\" invert=\"1\"/></Mappings>");
            }));
            check.report(true, "session with learned controllers", "state edited and loaded");
        } catch (const std::exception& e) {
            check.report(false, "session with learned controllers", e.what());
        }
        if (!o.hidReplay.empty()) h.setParameter("hid_input", "@1");

        // 2. Real time, audited: sample rates and block sizes change between blocks (the host
        //    restarts the stream, as DAWs do), with notes, MPE configuration, learned controllers,
        //    keyswitches, an instrument change and the HID input running.
        {
            const double rates[] = {22050.0, 44100.0, 48000.0, 96000.0, 192000.0};
            const int blocks[] = {1, 17, 256, 1024, 4096};
            audit::reset();
            Signal s;
            int runs = 0, silentRuns = 0;
            std::string firstSilent;
            for (double rate : rates)
                for (int block : blocks) {
                    h.startStream(rate, block, true, 2);
                    Signal run;
                    const int note = 40 + (runs * 5) % 36;
                    play(h, rate, block, block >= 1024 ? 0.4 : 0.15, true, run, [&](long long i, int n) {
                        Midi m;
                        if (i == 0) {
                            // MPE configuration (lower zone, 7 members) and a member's note; the
                            // checked note plays on channel 11, outside the zone the HID bow drives.
                            for (const auto& b : {bytes({0xB0, 101, 0}), bytes({0xB0, 100, 6}), bytes({0xB0, 6, 7}), bytes({0x91, note + 2, 100}),
                                                  bytes({0x9A, note, 100})})
                                m.push_back({0, b});
                        }
                        if (i == 1) m.push_back({n / 2, bytes({0xBA, 21, 40 + (runs * 13) % 88})}); // learned: bow force
                        if (i == 2) m.push_back({0, bytes({0xB0, 22, 64})});                    // learned: bow position
                        if (i == 3) m.push_back({0, bytes({0x90, 12 + runs % 6, 1})});           // keyswitch: articulation
                        return m;
                    });
                    if (runs % 6 == 5) h.setParameter("vibrato_depth", "@0.7"); // a parameter moves between runs
                    if (runs == 12) h.setParameter("instrument", "violin"); // a live instrument change
                    h.stopStream();
                    s.nonFinite += run.nonFinite;
                    s.peak = std::max(s.peak, run.peak);
                    if (run.rms() < 1e-4) {
                        ++silentRuns;
                        firstSilent += (firstSilent.empty() ? "" : ", ") + number(rate) + " Hz / " + std::to_string(block) + " (note " + std::to_string(note) + ")";
                    }
                    ++runs;
                }
            const audit::Counts c = audit::read();
            check.report(c.scopeSeen && c.plugin.total() == 0, "real-time audit",
                         std::to_string(runs) + " rate/block changes: in processBlock " + tally(c.plugin) + (c.scopeSeen ? "" : " (the plugin never reported its scope)"));
            check.report(s.nonFinite == 0 && s.peak <= outputBound && silentRuns == 0, "rates 22.05-192 kHz, blocks 1-4096",
                         "non-finite " + std::to_string(s.nonFinite) + ", peak " + number(s.peak) + ", silent runs " + std::to_string(silentRuns) +
                             (firstSilent.empty() ? "" : " (" + firstSilent + ")"));
        }

        // 3. Every parameter random-walked from a second thread while audio runs (real time, audited).
        {
            h.startStream(48000.0, 128, true, 2);
            std::atomic<bool> done{false};
            std::atomic<long> moves{0};
            const int count = h.parameterCount();
            // The host's bypass stays out of the walk (check 5 plays it on its own): at 0.5 +- a
            // step it bypassed Rosin for about half of a VST3 walk and, as LV2's first parameter,
            // for the whole LV2 walk, which then heard nothing of what the parameters did.
            const int bypass = h.bypassParameterIndex();
            // The HID input stays off too: on, it hands the bow (force, speed, contact) to the
            // replayed pen, so the walked bow parameters do nothing and the walk played near
            // silence (held on: peak 3e-4 over 0.5 s, 2e-3 over 2 s). Walked, it was on from about
            // sweep 2 to 58, so whether the walk was heard depended on how fast this thread ran: a
            // loaded CI machine's whole LV2 walk (61 sweeps) failed, an idle one's (70-140) passed.
            // Switching the input while audio runs is the processor tests' job (FakePenPlaysAVoice...,
            // StatesMapsLearnAndEnginesChangeWhileAudioRuns, the latter under ThreadSanitizer).
            const int hidInput = h.parameterIndex("hid_input");
            if (hidInput >= 0) h.setParameterNormalised(hidInput, 0.0f);
            std::thread automation([&] {
                std::mt19937 rng(o.seed);
                std::uniform_real_distribution<float> step(-0.08f, 0.08f);
                std::vector<float> value(static_cast<std::size_t>(count), 0.5f);
                while (!done.load()) {
                    for (int p = 0; p < count; ++p) {
                        if (p == bypass || p == hidInput) continue;
                        float& v = value[static_cast<std::size_t>(p)];
                        v = std::clamp(v + step(rng), 0.0f, 1.0f);
                        h.setParameterNormalised(p, v);
                        ++moves;
                    }
                    std::this_thread::sleep_for(std::chrono::milliseconds(1));
                }
            });
            audit::reset();
            Signal s;
            play(h, 48000.0, 128, o.walkSeconds, true, s, [](long long i, int) {
                Midi m;
                if (i % 60 == 0) m.push_back({0, bytes({0x90, 45 + static_cast<int>(i / 60) % 24, 90})});
                if (i % 60 == 45) m.push_back({3, bytes({0x80, 45 + static_cast<int>(i / 60) % 24, 0})});
                return m;
            });
            done = true;
            automation.join();
            // Moves made after the last block wait in JUCE's hosting layer and reach the plugin with
            // the next block: deliver them now, so that the output checked below includes them.
            play(h, 48000.0, 128, 0.01, false, s, nullptr);
            h.stopStream();
            const audit::Counts c = audit::read();
            // The walk must be heard: a peak this low means the notes never sounded (bypassed, muted).
            check.report(s.nonFinite == 0 && s.peak <= outputBound && s.peak > 1e-3 && c.plugin.total() == 0, "parameters random-walked from another thread",
                         std::to_string(moves.load()) + " moves over " + number(o.walkSeconds) + " s: non-finite " + std::to_string(s.nonFinite) +
                             ", peak " + number(s.peak) + "; in processBlock " + tally(c.plugin));
        }
    }

    // The later checks take a fresh instance. A VST3 host shows every MIDI controller of every
    // channel as a parameter, so check 3's walk also played random controllers, RPNs and pitch
    // bends on all 16 channels; what they leave (MPE zones, controller values, articulations)
    // belongs to the player, not the session, and outlives the state restore. Under load it left
    // check 4's note on channel 11 silent (twice in 16 runs, once in CI), or a third quieter,
    // depending on where the walk stopped; with the controllers left out of the walk, or on a
    // fresh instance, every run plays the same.
    PluginHost h(plugin);

    // 4. State saved and restored in the middle of a note: the note plays on, the state round-trips.
    //    The note plays on channel 11, away from channel 1, which a HID pen's bow drives when
    //    the HID input is on (its stop lifts the bow and ends channel 1's notes a few
    //    milliseconds later: on one instance with check 2 that once silenced a note here).
    {
        h.startStream(48000.0, 256, true, 2);
        Signal before, after;
        play(h, 48000.0, 256, 0.4, false, before, [](long long i, int) { return i == 0 ? Midi{{0, bytes({0x9A, 50, 100})}} : Midi{}; });
        const auto state = h.getState();
        h.setState(state);
        play(h, 48000.0, 256, 0.2, false, after, nullptr);
        Signal tail;
        play(h, 48000.0, 256, 0.1, false, tail, nullptr);
        const bool same = h.getState() == state;
        h.stopStream();
        check.report(tail.rms() > 1e-3 && after.nonFinite == 0 && same, "state saved and restored mid-note",
                     "rms after the restore " + number(tail.rms()) + (same ? ", the state reads back the same" : ", the state changed on the way"));
    }

    // 5. The host's bypass in the middle of a note: Rosin fades out, keeps following the keys
    //    while bypassed (a note released then does not sound on when the bypass ends; with
    //    JUCE's default bypass it did, for ever) and plays the next note after.
    if (const int bypass = h.bypassParameterIndex(); bypass < 0) {
        check.report(false, "host bypass mid-note", "the host shows no bypass parameter");
    } else {
        h.startStream(48000.0, 256, true, 2);
        Signal before, fade, bypassed, after, tail, next;
        play(h, 48000.0, 256, 0.5, false, before, [](long long i, int) { return i == 0 ? Midi{{0, bytes({0x9B, 45, 100})}} : Midi{}; });
        h.setParameterNormalised(bypass, 1.0f);
        play(h, 48000.0, 256, 0.03, false, fade, nullptr); // the block the change lands in, then the 10 ms fade
        play(h, 48000.0, 256, 0.3, false, bypassed, [](long long i, int) { return i == 10 ? Midi{{0, bytes({0x8B, 45, 0})}} : Midi{}; });
        h.setParameterNormalised(bypass, 0.0f);
        play(h, 48000.0, 256, 1.5, false, after, nullptr); // the released string rings down
        play(h, 48000.0, 256, 0.5, false, tail, nullptr);
        play(h, 48000.0, 256, 0.3, false, next, [](long long i, int) { return i == 0 ? Midi{{0, bytes({0x9B, 52, 100})}} : Midi{}; });
        h.stopStream();
        const long long nonFinite = before.nonFinite + fade.nonFinite + bypassed.nonFinite + after.nonFinite + tail.nonFinite + next.nonFinite;
        check.report(before.rms() > 1e-2 && bypassed.peak == 0.0 && tail.rms() < 1e-3 && next.rms() > 1e-2 && nonFinite == 0,
                     "host bypass mid-note",
                     "rms before " + number(before.rms()) + ", peak while bypassed " + number(bypassed.peak) +
                         ", rms of a note released while bypassed, 1.5 s after the bypass ends " + number(tail.rms()) +
                         ", rms of the next note " + number(next.rms()));
    }

    // 6. Bus layouts: mono and stereo outputs.
    for (int channels : {1, 2}) {
        const std::string name = channels == 1 ? "mono output" : "stereo output";
        try {
            h.startStream(48000.0, 512, true, channels);
            Signal s;
            play(h, 48000.0, 512, 0.5, false, s, [](long long i, int) { return i == 0 ? Midi{{0, bytes({0x90, 57, 100})}} : Midi{}; });
            h.stopStream();
            check.report(s.rms() > 1e-3 && s.nonFinite == 0, name, "rms " + number(s.rms()));
        } catch (const std::exception& e) {
            // LV2 ports are fixed by the bundle's description (two outputs): a mono host connects
            // one of them, so the left port alone must carry the instrument.
            if (channels == 1 && h.formatName() == "LV2") {
                h.startStream(48000.0, 512, true, 2);
                std::vector<float> l(512), r(512);
                Signal left;
                for (int b = 0; b < 47; ++b) {
                    h.processStream(512, b == 0 ? Midi{{0, bytes({0x90, 57, 100})}} : Midi{}, l.data(), r.data(), false);
                    left.add(l.data(), 512);
                }
                h.stopStream();
                check.report(left.rms() > 1e-3 && left.nonFinite == 0, name, "LV2 has two fixed output ports; the left one alone: rms " + number(left.rms()));
            } else {
                check.report(false, name, e.what());
            }
        }
    }

    // 7. Offline: an instrument change lands on the block it is asked for, and output stays finite.
    {
        h.startStream(48000.0, 512, false, 2);
        Signal s;
        play(h, 48000.0, 512, 0.3, false, s, [](long long i, int) { return i == 0 ? Midi{{0, bytes({0x90, 50, 100})}} : Midi{}; });
        h.setParameter("instrument", "double-bass");
        play(h, 48000.0, 512, 0.3, false, s, [](long long i, int) { return i == 0 ? Midi{{0, bytes({0x90, 40, 100})}} : Midi{}; });
        h.stopStream();
        const bool landed = h.parameter("instrument").text == "double-bass";
        check.report(s.nonFinite == 0 && s.rms() > 1e-3 && landed, "offline rendering", "rms " + number(s.rms()) + (landed ? "" : ", the instrument did not change"));
    }

    // 8. After the notes end, silence in gives silence out, with no denormals.
    {
        h.startStream(44100.0, 512, true, 2);
        Signal notes, quiet;
        play(h, 44100.0, 512, 0.5, false, notes, [](long long i, int) {
            Midi m;
            if (i == 0) m = {{0, bytes({0x90, 50, 100})}, {0, bytes({0x90, 57, 100})}};
            if (i == 20) m = {{0, bytes({0x80, 50, 0})}, {0, bytes({0x80, 57, 0})}};
            return m;
        });
        play(h, 44100.0, 512, 4.0, false, quiet, nullptr); // the strings and the body ring down
        Signal last;
        play(h, 44100.0, 512, 1.0, false, last, nullptr);
        h.stopStream();
        check.report(last.subnormal == 0 && quiet.subnormal == 0 && last.peak < 1e-5, "silence, no denormals",
                     "peak in the last second " + number(last.peak) + ", subnormal samples " + std::to_string(quiet.subnormal + last.subnormal));
    }
    return check.failed;
}

} // namespace rosin::host
