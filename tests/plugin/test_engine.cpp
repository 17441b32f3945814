// The instrument engine without JUCE: presets, string choice, MIDI 1.0 and MPE in physical
// units, pitch, release, determinism, and survival of absurd input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <atomic>
#include <chrono>
#include <thread>

#include "AudioChecks.h"
#include "rosin/engine/Synth.h"

using namespace rosin;
using namespace rosin::engine;
namespace fs = std::filesystem;

namespace {
const presets::Library presetDir; // the factory set compiled into the library
using presets::loadExciter;
using presets::loadInstrument;

struct Event {
    int frame;
    std::vector<std::uint8_t> bytes;
};

std::unique_ptr<Synth> makeSynth(const std::string& instrument = "cello", double fs = 48000.0,
                                 ParamValues params = defaultParams(), ControllerMap* map = nullptr)
{
    auto s = std::make_unique<Synth>();
    s->prepare(fs, loadInstrument(presetDir, instrument), params, map);
    return s;
}

/// Render `samples` frames with events at their frames, in blocks of `block`.
std::pair<std::vector<float>, std::vector<float>> render(Synth& s, int samples, const std::vector<Event>& events,
                                                         int block = 512)
{
    std::vector<float> l(static_cast<std::size_t>(samples)), r(static_cast<std::size_t>(samples));
    std::size_t next = 0;
    for (int start = 0; start < samples; start += block) {
        const int end = std::min(samples, start + block);
        int pos = start;
        while (next < events.size() && events[next].frame < end) {
            const int at = std::max(pos, events[next].frame);
            s.render(l.data() + pos, r.data() + pos, at - pos);
            pos = at;
            s.handleMidi(events[next].bytes.data(), static_cast<int>(events[next].bytes.size()));
            ++next;
        }
        s.render(l.data() + pos, r.data() + pos, end - pos);
    }
    return {l, r};
}

std::vector<float> mono(const std::pair<std::vector<float>, std::vector<float>>& lr)
{
    std::vector<float> m(lr.first.size());
    for (std::size_t i = 0; i < m.size(); ++i) m[i] = lr.first[i] + lr.second[i];
    return m;
}

Event on(int frame, int note, int vel = 100, int ch = 0) { return {frame, {std::uint8_t(0x90 | ch), std::uint8_t(note), std::uint8_t(vel)}}; }
Event off(int frame, int note, int ch = 0) { return {frame, {std::uint8_t(0x80 | ch), std::uint8_t(note), 0}}; }
Event cc(int frame, int number, int value, int ch = 0) { return {frame, {std::uint8_t(0xB0 | ch), std::uint8_t(number), std::uint8_t(value)}}; }
Event bend(int frame, int value14, int ch = 0) { return {frame, {std::uint8_t(0xE0 | ch), std::uint8_t(value14 & 0x7F), std::uint8_t(value14 >> 7)}}; }
Event pressure(int frame, int value, int ch) { return {frame, {std::uint8_t(0xD0 | ch), std::uint8_t(value)}}; }
} // namespace

TEST(EnginePresets, EveryInstrumentLoadsWithItsFourStringsInPitchOrder)
{
    for (const std::string name : {"violin", "viola", "cello", "double-bass"}) {
        const InstrumentPreset p = loadInstrument(presetDir, name);
        ASSERT_EQ(p.stringCount, 4) << name;
        for (int s = 1; s < 4; ++s) EXPECT_GT(p.strings[s].fundamental(), p.strings[s - 1].fundamental()) << name;
        EXPECT_GE(p.body.count, 8) << name;
        EXPECT_TRUE(p.strings[0].validate().empty()) << name;
    }
    EXPECT_NEAR(loadInstrument(presetDir, "double-bass").bowPosition, 0.13, 1e-9);
    EXPECT_EQ(presetDir.list("instruments").size(), 4u);
    EXPECT_EQ(loadControllerMap(presetDir, "pizzicato").articulation, 5);
    EXPECT_EQ(loadControllerMap(presetDir, "articulations-by-channel").articulationChannels, 1);
    EXPECT_EQ(loadExciter(presetDir, "enhanced-rod").contact, dsp::ContactLaw::PowerLaw);
    const MappingPreset keyboard = loadControllerMap(presetDir, "keyboard");
    ASSERT_EQ(keyboard.entries.size(), 4u);
    EXPECT_EQ(keyboard.entries[0].param, static_cast<int>(Param::BowForce));
}

