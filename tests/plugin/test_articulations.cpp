// The virtual player: every articulation is a bow (or finger) trajectory on the same string, and
// these tests listen to the rendered audio and watch the bow.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>

#include "AudioChecks.h"
#include "rosin/engine/Synth.h"
#include "rosin/lab/Classifier.h"

using namespace rosin;
using namespace rosin::engine;

namespace {
const presets::Library presetDir; // the factory set
using presets::loadInstrument;
constexpr int fs = 48000;

std::unique_ptr<Synth> make(const std::string& instrument, ParamValues p = defaultParams())
{
    auto s = std::make_unique<Synth>();
    s->prepare(fs, loadInstrument(presetDir, instrument), p);
    return s;
}

void midi(Synth& s, std::initializer_list<int> bytes)
{
    std::uint8_t b[3] = {0, 0, 0};
    int n = 0;
    for (int x : bytes) b[n++] = static_cast<std::uint8_t>(x);
    s.handleMidi(b, n);
}

/// Renders `seconds` in blocks of 48 samples, calling `watch` after each block; returns mono.
std::vector<float> play(Synth& s, double seconds, const std::function<void()>& watch = {})
{
    const int n = static_cast<int>(seconds * fs);
    std::vector<float> l(static_cast<std::size_t>(n)), r(static_cast<std::size_t>(n)), m(static_cast<std::size_t>(n));
    for (int i = 0; i < n; i += 48) {
        s.render(l.data() + i, r.data() + i, std::min(48, n - i));
        if (watch) watch();
    }
    for (int i = 0; i < n; ++i) m[static_cast<std::size_t>(i)] = l[static_cast<std::size_t>(i)] + r[static_cast<std::size_t>(i)];
    return m;
}

/// The lab's classifier (PHYSICS.md 6.5) on a voice's tapped bridge force: a Guettler ramp at
/// `accel` up to `speed`, on string `sp` bowed at `beta`.
lab::Classification classifyVoice(const std::vector<float>& bridge, const std::vector<std::uint8_t>& stick,
                                  const dsp::StringParams& sp, double beta, double accel, double speed)
{
    lab::ClassifierInput in;
    in.bridgeForce.assign(bridge.begin(), bridge.end());
    in.sampleRate = fs;
    in.f0 = sp.fundamental();
    in.beta = beta;
    in.z0 = sp.impedance();
    in.tension = sp.tension;
    in.length = sp.length;
    in.bowSpeed = [accel, speed](double t) { return std::min(speed, accel * t); };
    in.stick.assign(stick.begin(), stick.end());
    return lab::classify(in);
}

ParamValues with(std::initializer_list<std::pair<Param, float>> values)
{
    ParamValues p = defaultParams();
    for (auto [k, v] : values) p[static_cast<std::size_t>(k)] = v;
    return p;
}
} // namespace

TEST(Articulation, KeyswitchControllerAndChannelChooseIt)
{
    auto s = make("cello");
    midi(*s, {0x90, Synth::keyswitchBase + 2, 100}); // C0+2: spiccato
    EXPECT_FLOAT_EQ(s->parameter(static_cast<int>(Param::Articulation)), 2.0f);
    EXPECT_EQ(s->activeVoiceCount(), 0); // a keyswitch makes no sound
    midi(*s, {0xB0, 20, 127});           // CC20 top of the range: harmonic
    EXPECT_FLOAT_EQ(s->parameter(static_cast<int>(Param::Articulation)), 6.0f);
    midi(*s, {0xB0, 20, 30});            // 30/128 of seven: martele
    EXPECT_FLOAT_EQ(s->parameter(static_cast<int>(Param::Articulation)), 1.0f);
}