TEST(EnginePresets, BadFilesNameTheFileAndTheField)
{
    const fs::path dir = fs::temp_directory_path() / "rosin-engine-presets";
    fs::create_directories(dir);
    auto expectError = [&](const std::string& text, const std::string& fieldWords, const std::string& kind) {
        const fs::path f = dir / "bad.json";
        std::ofstream(f) << text;
        try {
            if (kind == "instrument") loadInstrument(presetDir, f.string());
            else if (kind == "mapping") loadControllerMap(presetDir, f.string());
            else loadExciter(presetDir, f.string());
            ADD_FAILURE() << "no error for " << text;
        } catch (const std::runtime_error& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(f.string()), std::string::npos) << msg;
            EXPECT_NE(msg.find(fieldWords), std::string::npos) << msg;
        }
    };
    expectError("{", "not valid JSON", "instrument");
    expectError(R"({"format":"rosin-instrument/1","name":"x","strings":"strings/cello.json","body":{"modes":[{"f_hz":100,"q":-3,"gain":1}]}})",
                "body.modes[0]: field 'q'", "instrument");
    expectError(R"({"format":"rosin-instrument/1","name":"x","strings":"strings/none.json","body":{"modes":[]}})",
                "field 'strings'", "instrument");
    expectError(R"({"format":"rosin-mapping/1","name":"m","mappings":[{"cc":7,"param":"bow_forse"}]})",
                "mappings[0]: field 'param'", "mapping");
    expectError(R"({"format":"rosin-exciter/1","name":"e","friction_model":"magic"})", "field 'friction_model'", "exciter");
    expectError(R"({"format":"rosin-mapping/1","name":"m","articulation":"glissando","mappings":[]})", "field 'articulation'", "mapping");
    EXPECT_THROW(loadInstrument(presetDir, "theremin"), std::runtime_error);
}

TEST(EngineStrings, NotesGoWhereACellistWouldPlayThem)
{
    auto s = makeSynth("cello");
    // Lowest position: the highest open string at or below the note.
    EXPECT_EQ(s->chooseString(s->noteFrequency(36), -1, 0), 0); // C2, open C
    EXPECT_EQ(s->chooseString(s->noteFrequency(47), -1, 0), 1); // B2 on G
    EXPECT_EQ(s->chooseString(s->noteFrequency(50), -1, 0), 2); // D3, open D
    EXPECT_EQ(s->chooseString(s->noteFrequency(64), -1, 0), 3); // E4 on A
    EXPECT_EQ(s->chooseString(s->noteFrequency(24), -1, 0), 0); // below the cello: C string tuned down
    // A chord: with D taken, F3 goes to the G string (a free string that reaches it).
    EXPECT_EQ(s->chooseString(s->noteFrequency(53), -1, 1u << 2), 1);
    s->setParameter(static_cast<int>(Param::StringPolicy), 1.0f); // stay on string
    EXPECT_EQ(s->chooseString(s->noteFrequency(57), 1, 0), 1);    // A3 stays on G (14 semitones up)
    EXPECT_EQ(s->chooseString(s->noteFrequency(80), 1, 0), 3);    // G#5 is beyond G's reach
    s->setParameter(static_cast<int>(Param::StringPolicy), 2.0f); // fixed string 2 (G)
    s->setParameter(static_cast<int>(Param::FixedString), 2.0f);
    EXPECT_EQ(s->chooseString(s->noteFrequency(55), -1, 0), 1);
}

TEST(EnginePitch, NotesSoundWithinFiveCentsAfterTheAttack)
{
    for (const auto& [instrument, note] : std::vector<std::pair<std::string, int>>{
             {"cello", 50}, {"cello", 53}, {"cello", 45}, {"violin", 67}, {"violin", 76}, {"viola", 62}, {"double-bass", 38}}) {
        auto s = makeSynth(instrument);
        const int fs = 48000;
        const auto out = mono(render(*s, fs, {on(0, note)}));
        const double f = test::pitchHz(out, fs, fs / 2, fs, 25.0, 2000.0);
        EXPECT_LT(std::abs(test::cents(f, test::midiToHz(note))), 5.0) << instrument << " note " << note << ": " << f << " Hz";
        EXPECT_GT(test::rms(out, fs / 2, fs), 1e-3) << instrument;
    }
}

// The physics the intonation corrects: with the finger fixed, a bowed string plays flatter as
// the bow force rises (McIntyre & Woodhouse; Euphonics ch. 9), more so with the thermal model.
TEST(EnginePitch, WithoutIntonationTheStringFlattensAsTheForceRises)
{
    double previous = 1e9;
    for (float force : {0.1f, 0.3f, 0.6f}) {
        ParamValues p = defaultParams();
        p[static_cast<int>(Param::Intonation)] = 0.0f;
        p[static_cast<int>(Param::BowForce)] = force;
        auto s = makeSynth("violin", 48000.0, p);
        const auto out = mono(render(*s, 48000, {on(0, 67)}));
        const double c = test::cents(test::pitchHz(out, 48000, 24000, 48000), test::midiToHz(67));
        EXPECT_LT(c, previous - 1.0) << force;
        EXPECT_LT(c, 1.0) << force;
        previous = c;
    }
    EXPECT_LT(previous, -8.0);
}

TEST(EngineRelease, SilenceAfterTheBowLiftsAndTheStringIsDamped)
{
    auto s = makeSynth("cello");
    const int fs = 48000;
    const auto out = mono(render(*s, 3 * fs, {on(0, 50), off(fs / 2, 50)}));
    EXPECT_GT(test::rms(out, fs / 4, fs / 2), 1e-2);
    EXPECT_EQ(s->activeVoiceCount(), 0);
    EXPECT_LT(test::peakAbs(out, 2 * fs, 3 * fs), 1e-6); // -120 dB: only the body's last decay
}

TEST(EngineDeterminism, BlockSizeDoesNotChangeOneBit)
{
    const std::vector<Event> events{on(0, 50, 90), cc(3000, 74, 90), bend(4100, 9000), on(7001, 57, 60),
                                    pressure(9000, 100, 0), off(20000, 50), off(26000, 57)};
    auto reference = makeSynth("cello");
    const auto ref = render(*reference, 30000, events, 30000);
    for (int block : {1, 7, 64, 512, 4096}) {
        auto s = makeSynth("cello");
        const auto got = render(*s, 30000, events, block);
        ASSERT_EQ(got.first, ref.first) << "block " << block;
        ASSERT_EQ(got.second, ref.second) << "block " << block;
    }
}

// The instrument on the model's fast path: each voice runs its string a control interval at a
// time through BowedString::processBlock. The reference runs it one sample at a time.
TEST(EngineFastPath, BlockPathEqualsTheSampleBySamplePath)
{
    const std::vector<Event> events{on(0, 50, 90), cc(3000, 74, 90), bend(4100, 9000), on(7001, 57, 60), cc(8000, 1, 100),
                                    pressure(9000, 100, 0), on(12000, 69, 110), off(20000, 50), off(26000, 57), off(27000, 69)};
    for (const float model : {1.0f, 0.0f, 2.0f}) { // thermal (the fast loop), friction curve, enhanced
        ParamValues p = defaultParams();
        p[static_cast<int>(Param::FrictionModel)] = model;
        auto fast = makeSynth("violin", 48000.0, p), reference = makeSynth("violin", 48000.0, p);
        reference->setPerSample(true);
        const auto a = render(*fast, 30000, events, 256), b = render(*reference, 30000, events, 256);
        ASSERT_EQ(a.first.size(), b.first.size());
        double worst = 0.0, peak = 0.0;
        for (std::size_t i = 0; i < a.first.size(); ++i) {
            worst = std::max(worst, static_cast<double>(std::abs(a.first[i] - b.first[i])));
            peak = std::max(peak, static_cast<double>(std::abs(b.first[i])));
        }
        EXPECT_GT(peak, 1e-3) << "model " << model;
        EXPECT_LE(worst, 1e-6 * peak) << "model " << model; // float rounding at most (the loops run the same operations)
    }
}

TEST(EngineVoices, AStolenNoteFadesOutInsteadOfClicking)
{
    auto s = makeSynth("cello");
    std::vector<Event> notes;
    for (int k = 0; k < Synth::maxVoices; ++k) notes.push_back(on(k * 100, 36 + 2 * k, 100));
    const auto before = mono(render(*s, 24000, notes));
    ASSERT_EQ(s->activeVoiceCount(), Synth::maxVoices);
    const int oldestNote = 36;
    // The 17th note takes the oldest note's place; that one fades in its own slot (a spare).
    auto after = mono(render(*s, 48, {on(0, 80, 100)}));
    EXPECT_EQ(s->activeVoiceCount(), Synth::maxVoices + 1); // 1 ms in: still fading
    const auto rest = mono(render(*s, 432, {}));
    after.insert(after.end(), rest.begin(), rest.end());
    EXPECT_EQ(s->activeVoiceCount(), Synth::maxVoices); // 10 ms later it is gone
    bool oldestSounding = false;
    for (int i = 0; i < Synth::voiceSlots; ++i) oldestSounding = oldestSounding || (s->voiceInfo(i).active && s->voiceInfo(i).note == oldestNote);
    EXPECT_FALSE(oldestSounding);
    // No step larger than the music's own in the 10 ms after the steal.
    double stepBefore = 0.0, stepAfter = std::abs(static_cast<double>(after[0]) - before.back());
    for (std::size_t i = before.size() - 4800; i < before.size(); ++i) stepBefore = std::max(stepBefore, std::abs(static_cast<double>(before[i]) - before[i - 1]));
    for (std::size_t i = 1; i < after.size(); ++i) stepAfter = std::max(stepAfter, std::abs(static_cast<double>(after[i]) - after[i - 1]));
    EXPECT_LT(stepAfter, 1.5 * stepBefore);
}