TEST(Articulation, PizzicatoDecaysWithoutASustainedTone)
{
    auto s = make("cello", with({{Param::Articulation, 5.0f}}));
    midi(*s, {0x90, 50, 100});
    double maxForce = 0.0;
    const auto out = play(*s, 1.5, [&] { maxForce = std::max(maxForce, s->voiceInfo(0).force); });
    EXPECT_EQ(maxForce, 0.0); // the bow never touched the string
    std::vector<double> windows;
    for (double t = 0.05; t < 1.45; t += 0.2) windows.push_back(test::rms(out, static_cast<std::size_t>(t * fs), static_cast<std::size_t>((t + 0.1) * fs)));
    EXPECT_GT(windows.front(), 1e-3);
    for (std::size_t i = 1; i < windows.size(); ++i) EXPECT_LT(windows[i], windows[i - 1]) << i;
    EXPECT_LT(windows.back(), 0.5 * windows.front());
    EXPECT_LT(std::abs(test::cents(test::pitchHz(out, fs, fs / 10, fs / 2), test::midiToHz(50))), 10.0);
}

TEST(Articulation, SpiccatoBouncesAtItsRate)
{
    auto s = make("violin", with({{Param::Articulation, 2.0f}, {Param::SpiccatoRate, 7.0f}}));
    midi(*s, {0x90, 67, 100});
    int bounces = 0;
    bool onString = false;
    int reversals = 0, lastDirection = 0;
    const auto out = play(*s, 2.0, [&] {
        const VoiceInfo v = s->voiceInfo(0);
        const bool on = v.force > 1e-3;
        if (on && !onString) ++bounces;
        onString = on;
        if (on && v.bowDirection != 0 && lastDirection != 0 && v.bowDirection != lastDirection) ++reversals;
        if (on && v.bowDirection != 0) lastDirection = v.bowDirection;
    });
    EXPECT_NEAR(bounces, 14, 1);   // 7 per second for 2 s: the bow leaves and comes back
    EXPECT_NEAR(reversals, 13, 2); // each bounce the other way
    // The sound is struck anew each bounce: in each 1/7 s the 5 ms envelope dips well below its peak.
    const std::size_t period = fs / 7, win = fs / 200;
    int separated = 0, periods = 0;
    for (std::size_t start = period; start + period <= out.size(); start += period, ++periods) {
        double lo = 1e9, hi = 0.0;
        for (std::size_t i = start; i + win <= start + period; i += win) {
            const double r = test::rms(out, i, i + win);
            lo = std::min(lo, r);
            hi = std::max(hi, r);
        }
        separated += lo < 0.6 * hi ? 1 : 0;
    }
    EXPECT_GE(separated, periods - 1) << separated << " of " << periods;
}

TEST(Articulation, TremoloReversesTheBowAtTheAskedRate)
{
    for (float rate : {6.0f, 12.0f}) {
        auto s = make("viola", with({{Param::Articulation, 3.0f}, {Param::TremoloRate, rate}}));
        midi(*s, {0x90, 62, 100});
        int reversals = 0, last = 0;
        const auto out = play(*s, 2.0, [&] {
            const int d = s->voiceInfo(0).bowDirection;
            if (d != 0 && last != 0 && d != last) ++reversals;
            if (d != 0) last = d;
        });
        EXPECT_NEAR(reversals, 2.0 * rate, 1.5) << rate;
        EXPECT_GT(test::rms(out, fs / 2, 2 * fs), 1e-2) << rate;
    }
}

TEST(Articulation, MarteleBitesThenStrokesThenStops)
{
    auto s = make("violin", with({{Param::Articulation, 1.0f}}));
    midi(*s, {0x90, 67, 100});
    std::vector<VoiceInfo> seen;
    const auto out = play(*s, 0.6, [&] { seen.push_back(s->voiceInfo(0)); });
    const double nominal = defaultParams()[static_cast<int>(Param::BowForce)];
    EXPECT_GT(seen[24].force, 2.0 * nominal);           // 25 ms: pressed hard, not moving
    EXPECT_LT(std::abs(seen[24].speed), 1e-3);
    double fastest = 0.0;
    for (const auto& v : seen) fastest = std::max(fastest, std::abs(v.speed));
    EXPECT_GT(fastest, 2.0 * defaultParams()[static_cast<int>(Param::BowSpeed)]);
    EXPECT_LT(std::abs(seen.back().speed), 1e-3);       // the bow has stopped on the string
    EXPECT_GT(test::rms(out, fs / 20, fs / 5), 4.0 * test::rms(out, fs / 2, 6 * fs / 10)); // accent, then quiet
}