TEST(EngineVoices, ANonFiniteVoiceIsFreedAndTheOthersPlayOn)
{
    auto s = makeSynth("cello");
    const int fs = 48000;
    render(*s, fs / 4, {on(0, 50), on(0, 57)});
    ASSERT_EQ(s->activeVoiceCount(), 2);
    int poisoned = -1;
    for (int i = 0; i < Synth::voiceSlots && poisoned < 0; ++i)
        if (s->voiceInfo(i).active && s->voiceInfo(i).note == 57) poisoned = i;
    ASSERT_GE(poisoned, 0);
    // A fault inside the model (never reachable from parameters): NaN in the string's lines.
    s->voice(poisoned).stringModel(s->voiceInfo(poisoned).stringIndex).processForce(std::nanf(""));
    const auto out = mono(render(*s, fs / 4, {}));
    for (float x : out) ASSERT_TRUE(std::isfinite(x));
    EXPECT_EQ(s->activeVoiceCount(), 1);
    EXPECT_GT(test::rms(out, fs / 8, fs / 4), 1e-2); // the D still sounds (the old guard silenced the mix)
    EXPECT_LT(std::abs(test::cents(test::pitchHz(out, fs, fs / 16, fs / 4), test::midiToHz(50))), 10.0);
}

TEST(EngineMidi, FourteenBitControllersReachTheBowForce)
{
    auto s = makeSynth("cello");
    const int fs = 48000;
    // CC2 MSB 32, LSB 64: (32*128 + 64)/16383 = 0.2539 -> force = 2 * 0.2539 * nominal.
    render(*s, fs / 2, {on(0, 50), cc(10, 2, 32), cc(11, 34, 64)});
    const double nominal = s->parameter(static_cast<int>(Param::BowForce));
    EXPECT_NEAR(s->voiceInfo(0).force, 2.0 * (32 * 128 + 64) / 16383.0 * nominal, 1e-3 * nominal);
    // A new MSB alone clears the LSB: 7-bit senders work too.
    render(*s, fs / 2, {cc(0, 2, 96)});
    EXPECT_NEAR(s->voiceInfo(0).force, 2.0 * 96 / 127.0 * nominal, 1e-3 * nominal);
}

TEST(EngineMidi, RpnBendRangeAndSustain)
{
    auto s = makeSynth("cello");
    const int fs = 48000;
    // RPN 0 = 12 semitones, then full bend up: D3 sounds as D4.
    render(*s, fs / 2, {cc(0, 101, 0), cc(1, 100, 0), cc(2, 6, 12), cc(3, 101, 127), cc(4, 100, 127),
                        on(10, 50), bend(20, 16383)});
    EXPECT_NEAR(test::cents(s->voiceInfo(0).frequency, test::midiToHz(62)), s->voiceInfo(0).correctionCents, 1.0);
    // Sustain holds the note past its note-off; releasing the pedal lifts the bow.
    render(*s, fs / 4, {cc(0, 64, 127), off(10, 50)});
    EXPECT_TRUE(s->voiceInfo(0).active);
    EXPECT_FALSE(s->voiceInfo(0).released);
    render(*s, 10, {cc(0, 64, 0)});
    EXPECT_TRUE(s->voiceInfo(0).released);
}

TEST(EngineMidi, LegatoGlidesOnOneStringAndReturnsToTheHeldNote)
{
    ParamValues p = defaultParams();
    p[static_cast<int>(Param::Legato)] = 1.0f;
    p[static_cast<int>(Param::Portamento)] = 0.05f;
    auto s = makeSynth("cello", 48000.0, p);
    render(*s, 24000, {on(0, 50), on(12000, 52)});
    EXPECT_EQ(s->activeVoiceCount(), 1);
    EXPECT_NEAR(test::cents(s->voiceInfo(0).frequency, test::midiToHz(52)), s->voiceInfo(0).correctionCents, 0.5);
    render(*s, 12000, {off(0, 52)});
    EXPECT_EQ(s->activeVoiceCount(), 1);
    EXPECT_NEAR(test::cents(s->voiceInfo(0).frequency, test::midiToHz(50)), s->voiceInfo(0).correctionCents, 0.5);
    EXPECT_FALSE(s->voiceInfo(0).released);
}

TEST(EngineMidi, MidiLearnAssignsTheNextControllerOverTheFullRange)
{
    ControllerMap map;
    auto s = makeSynth("cello", 48000.0, defaultParams(), &map);
    map.armLearn(static_cast<int>(Param::Ambient));
    render(*s, 100, {cc(0, 21, 127)});
    EXPECT_EQ(map.learning(), -1);
    EXPECT_EQ(map.get(21).param, static_cast<int>(Param::Ambient));
    EXPECT_FLOAT_EQ(s->parameter(static_cast<int>(Param::Ambient)), 40.0f);
    render(*s, 100, {cc(0, 21, 0)});
    EXPECT_FLOAT_EQ(s->parameter(static_cast<int>(Param::Ambient)), 0.0f);
    // Unlearned controllers keep their built-in meaning and do not touch parameters.
    render(*s, 100, {cc(0, 22, 64)});
    EXPECT_FLOAT_EQ(s->parameter(static_cast<int>(Param::Ambient)), 0.0f);
}

TEST(EngineMpe, PerNoteControlAffectsOnlyItsNote)
{
    ParamValues p = defaultParams();
    p[static_cast<int>(Param::Mpe)] = 1.0f;
    const int n = 36000;
    // Two notes on member channels 2 and 3 (indices 1, 2); pressure, CC74 and bend on channel 2 only.
    const std::vector<Event> expression{pressure(6000, 120, 1), cc(9000, 74, 20, 1), bend(12000, 12000, 1)};
    std::vector<Event> both{on(0, 50, 100, 1), on(0, 57, 100, 2)};
    both.insert(both.end(), expression.begin(), expression.end());
    std::vector<Event> firstOnly{on(0, 50, 100, 1)};
    firstOnly.insert(firstOnly.end(), expression.begin(), expression.end());
    auto a = makeSynth("cello", 48000.0, p), b = makeSynth("cello", 48000.0, p), c = makeSynth("cello", 48000.0, p);
    const auto mixed = render(*a, n, both), alone = render(*b, n, firstOnly), second = render(*c, n, {on(0, 57, 100, 2)});
    // The mix is linear after the strings: (both) - (first alone) must be the second note untouched.
    double worst = 0.0, level = test::peakAbs(second.first, 0, n);
    for (int i = 0; i < n; ++i) worst = std::max(worst, std::abs(static_cast<double>(mixed.first[i] - alone.first[i] - second.first[i])));
    EXPECT_GT(level, 1e-2);
    EXPECT_LT(worst, 1e-5 * std::max(1.0, level));
    // And the expression did reach the first note: its bend is 12000 -> (12000-8192)/8191 * 48 st.
    EXPECT_NEAR(test::cents(a->voiceInfo(0).frequency, test::midiToHz(50 + (12000 - 8192) / 8191.0 * 48)), a->voiceInfo(0).correctionCents, 1.0);
}

TEST(EngineMpe, ConfigurationMessageSetsTheZones)
{
    auto s = makeSynth("cello");
    EXPECT_FALSE(s->mpeMemberChannel(3));
    std::vector<Event> mcm{cc(0, 101, 0), cc(0, 100, 6), cc(0, 6, 7)}; // lower zone, 7 members
    render(*s, 10, mcm);
    EXPECT_TRUE(s->mpeMemberChannel(1));
    EXPECT_TRUE(s->mpeMemberChannel(7));
    EXPECT_FALSE(s->mpeMemberChannel(8));
    render(*s, 10, {cc(0, 101, 0, 15), cc(0, 100, 6, 15), cc(0, 6, 4, 15)}); // upper zone, 4 members
    EXPECT_TRUE(s->mpeMemberChannel(11));
    EXPECT_FALSE(s->mpeMemberChannel(10));
}