TEST(Articulation, LongNotesChangeBowWhenTheBowRunsOut)
{
    auto s = make("cello", with({{Param::BowLength, 0.3f}, {Param::BowSpeed, 0.15f}}));
    midi(*s, {0x90, 50, 100});
    int changes = 0, last = 0;
    double maxPosition = 0.0;
    const auto out = play(*s, 5.0, [&] {
        const VoiceInfo v = s->voiceInfo(0);
        if (v.bowDirection != 0 && last != 0 && v.bowDirection != last) ++changes;
        if (v.bowDirection != 0) last = v.bowDirection;
        maxPosition = std::max(maxPosition, v.bowPosition);
    });
    EXPECT_GE(changes, 2); // 0.3 m at 0.15 m/s: a change every ~2 s
    EXPECT_LE(changes, 3);
    EXPECT_LE(maxPosition, 0.3);
    EXPECT_GT(test::rms(out, 4 * fs, 5 * fs), 0.3 * test::rms(out, fs, 2 * fs)); // it keeps sounding
    // Consecutive notes alternate: the next note starts up bow.
    midi(*s, {0x80, 50, 0});
    play(*s, 1.0);
    midi(*s, {0x90, 50, 100});
    int direction = 0;
    play(*s, 0.1, [&] {
        for (int i = 0; i < Synth::maxVoices; ++i) {
            const VoiceInfo v = s->voiceInfo(i);
            if (v.active && !v.released && v.bowDirection != 0) direction = v.bowDirection;
        }
    });
    EXPECT_NE(direction, 0); // the new note bows (which way depends on where the last one ended)
}

TEST(Articulation, ConsecutiveNotesAlternateDownAndUpBow)
{
    auto s = make("violin");
    int first = 0, second = 0;
    midi(*s, {0x90, 67, 100});
    play(*s, 0.3, [&] { first = s->voiceInfo(0).bowDirection ? s->voiceInfo(0).bowDirection : first; });
    midi(*s, {0x80, 67, 0});
    midi(*s, {0x90, 69, 100});
    play(*s, 0.3, [&] {
        for (int i = 0; i < Synth::maxVoices; ++i)
            if (s->voiceInfo(i).active && s->voiceInfo(i).note == 69 && s->voiceInfo(i).bowDirection) second = s->voiceInfo(i).bowDirection;
    });
    EXPECT_EQ(first, 1);
    EXPECT_EQ(second, -1);
}

TEST(Articulation, AutomaticVibratoModulatesTheFingerAtItsRateAndDepth)
{
    auto s = make("violin", with({{Param::VibratoAuto, 1.0f}, {Param::VibratoDepth, 30.0f}, {Param::VibratoRate, 5.0f},
                                  {Param::VibratoDelay, 0.2f}, {Param::Intonation, 0.0f}}));
    midi(*s, {0x90, 69, 100});
    std::vector<double> cents;
    play(*s, 2.5, [&] { cents.push_back(test::cents(s->voiceInfo(0).frequency, test::midiToHz(69))); });
    // Before the onset delay the finger is still; after it, +-30 cents at 5 Hz.
    EXPECT_LT(std::abs(cents[100]), 0.5); // 0.1 s
    double lo = 1e9, hi = -1e9;
    int crossings = 0;
    for (std::size_t i = 1000; i < cents.size(); ++i) { // from 1 s on (1000 blocks of 1 ms)
        lo = std::min(lo, cents[i]);
        hi = std::max(hi, cents[i]);
        if ((cents[i - 1] < 0.0) != (cents[i] < 0.0)) ++crossings;
    }
    EXPECT_NEAR(hi, 30.0, 2.0);
    EXPECT_NEAR(lo, -30.0, 2.0);
    EXPECT_NEAR(crossings / 2.0 / 1.5, 5.0, 0.5); // crossings per second / 2 = rate
}