TEST(EngineRobustness, AbsurdParametersAndControllersNeverGiveNanOrBlowUp)
{
    auto s = makeSynth("violin");
    std::vector<Event> events{on(0, 67), on(0, 88), on(0, 55)};
    const auto first = render(*s, 4800, events);
    const std::vector<float> absurd{std::nanf(""), INFINITY, -INFINITY, 1e30f, -1e30f, 0.0f};
    int frame = 0;
    for (float x : absurd) {
        for (int i = 0; i < paramCount; ++i) s->setParameter(i, x);
        const auto out = render(*s, 2400, {cc(0, 2, 127), bend(1, 16383), pressure(2, 127, 0), on(3, frame % 128)});
        for (std::size_t k = 0; k < out.first.size(); ++k) {
            ASSERT_TRUE(std::isfinite(out.first[k]) && std::isfinite(out.second[k])) << x;
            ASSERT_LE(std::abs(out.first[k]), 4.0f);
        }
        ++frame;
    }
    for (int i = 0; i < paramCount; ++i) {
        const float v = s->parameter(i);
        EXPECT_GE(v, paramInfo(i).min);
        EXPECT_LE(v, paramInfo(i).max);
    }
    // Garbage MIDI: short, empty and system messages are ignored.
    const std::uint8_t junk[] = {0xF0, 0x7E, 0xF7};
    s->handleMidi(junk, 3);
    s->handleMidi(junk, 0);
    s->handleMidi(nullptr, 3);
    const std::uint8_t shortNote[] = {0x90};
    s->handleMidi(shortNote, 1);
}

TEST(EngineRobustness, FrictionModelSwitchMidNoteKeepsTheNoteSounding)
{
    auto s = makeSynth("cello");
    const int fs = 48000;
    render(*s, fs / 2, {on(0, 50)});
    for (int m : {0, 2, 1}) {
        s->setParameter(static_cast<int>(Param::FrictionModel), static_cast<float>(m));
        s->setParameter(static_cast<int>(Param::ContactLaw), static_cast<float>(m % 2));
        const auto out = mono(render(*s, fs / 2, {}));
        EXPECT_GT(test::rms(out, fs / 4, fs / 2), 1e-2) << m;
        EXPECT_LT(std::abs(test::cents(test::pitchHz(out, fs, fs / 8, fs / 2), test::midiToHz(50))), 10.0) << m;
    }
}

namespace {
ControlEvent control(Control kind, float value, int channel = 0, int note = -1)
{
    ControlEvent e;
    e.kind = kind;
    e.value = value;
    e.channel = static_cast<std::int8_t>(channel);
    e.note = static_cast<std::int8_t>(note);
    return e;
}
} // namespace

// A controller's hand on the bow (what HID sends): the same normalised controls as MIDI, mapped
// with the same nominal parameters and the same per-string scaling; the speed is signed.
TEST(EngineDirectBow, AControllersHandHoldsTheBowThroughTheSameMapping)
{
    auto s = makeSynth("cello");
    const ParamValues& p = s->parameters();
    const double nominalForce = p[static_cast<int>(Param::BowForce)], nominalSpeed = p[static_cast<int>(Param::BowSpeed)];
    const double nominalBeta = p[static_cast<int>(Param::BowPosition)];
    const double gScale = stringForceScale(s->instrument(), 1);
    ASSERT_GT(std::abs(gScale - 1.0), 0.05); // the G string is heavier than the D: the scaling shows
    for (const auto& e : {control(Control::StringChoice, 1.0f), control(Control::DirectForce, 0.6f), control(Control::DirectSpeed, 0.7f),
                          control(Control::DirectPosition, 0.7f), control(Control::Engage, 1.0f)})
        s->apply(e);
    const int fs = 48000;
    const auto down = mono(render(*s, fs / 2, {on(0, 50)}));
    VoiceInfo v = s->voiceInfo(0);
    EXPECT_EQ(v.stringIndex, 1); // the controller chose the G string: D3 is stopped there
    EXPECT_NEAR(v.force, 2.0 * 0.6 * nominalForce * gScale, 1e-3);
    EXPECT_NEAR(v.speed, 2.0 * 0.7 * nominalSpeed, 1e-3);
    EXPECT_NEAR(v.beta, nominalBeta * std::exp2(2.0 * 0.2), 1e-3);
    EXPECT_GT(test::rms(down, fs / 4, fs / 2), 1e-2);
    s->apply(control(Control::DirectSpeed, -0.7f)); // a bow change
    const auto up = mono(render(*s, fs / 2, {}));
    EXPECT_NEAR(s->voiceInfo(0).speed, -2.0 * 0.7 * nominalSpeed, 1e-3);
    EXPECT_GT(test::rms(up, fs / 4, fs / 2), 1e-2);
    EXPECT_LT(std::abs(test::cents(test::pitchHz(up, fs, fs / 4, fs / 2), test::midiToHz(50))), 10.0);
    s->apply(control(Control::Engage, 0.0f)); // lifted: no force, the string rings down
    render(*s, fs / 10, {});
    EXPECT_NEAR(s->voiceInfo(0).force, 0.0, 1e-3);
    // Absurd values reach the model clamped to its own limits, never as NaN.
    s->apply(control(Control::Engage, 1.0f));
    s->apply(control(Control::DirectForce, NAN));
    s->apply(control(Control::DirectSpeed, INFINITY));
    const auto wild = mono(render(*s, fs / 10, {}));
    for (float x : wild) ASSERT_TRUE(std::isfinite(x));
    EXPECT_LE(std::abs(s->voiceInfo(0).speed), 2.0 * nominalSpeed + 1e-6);
    // Released: the channel's virtual player bows again (the direction alternates, speed positive first).
    s->apply(control(Control::DirectRelease, 0.0f));
    render(*s, fs / 4, {off(0, 50), on(10, 57)});
    EXPECT_FALSE(s->performance().channel(0).hand.holds);
}

TEST(EngineDirectBow, MidiPressureAndAControllerReachTheSameForce)
{
    // The one road: CC2 at x and a controller's force at x give the same newtons on one string.
    ParamValues p = defaultParams();
    p[static_cast<int>(Param::AttackForce)] = 0.0f;
    auto midi = makeSynth("cello", 48000.0, p), hid = makeSynth("cello", 48000.0, p);
    render(*midi, 24000, {cc(0, 2, 90), on(1, 50)});
    hid->apply(control(Control::DirectForce, 90.0f / 127.0f));
    hid->apply(control(Control::DirectSpeed, 0.5f));
    hid->apply(control(Control::Engage, 1.0f));
    render(*hid, 24000, {on(1, 50)});
    EXPECT_NEAR(midi->voiceInfo(0).force, hid->voiceInfo(0).force, 1e-4);
    EXPECT_NEAR(midi->voiceInfo(0).force, 2.0 * 90.0 / 127.0 * p[static_cast<int>(Param::BowForce)], 1e-3);
}

// A tablet put down (pen lifted at zero pressure, then released) must not leave its force and
// position on the channel: the keyboard played next gets its own CC2 and CC74 back.
TEST(EngineDirectBow, AKeyboardAfterTheTabletPlaysWithItsOwnControls)
{
    ParamValues p = defaultParams();
    p[static_cast<int>(Param::AttackForce)] = 0.0f;
    auto s = makeSynth("cello", 48000.0, p);
    const int fs = 48000;
    render(*s, fs / 10, {cc(0, 2, 80), cc(0, 74, 40)});
    for (const auto& e : {control(Control::DirectForce, 0.0f), control(Control::DirectSpeed, 0.5f), control(Control::DirectPosition, 1.0f),
                          control(Control::Engage, 0.0f), control(Control::DirectRelease, 0.0f)})
        s->apply(e);
    const auto keyboard = mono(render(*s, fs / 2, {on(0, 50)}));
    const VoiceInfo v = s->voiceInfo(0);
    const double nominalForce = s->parameters()[static_cast<int>(Param::BowForce)];
    const double nominalBeta = s->parameters()[static_cast<int>(Param::BowPosition)];
    EXPECT_NEAR(v.force, 2.0 * 80.0 / 127.0 * nominalForce * stringForceScale(s->instrument(), v.stringIndex), 1e-3);
    EXPECT_NEAR(v.beta, nominalBeta * std::exp2(2.0 * (40.0 / 127.0 - 0.5)), 1e-3);
    EXPECT_GT(test::rms(keyboard, fs / 4, fs / 2), 1e-2);
}