TEST(Articulation, LegatoChangesPitchWithoutANewAttack)
{
    auto s = make("cello", with({{Param::Legato, 1.0f}, {Param::Portamento, 0.03f}}));
    midi(*s, {0x90, 50, 100});
    play(*s, 0.8);
    const double speedBefore = std::abs(s->voiceInfo(0).speed);
    double slowest = 1e9;
    midi(*s, {0x90, 53, 100});
    const auto out = play(*s, 0.8, [&] { slowest = std::min(slowest, std::abs(s->voiceInfo(0).speed)); });
    EXPECT_EQ(s->activeVoiceCount(), 1);
    EXPECT_GT(slowest, 0.9 * speedBefore); // the bow keeps moving: no new stroke, no new Guettler ramp
    EXPECT_LT(std::abs(test::cents(test::pitchHz(out, fs, fs / 4, 3 * fs / 4), test::midiToHz(53))), 10.0);
    // No attack transient: the level around the change stays within a factor of 2.
    const double before = test::rms(out, 0, fs / 50);
    for (std::size_t i = 0; i + 480 < static_cast<std::size_t>(fs / 5); i += 480) {
        const double r = test::rms(out, i, i + 480);
        EXPECT_LT(r, 2.0 * before + 1e-3) << i;
        EXPECT_GT(r, 0.5 * before) << i;
    }
}

TEST(Articulation, MuteTakesTheUpperBodyDown)
{
    auto open = make("violin"), muted = make("violin", with({{Param::Mute, 1.0f}}));
    midi(*open, {0x90, 67, 100});
    midi(*muted, {0x90, 67, 100});
    const auto a = play(*open, 1.0), b = play(*muted, 1.0);
    auto highs = [](const std::vector<float>& x) { // first difference: a crude high-pass
        double e = 0.0;
        for (std::size_t i = fs / 2 + 1; i < x.size(); ++i) e += std::pow(static_cast<double>(x[i]) - x[i - 1], 2.0);
        return e;
    };
    EXPECT_LT(highs(b) / test::rms(b, fs / 2, fs) / test::rms(b, fs / 2, fs),
              0.7 * highs(a) / test::rms(a, fs / 2, fs) / test::rms(a, fs / 2, fs));
}

// A keyboard player at default velocity gets a clean Helmholtz attack on every string of every
// instrument: the lab's classifier (PHYSICS.md 6.5) on the voice's own bridge force.
TEST(Articulation, DefaultVelocityReachesHelmholtzOnEveryString)
{
    for (const std::string name : {"violin", "viola", "cello", "double-bass"}) {
        const InstrumentPreset preset = loadInstrument(presetDir, name);
        for (int string = 0; string < preset.stringCount; ++string) {
            const auto& sp = preset.strings[static_cast<std::size_t>(string)];
            const int note = static_cast<int>(std::lround(69.0 + 12.0 * std::log2(sp.fundamental() / 440.0)));
            ParamValues p = defaultParams();
            p[static_cast<int>(Param::BowForce)] = static_cast<float>(preset.bowForce);
            p[static_cast<int>(Param::BowSpeed)] = static_cast<float>(preset.bowSpeed);
            p[static_cast<int>(Param::BowPosition)] = static_cast<float>(preset.bowPosition);
            p[static_cast<int>(Param::AttackAccel)] = static_cast<float>(preset.attackAccel);
            p[static_cast<int>(Param::RosinTg)] = static_cast<float>(preset.rosinTg);
            Synth s;
            s.prepare(fs, preset, p);
            std::vector<float> bridge(fs);
            std::vector<std::uint8_t> stick(fs);
            s.setVoiceTap(bridge.data(), stick.data(), fs);
            midi(s, {0x90, note, 100}); // a keyboard's default velocity
            play(s, 1.0);
            const lab::Classification c =
                classifyVoice(bridge, stick, sp, preset.bowPosition, preset.attackAccel * 100.0 / 127.0, preset.bowSpeed);
            EXPECT_TRUE(c.success) << name << " string " << string << ": " << c.labels;
            EXPECT_LE(c.transientPeriods, 20) << name << " string " << string;
        }
    }
}