// The editor's live views: the newest note writes its physics, sample by sample, into the ring
// while someone listens; nobody listening costs no frames; a full ring drops, never blocks.
TEST(EngineViewTap, TheNewestNoteWritesItsPhysicsWhileSomeoneListens)
{
    auto s = makeSynth("cello");
    ViewRing ring(1u << 16);
    s->setViewTap(&ring);
    render(*s, 4800, {on(0, 50)});
    std::vector<ViewFrame> frames(ring.capacity());
    EXPECT_EQ(ring.read(frames.data(), frames.size()), 0u) << "no listener, no frames";

    ring.setListening(true);
    const int n = 24000;
    render(*s, n, {on(0, 57)}); // a second note (A3, the open A string): the views follow it
    const std::size_t got = ring.read(frames.data(), frames.size());
    ASSERT_EQ(got, static_cast<std::size_t>(n));
    EXPECT_EQ(frames[0].noteStart, 1);
    EXPECT_EQ(frames[1].noteStart, 0);
    const double expected = 440.0 * std::exp2((57 - 69) / 12.0);
    EXPECT_NEAR(frames[n - 1].frequency, expected, expected * 0.01);
    // Helmholtz motion on the bowed note: sticking at the bow speed, slipping once a period.
    int onsets = 0;
    double stickMismatch = 0.0;
    for (int i = n / 2; i < n; ++i) {
        const auto& f = frames[static_cast<std::size_t>(i)];
        if (!f.stick && frames[static_cast<std::size_t>(i - 1)].stick) ++onsets;
        if (f.stick) stickMismatch = std::max(stickMismatch, std::abs(static_cast<double>(f.velocity - f.bowSpeed)));
        EXPECT_GT(f.force, 0.0f);
        EXPECT_TRUE(std::isfinite(f.temperature));
    }
    const double periods = (n / 2) / 48000.0 * expected;
    EXPECT_NEAR(onsets / periods, 1.0, 0.1);
    EXPECT_LT(stickMismatch, 1e-3);

    // The ring full and unread: the audio keeps running, frames are counted as dropped.
    render(*s, static_cast<int>(ring.capacity()) + 4800, {});
    EXPECT_GE(ring.dropped(), 4800u);
    EXPECT_EQ(ring.read(frames.data(), frames.size()), ring.capacity());
}

TEST(EngineViewTap, WhenTheWatchedNoteEndsTheViewsFollowOneStillSounding)
{
    auto s = makeSynth("violin");
    ViewRing ring(1u << 17);
    ring.setListening(true);
    s->setViewTap(&ring);
    // G3 held, D5 played and released: after D5 dies the views return to the G.
    render(*s, 96000, {on(0, 55), on(4800, 74), off(24000, 74)});
    std::vector<ViewFrame> frames(ring.capacity());
    const std::size_t got = ring.read(frames.data(), frames.size());
    ASSERT_GT(got, 90000u);
    EXPECT_NEAR(frames[100].frequency, 196.0, 3.0);
    // The frame shows the D, not the G. Its frequency is the stopped string's, which the ear's
    // intonation correction may move by -50..+100 cents (listen() in Synth.cpp); this D5
    // double-slips at times, so the correction wanders inside that range.
    EXPECT_GE(frames[10000].frequency, 587.3 * std::exp2(-50.0 / 1200.0));
    EXPECT_LE(frames[10000].frequency, 587.3 * std::exp2(100.0 / 1200.0));
    EXPECT_NEAR(frames[got - 1].frequency, 196.0, 3.0);
    int starts = 0;
    for (std::size_t i = 0; i < got; ++i) starts += frames[i].noteStart;
    EXPECT_EQ(starts, 3); // G, D, back to G
}

// Cross-thread channels under ThreadSanitizer (the `tsan` build runs these): the MIDI-learn table
// is edited on one thread while the audio thread reads it and a third frees old tables.
TEST(EngineThreads, ControllerTablesAreNeverSeenHalfWritten)
{
    ControllerMap map;
    std::atomic<bool> done{false};
    std::atomic<long> torn{0}, reads{0};
    std::thread audio([&] {
        while (!done.load()) {
            const ControllerTable& t = map.acquire();
            // Every edit writes one generation into every slot it maps: a table mixing two
            // generations would be a torn read.
            float seen = -1.0f;
            for (int cc = 0; cc < ControllerTable::numControllers; ++cc) {
                const MappingEntry& e = t.get(cc);
                if (e.param < 0) continue;
                if (seen < 0.0f) seen = e.min;
                else if (e.min != seen) torn.fetch_add(1);
            }
            reads.fetch_add(1);
        }
    });
    std::thread housekeeping([&] {
        while (!done.load()) {
            map.collect();
            std::this_thread::yield();
        }
    });
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(400);
    for (int g = 0; std::chrono::steady_clock::now() < end || reads.load() < 1000; ++g) {
        std::vector<MappingEntry> list;
        for (int cc = g % 7; cc < ControllerTable::numControllers; cc += 3)
            list.push_back({cc, static_cast<int>(Param::BowForce), static_cast<float>(g), static_cast<float>(g + 1), false});
        map.assign(list);
        if (g % 10 == 0) map.set(5, static_cast<int>(Param::Gain), static_cast<float>(g), 0.0f, false);
    }
    done = true;
    audio.join();
    housekeeping.join();
    EXPECT_EQ(torn.load(), 0);
    EXPECT_GT(reads.load(), 100);
}