TEST(Articulation, HarmonicsSoundAtTheHarmonicsPitch)
{
    // Natural: D5 is the D string's second harmonic (open string, a light finger at its middle).
    // Artificial: C7 is C5 stopped and touched a fourth above (the 4th harmonic).
    // The violin preset's bow, as a player loading "violin" gets it (a cello's 1.1 N on a violin
    // harmonic tips it into the mode twice as high, as too heavy a bow does on a real string).
    const InstrumentPreset violin = loadInstrument(presetDir, "violin");
    for (const int note : {74, 79, 86, 88, 95, 96}) { // natural n=2 (D, E), n=3 (E); artificial on G, D, A
        auto s = make("violin", with({{Param::Articulation, 6.0f}, {Param::BowForce, static_cast<float>(violin.bowForce)},
                                      {Param::BowSpeed, static_cast<float>(violin.bowSpeed)},
                                      {Param::BowPosition, static_cast<float>(violin.bowPosition)},
                                      {Param::AttackAccel, static_cast<float>(violin.attackAccel)}}));
        midi(*s, {0x90, note, 100});
        const auto out = play(*s, 1.5);
        const double target = test::midiToHz(note);
        const double f = test::pitchHz(out, fs, fs / 2, 3 * fs / 2, 0.6 * target, 3.0 * target); // an octave above is searched too
        EXPECT_LT(std::abs(test::cents(f, test::midiToHz(note))), 10.0) << note << ": " << f << " Hz";
        EXPECT_GT(test::rms(out, fs / 2, 3 * fs / 2), 1e-3) << note;
    }
    auto s = make("violin");
    int string = -1;
    EXPECT_EQ(s->chooseHarmonic(test::midiToHz(74), string), 2);
    EXPECT_EQ(string, 1); // the D string (G=0, D=1, A=2, E=3)
    EXPECT_EQ(s->chooseHarmonic(test::midiToHz(96), string), 4);
}

// On purpose, past Schelleng's limits: pressing hard with a slow bow (CC2 at the top, CC11 near
// the bottom) does not give Helmholtz motion: the scratch a player can reach for.
TEST(Articulation, PressingHardWithASlowBowScratches)
{
    const InstrumentPreset preset = loadInstrument(presetDir, "cello");
    const auto& sp = preset.strings[2];
    auto run = [&](int pressure, int expression) {
        Synth s;
        s.prepare(fs, preset, defaultParams());
        std::vector<float> bridge(fs);
        std::vector<std::uint8_t> stick(fs);
        s.setVoiceTap(bridge.data(), stick.data(), fs);
        midi(s, {0xB0, 2, pressure});
        midi(s, {0xB0, 11, expression});
        midi(s, {0x90, 50, 100});
        play(s, 1.0);
        const ParamValues d = defaultParams();
        return classifyVoice(bridge, stick, sp, d[static_cast<int>(Param::BowPosition)],
                             d[static_cast<int>(Param::AttackAccel)] * 100.0 / 127.0,
                             d[static_cast<int>(Param::BowSpeed)] * 2.0 * expression / 127.0);
    };
    EXPECT_TRUE(run(64, 64).success);   // the nominal bow speaks
    EXPECT_FALSE(run(127, 8).success);  // 2x the force at 1/8 of the speed: no Helmholtz
}
