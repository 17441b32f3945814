// The JUCE processor itself, in-process: what a host cannot reach from outside (MIDI learn
// driven by the editor, mapping and exciter presets) and how it lands in the saved state.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "RosinProcessor.h"
#include "rosin/hid/Recording.h"
#include "rosin/engine/Parameters.h"

using rosin::plugin::RosinProcessor;
namespace engine = rosin::engine;

namespace {
void play(RosinProcessor& p, std::initializer_list<juce::MidiMessage> messages, int blocks = 4)
{
    juce::AudioBuffer<float> buffer(2, 256);
    juce::MidiBuffer midi;
    for (const auto& m : messages) midi.addEvent(m, 0);
    for (int b = 0; b < blocks; ++b) {
        buffer.clear();
        p.processBlock(buffer, midi);
        midi.clear();
    }
}
} // namespace

TEST(Processor, MidiLearnLandsInTheStateAndComesBack)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor a;
    a.setPlayConfigDetails(0, 2, 48000.0, 256);
    a.prepareToPlay(48000.0, 256);
    a.controllerMap().armLearn(static_cast<int>(engine::Param::BowPosition));
    play(a, {juce::MidiMessage::controllerEvent(1, 21, 100)});
    EXPECT_EQ(a.controllerMap().learning(), -1);
    // The audio thread reports the learn; the housekeeping thread writes the table.
    for (int i = 0; i < 200 && a.controllerMap().get(21).param < 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_EQ(a.controllerMap().get(21).param, static_cast<int>(engine::Param::BowPosition));
    // The controller's value moved the host parameter too: slider, automation and session agree.
    const auto& info = engine::paramInfo(engine::Param::BowPosition);
    const float expected = info.min + (info.max - info.min) * 100.0f / 127.0f;
    for (int i = 0; i < 200 && std::abs(a.parameters().getRawParameterValue("bow_position")->load() - expected) > 1e-5f; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_NEAR(a.parameters().getRawParameterValue("bow_position")->load(), expected, 1e-5f);

    juce::MemoryBlock state;
    a.getStateInformation(state);
    RosinProcessor b;
    b.setStateInformation(state.getData(), static_cast<int>(state.getSize()));
    const auto e = b.controllerMap().get(21);
    EXPECT_EQ(e.param, static_cast<int>(engine::Param::BowPosition));
    EXPECT_FLOAT_EQ(e.min, engine::paramInfo(engine::Param::BowPosition).min);
    EXPECT_FLOAT_EQ(e.max, engine::paramInfo(engine::Param::BowPosition).max);
    juce::MemoryBlock again;
    b.getStateInformation(again);
    EXPECT_EQ(again, state);
}

TEST(Processor, MappingAndExciterPresetsSetWhatTheyName)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.loadMapping("keyboard");
    EXPECT_EQ(p.controllerMap().get(21).param, static_cast<int>(engine::Param::BowForce));
    EXPECT_FLOAT_EQ(p.controllerMap().get(21).max, 3.0f);
    p.loadMapping("mpe");
    EXPECT_EQ(p.controllerMap().get(21).param, -1);
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("mpe")->load(), 1.0f);
    p.loadExciter("enhanced-rod");
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("friction_model")->load(), 2.0f);
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("contact_law")->load(), 1.0f);
    EXPECT_THROW(p.loadMapping("no-such-map"), std::runtime_error);
    p.loadMapping("pizzicato"); // articulation choices travel in map presets too
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("articulation")->load(), 5.0f);
    p.loadMapping("articulations-by-channel");
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("articulation_channels")->load(), 1.0f);
}

TEST(Processor, LoadingAnInstrumentPresetSetsItsBowDefaults)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    p.loadInstrument("double-bass", true);
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("bow_force")->load(), 3.0f);
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("bow_position")->load(), 0.13f);
    EXPECT_EQ(p.currentInstrument(), "double-bass");
    play(p, {juce::MidiMessage::noteOn(1, 40, 0.8f)}, 8);
    EXPECT_EQ(p.activeVoices(), 1);
}

// A preset chosen from another thread while the housekeeping thread polls the instrument
// parameter: the poll must not build the instrument the parameter named a moment before the
// preset moved it, which undid the choice (seen once in CI, about once in 30 loads here).
TEST(Processor, PresetsLoadedInARowAreNotUndoneByTheHousekeepingThread)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    const auto& names = RosinProcessor::instrumentNames();
    for (int k = 0; k < 150; ++k) {
        const juce::String name = names[(k * 3 + 1) % names.size()];
        p.loadInstrument(name, false);
        std::this_thread::sleep_for(std::chrono::milliseconds(k % 7)); // land anywhere in the 5 ms poll
        ASSERT_EQ(p.currentInstrument(), name) << "load " << k;
        ASSERT_EQ(juce::roundToInt(p.parameters().getRawParameterValue("instrument")->load()), names.indexOf(name)) << "load " << k;
    }
}

// The whole HID path with a fake device at the hidapi boundary: device thread -> decoder ->
// mapper -> SPSC queue -> processBlock -> voice, and the device unplugged in the middle of a note.
namespace {
class FakePen : public rosin::hid::DeviceHandle {
public:
    FakePen(std::vector<std::uint8_t> descriptor, std::atomic<bool>& plugged, std::atomic<int>& sent)
        : descriptor_(std::move(descriptor)), plugged_(plugged), sent_(sent) {}
    int read(std::uint8_t* buffer, std::size_t size, int) override
    {
        if (!plugged_) return -1;
        std::this_thread::sleep_for(std::chrono::milliseconds(2)); // a 500 Hz tablet
        // Huion report 10: in range + tip, x sweeping right then left, y centred, pressure 60 %.
        const int k = sent_++;
        const double x = 0.3 + 0.2 * std::sin(k * 0.01);
        std::uint8_t r[10] = {10, 0x41, 0, 0, 0, 0x40, 0, 0, 0x9A, 0x13}; // tip (bit 0) + in range (bit 6)
        const auto xi = static_cast<std::uint16_t>(x * 32767);
        r[2] = static_cast<std::uint8_t>(xi & 0xFF);
        r[3] = static_cast<std::uint8_t>(xi >> 8);
        r[6] = static_cast<std::uint8_t>(4915 & 0xFF); // pressure 0.6 of 8191
        r[7] = static_cast<std::uint8_t>(4915 >> 8);
        std::copy_n(r, std::min<std::size_t>(size, 10), buffer);
        return 10;
    }
    std::vector<std::uint8_t> descriptor() override { return descriptor_; }

private:
    std::vector<std::uint8_t> descriptor_;
    std::atomic<bool>& plugged_;
    std::atomic<int>& sent_;
};

class FakeBackend : public rosin::hid::DeviceBackend {
public:
    FakeBackend(std::vector<std::uint8_t> d, std::atomic<bool>& plugged, std::atomic<int>& sent)
        : descriptor_(std::move(d)), plugged_(plugged), sent_(sent) {}
    std::vector<rosin::hid::DeviceInfo> enumerate() override
    {
        if (!plugged_) return {};
        return {{"/dev/fake-hidraw0", 0x256C, 0x006D, "Fake Huion pen"}};
    }
    std::unique_ptr<rosin::hid::DeviceHandle> open(const rosin::hid::DeviceInfo&, std::string&) override
    {
        return std::make_unique<FakePen>(descriptor_, plugged_, sent_);
    }

private:
    std::vector<std::uint8_t> descriptor_;
    std::atomic<bool>& plugged_;
    std::atomic<int>& sent_;
};

double blockRms(RosinProcessor& p, int blocks, juce::MidiBuffer midi = {})
{
    juce::AudioBuffer<float> buffer(2, 256);
    double sum = 0.0;
    for (int b = 0; b < blocks; ++b) {
        buffer.clear();
        p.processBlock(buffer, midi);
        midi.clear();
        for (int i = 0; i < 256; ++i) sum += buffer.getSample(0, i) * buffer.getSample(0, i);
        std::this_thread::sleep_for(std::chrono::microseconds(5333)); // about real time at 48 kHz
    }
    return std::sqrt(sum / (blocks * 256.0));
}
} // namespace

TEST(Processor, FakePenPlaysAVoiceAndUnpluggingMidNoteLiftsTheBow)
{
    juce::ScopedJuceInitialiser_GUI juce;
    std::atomic<bool> plugged{true};
    std::atomic<int> sent{0};
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    ASSERT_TRUE(p.hidInput().setBackend(std::make_unique<FakeBackend>(
        rosin::hid::readBinary(ROSIN_HID_DATA "/huion_h640p_256c_006d_pen.rdesc.bin"), plugged, sent)));
    p.hidInput().rescanSeconds = 0.05;
    // The reference silence is taken before the pen is enabled: once the thread runs, the pen may
    // start the note within the first blocks (it did under load, making "silent" a note).
    const double silent = blockRms(p, 5);
    p.parameters().getParameter("hid_input")->setValueNotifyingHost(1.0f); // the loader starts the thread
    double playing = 0.0;
    for (int tries = 0; tries < 40 && p.activeVoices() == 0; ++tries) playing = blockRms(p, 5);
    ASSERT_EQ(p.activeVoices(), 1) << p.hidInput().status();
    playing = blockRms(p, 60); // the pen bows back and forth for a third of a second
    EXPECT_GT(sent.load(), 50);
    EXPECT_GT(playing, 1e-3);
    EXPECT_GT(playing, 10.0 * silent);
    EXPECT_NE(p.hidInput().status().find("tablet"), std::string::npos) << p.hidInput().status();

    plugged = false; // unplugged while the note sounds
    for (int tries = 0; tries < 400 && p.activeVoices() > 0; ++tries) blockRms(p, 1);
    EXPECT_EQ(p.activeVoices(), 0);
    EXPECT_NE(p.hidInput().status().find("unplugged"), std::string::npos) << p.hidInput().status();
    // The body's own modes ring on after the string is free, from wherever in its cycle the bow
    // left (the HID thread's timing decides that, so the tail's level varies from run to run:
    // usually under -120 dB at once, once still above it 20 blocks on under ThreadSanitizer).
    // What must hold is that it dies away, to -120 dB within half a second.
    int tailBlocks = 0;
    double tail = 1.0;
    while (tailBlocks < 94 && (tail = blockRms(p, 1)) >= 1e-6) ++tailBlocks;
    EXPECT_LT(tailBlocks, 94) << "still " << tail << " after half a second";
    EXPECT_LT(blockRms(p, 10), 1e-6); // and stays silent

    plugged = true; // and back
    for (int tries = 0; tries < 100 && p.hidInput().connections() < 2; ++tries) blockRms(p, 2);
    EXPECT_EQ(p.hidInput().connections(), 2);
    p.parameters().getParameter("hid_input")->setValueNotifyingHost(0.0f);
    for (int tries = 0; tries < 100 && p.hidInput().running(); ++tries) blockRms(p, 2);
    EXPECT_FALSE(p.hidInput().running());
}

TEST(Processor, HidMappingsAreSavedWithTheState)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor a;
    auto m = a.hidInput().mapping(rosin::hid::DeviceKind::Gamepad);
    m.forceCurve.outMax = 0.75;
    a.hidInput().setMapping(m);
    juce::MemoryBlock state;
    a.getStateInformation(state);
    RosinProcessor b;
    b.setStateInformation(state.getData(), static_cast<int>(state.getSize()));
    EXPECT_DOUBLE_EQ(b.hidInput().mapping(rosin::hid::DeviceKind::Gamepad).forceCurve.outMax, 0.75);
    b.loadHidMapping("gamepad");
    EXPECT_DOUBLE_EQ(b.hidInput().mapping(rosin::hid::DeviceKind::Gamepad).forceCurve.outMax, 1.0);
    EXPECT_THROW(b.loadHidMapping("theremin"), std::runtime_error);
}

// ---- Issue 21: what a DAW user meets sooner or later ----
namespace {
juce::MidiBuffer messages(std::initializer_list<juce::MidiMessage> list)
{
    juce::MidiBuffer m;
    for (const auto& x : list) m.addEvent(x, 0);
    return m;
}

void blocks(RosinProcessor& p, int count, juce::MidiBuffer midi = {}, int size = 256)
{
    juce::AudioBuffer<float> buffer(2, size);
    for (int b = 0; b < count; ++b) {
        buffer.clear();
        p.processBlock(buffer, midi);
        midi.clear();
    }
}

void setChoice(RosinProcessor& p, const char* id, int index)
{
    auto* param = p.parameters().getParameter(id);
    param->setValueNotifyingHost(param->convertTo0to1(static_cast<float>(index)));
}

/// The processor's own state out of a VST3 state file as JUCE's VST3 host saves it.
juce::MemoryBlock rosinStateOf(const juce::File& file)
{
    juce::MemoryBlock outer;
    file.loadFileAsData(outer);
    std::unique_ptr<juce::XmlElement> xml(juce::AudioProcessor::getXmlFromBinary(outer.getData(), static_cast<int>(outer.getSize())));
    juce::MemoryBlock inner;
    if (xml)
        if (auto* component = xml->getChildByName("IComponent")) inner.fromBase64Encoding(component->getAllSubText());
    return inner;
}

float raw(RosinProcessor& p, const char* id) { return p.parameters().getRawParameterValue(id)->load(); }
} // namespace

TEST(ProcessorSwap, AnInstrumentChangeKeepsZonesBendRangesPedalAndHeldNotes)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    p.setNonRealtime(true);
    // An MPE controller configures its zone once (7 members), sets a member's bend range to 24,
    // the pedal goes down and a note is held on member channel 3.
    juce::MidiBuffer setup;
    int at = 0;
    for (const auto m : juce::MidiRPNGenerator::generate(1, 6, 7 << 7, false, true)) setup.addEvent(m.getMessage(), at++);
    for (const auto m : juce::MidiRPNGenerator::generate(3, 0, 24 << 7, false, true)) setup.addEvent(m.getMessage(), at++);
    setup.addEvent(juce::MidiMessage::controllerEvent(1, 64, 127), at++);
    setup.addEvent(juce::MidiMessage::noteOn(3, 57, 0.8f), at++);
    blocks(p, 40, setup);
    ASSERT_EQ(p.activeVoices(), 1);
    const int before = p.enginesInstalled();
    setChoice(p, "instrument", 1); // viola
    blocks(p, 40);
    ASSERT_EQ(p.enginesInstalled(), before + 1);
    EXPECT_EQ(p.currentInstrument(), "viola");
    EXPECT_EQ(p.performance().lowerMembers(), 7);
    EXPECT_TRUE(p.performance().channel(0).sustain);
    EXPECT_FLOAT_EQ(p.decoder().bendRange(2, p.performance(), p.currentParams()), 24.0f);
    EXPECT_EQ(p.activeVoices(), 1); // the held A3 sounds on the viola
    ASSERT_EQ(p.performance().heldCount(), 1);
    EXPECT_EQ(p.performance().held(0).note, 57);
}

TEST(ProcessorSwap, RestoringTheSameInstrumentKeepsItsEngine)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    blocks(p, 20, messages({juce::MidiMessage::noteOn(1, 50, 0.8f)}));
    juce::MemoryBlock state;
    p.getStateInformation(state);
    const int before = p.enginesInstalled();
    p.setStateInformation(state.getData(), static_cast<int>(state.getSize()));
    blocks(p, 20);
    EXPECT_EQ(p.enginesInstalled(), before); // no rebuild, so the note plays on undisturbed
    EXPECT_EQ(p.activeVoices(), 1);
    // prepareToPlay at the same rate keeps it too.
    p.prepareToPlay(48000.0, 256);
    EXPECT_EQ(p.enginesInstalled(), before);
}

// A learned controller moves the engine at once and its host parameter a few ms later (the
// housekeeping thread). A state restored in between is newer than that move: the move must not
// land on top of it, and the engine must take the restored value even when it equals the value
// the engine had before the controller moved it (the validator's mid-note restore was sometimes
// left with a walked force and articulation, and a silent note, before this).
TEST(ProcessorState, AControllerMoveMadeBeforeARestoreDoesNotOverwriteIt)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    const auto force = engine::Param::BowForce;
    const auto& info = engine::paramInfo(force);
    p.controllerMap().set(21, static_cast<int>(force), info.min, info.max, false);
    blocks(p, 4, messages({juce::MidiMessage::noteOn(1, 50, 0.8f)}));
    juce::MemoryBlock saved;
    p.getStateInformation(saved);
    const float restored = p.currentParams()[static_cast<std::size_t>(force)];
    const float moved = info.min + (info.max - info.min) * 10.0f / 127.0f;
    ASSERT_GT(std::abs(moved - restored), 0.1f * (info.max - info.min));
    for (int trial = 0; trial < 5; ++trial) {
        blocks(p, 1, messages({juce::MidiMessage::controllerEvent(1, 21, 10)}));
        ASSERT_NEAR(p.engineParameter(force), moved, 1e-4f); // the engine moved within the block
        p.setStateInformation(saved.getData(), static_cast<int>(saved.getSize()));
        std::this_thread::sleep_for(std::chrono::milliseconds(60)); // the housekeeping thread runs about ten times
        blocks(p, 2);
        EXPECT_NEAR(p.currentParams()[static_cast<std::size_t>(force)], restored, 1e-4f) << "trial " << trial;
        EXPECT_NEAR(p.engineParameter(force), restored, 1e-4f) << "trial " << trial;
    }
    // A move made after the restore still reaches the host parameter.
    blocks(p, 1, messages({juce::MidiMessage::controllerEvent(1, 21, 10)}));
    for (int i = 0; i < 200 && std::abs(p.currentParams()[static_cast<std::size_t>(force)] - moved) > 1e-4f; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_NEAR(p.currentParams()[static_cast<std::size_t>(force)], moved, 1e-4f);
    EXPECT_NEAR(p.engineParameter(force), moved, 1e-4f);
}

TEST(ProcessorSwap, ABrokenPresetDoesNotStallOfflineRendering)
{
    // A user folder holds a broken violin preset: the build fails, and an offline render must
    // not wait for an engine that will never come (it waited 5 s in every block).
    const juce::File dir = juce::File::getSpecialLocation(juce::File::tempDirectory).getChildFile("rosin-broken-presets");
    dir.getChildFile("instruments").createDirectory();
    dir.getChildFile("instruments").getChildFile("violin.json").replaceWithText("{\"format\": \"rosin-instrument/1\", \"name\": ");
    ::setenv("ROSIN_PRESETS", dir.getFullPathName().toRawUTF8(), 1);
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    ::unsetenv("ROSIN_PRESETS");
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    p.setNonRealtime(true);
    setChoice(p, "instrument", 0);
    const auto start = std::chrono::steady_clock::now();
    blocks(p, 20, messages({juce::MidiMessage::noteOn(1, 62, 0.8f)}));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 3.0); // 20 blocks: 100 s before the fix
    EXPECT_EQ(p.currentInstrument(), "cello"); // the cello plays on
    EXPECT_EQ(p.activeVoices(), 1);
    dir.deleteRecursively();
}

TEST(ProcessorState, StatesOfEarlierVersionsLoad)
{
    juce::ScopedJuceInitialiser_GUI juce;
    const juce::File data(ROSIN_TEST_DATA "/state");
    {
        RosinProcessor p;
        const auto s = rosinStateOf(data.getChildFile("v1-violin-pizzicato.state"));
        ASSERT_GT(s.getSize(), 100u);
        p.setStateInformation(s.getData(), static_cast<int>(s.getSize()));
        EXPECT_EQ(p.lastStateProblem(), "");
        EXPECT_FLOAT_EQ(raw(p, "instrument"), 0.0f); // violin
        EXPECT_FLOAT_EQ(raw(p, "articulation"), 5.0f); // pizzicato
        EXPECT_FLOAT_EQ(raw(p, "mute"), 1.0f);
        EXPECT_FLOAT_EQ(raw(p, "gain"), -6.0f);
        EXPECT_NEAR(raw(p, "bow_force"), 0.7f, 1e-6);
        // Saved again it is the current version, and it reads back to the same state.
        juce::MemoryBlock again;
        p.getStateInformation(again);
        std::unique_ptr<juce::XmlElement> xml(juce::AudioProcessor::getXmlFromBinary(again.getData(), static_cast<int>(again.getSize())));
        EXPECT_EQ(xml->getStringAttribute("format"), "rosin-state/" + juce::String(RosinProcessor::stateVersion));
        RosinProcessor q;
        q.setStateInformation(again.getData(), static_cast<int>(again.getSize()));
        juce::MemoryBlock third;
        q.getStateInformation(third);
        EXPECT_EQ(third, again);
    }
    {
        RosinProcessor p;
        const auto s = rosinStateOf(data.getChildFile("v1-learned-and-hid.state"));
        p.setStateInformation(s.getData(), static_cast<int>(s.getSize()));
        EXPECT_EQ(p.lastStateProblem(), "");
        const auto force = p.controllerMap().get(21), ambient = p.controllerMap().get(74);
        EXPECT_EQ(force.param, static_cast<int>(engine::Param::BowForce));
        EXPECT_FLOAT_EQ(force.max, 3.0f);
        EXPECT_EQ(ambient.param, static_cast<int>(engine::Param::Ambient));
        EXPECT_TRUE(ambient.invert);
        // The version-1 gamepad map reached 1.1 N: the nominal force, 0.5 in today's units.
        EXPECT_NEAR(p.hidInput().mapping(rosin::hid::DeviceKind::Gamepad).forceCurve.outMax, 0.5, 1e-9);
        EXPECT_NEAR(p.hidInput().mapping(rosin::hid::DeviceKind::Tablet).forceCurve.outMax, 1.0, 1e-9);
    }
    if (data.getChildFile("v1-first-release.state").existsAsFile()) {
        // The first release had no articulations, mute or automatic vibrato: they come back at
        // their defaults, not at whatever this instance had.
        RosinProcessor p;
        setChoice(p, "articulation", 5);
        setChoice(p, "mute", 1);
        const auto s = rosinStateOf(data.getChildFile("v1-first-release.state"));
        p.setStateInformation(s.getData(), static_cast<int>(s.getSize()));
        EXPECT_EQ(p.lastStateProblem(), "");
        EXPECT_FLOAT_EQ(raw(p, "articulation"), 0.0f);
        EXPECT_FLOAT_EQ(raw(p, "mute"), 0.0f);
        EXPECT_FLOAT_EQ(raw(p, "vibrato_auto"), 0.0f);
    } else {
        ADD_FAILURE() << "tests/data/state/v1-first-release.state is missing";
    }
}

TEST(ProcessorState, AStateFromANewerBuildIsRefusedWithAReason)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    setChoice(p, "articulation", 2);
    const auto s = rosinStateOf(juce::File(ROSIN_TEST_DATA "/state").getChildFile("v9-from-a-newer-build.state"));
    p.setStateInformation(s.getData(), static_cast<int>(s.getSize()));
    EXPECT_NE(p.lastStateProblem().indexOf("newer Rosin"), -1) << p.lastStateProblem();
    EXPECT_FLOAT_EQ(raw(p, "articulation"), 2.0f); // untouched
    const char garbage[] = "not a state at all";
    p.setStateInformation(garbage, sizeof garbage);
    EXPECT_NE(p.lastStateProblem().indexOf("not a Rosin state"), -1) << p.lastStateProblem();
    // Found by the fuzzer: a processing instruction inside an element left unclosed sends JUCE's
    // XML parser into an endless loop (this test would hang until ctest's timeout). Refused unread.
    juce::MemoryBlock hostile;
    juce::AudioProcessor::copyXmlToBinary(juce::XmlElement("placeholder"), hostile);
    const juce::String text = R"(<?xml version="1.0"?><RosinState format="rosin-state/2"><??><e t=""><??>a)";
    hostile.setSize(8);
    hostile.append(text.toRawUTF8(), text.getNumBytesAsUTF8() + 1);
    static_cast<juce::uint32*>(hostile.getData())[1] = juce::ByteOrder::swapIfBigEndian(static_cast<juce::uint32>(text.getNumBytesAsUTF8() + 1));
    p.setStateInformation(hostile.getData(), static_cast<int>(hostile.getSize()));
    EXPECT_NE(p.lastStateProblem().indexOf("malformed"), -1) << p.lastStateProblem();
    EXPECT_FLOAT_EQ(raw(p, "articulation"), 2.0f);
}

TEST(ProcessorParameters, AChoiceAddedLaterDoesNotMoveAutomation)
{
    // Hosts store choices as normalised values. Each growing choice has spare slots, so the
    // normalised value of every existing choice is fixed by its slot count, not by how many
    // choices exist today.
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    const std::pair<const char*, int> slots[] = {{"articulation", 16}, {"friction_model", 8}, {"contact_law", 4}, {"string_policy", 4}, {"fixed_string", 8}};
    for (const auto& [id, n] : slots) {
        auto* param = dynamic_cast<juce::AudioParameterChoice*>(p.parameters().getParameter(id));
        ASSERT_NE(param, nullptr) << id;
        EXPECT_EQ(param->choices.size(), n) << id;
        const int real = static_cast<int>(engine::choiceNames(static_cast<engine::Param>(engine::paramIndex(id))).size());
        for (int i = 0; i < real; ++i) EXPECT_FLOAT_EQ(param->convertTo0to1(static_cast<float>(i)), static_cast<float>(i) / (n - 1)) << id;
        // A spare slot plays the last real choice.
        param->setValueNotifyingHost(1.0f);
        const auto which = static_cast<engine::Param>(engine::paramIndex(id));
        EXPECT_FLOAT_EQ(engine::sanitise(which, p.currentParams()[static_cast<std::size_t>(which)]), engine::paramInfo(which).max) << id;
    }
    EXPECT_EQ(engine::choiceNames(engine::Param::Articulation).size(), 7u); // the README lists these seven
}

// Every cross-thread path of the processor at once (the `tsan` build runs this under
// ThreadSanitizer): the audio thread plays, in real-time and offline mode, while the message
// thread restores states of other instruments, loads maps, arms MIDI-learn and moves
// parameters, the housekeeping thread builds and frees engines, and the HID thread plays a pen.
TEST(ProcessorThreads, StatesMapsLearnAndEnginesChangeWhileAudioRuns)
{
    juce::ScopedJuceInitialiser_GUI juce;
    std::atomic<bool> plugged{true};
    std::atomic<int> sent{0};
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    ASSERT_TRUE(p.hidInput().setBackend(std::make_unique<FakeBackend>(
        rosin::hid::readBinary(ROSIN_HID_DATA "/huion_h640p_256c_006d_pen.rdesc.bin"), plugged, sent)));
    p.hidInput().rescanSeconds = 0.01;
    std::vector<juce::MemoryBlock> states(4);
    for (int i = 0; i < 4; ++i) {
        setChoice(p, "instrument", i);
        p.getStateInformation(states[static_cast<std::size_t>(i)]);
    }
    std::atomic<bool> done{false};
    std::atomic<long> blocksDone{0};
    std::atomic<bool> finite{true};
    std::thread audio([&] {
        juce::AudioBuffer<float> buffer(2, 256);
        int k = 0;
        while (!done.load()) {
            juce::MidiBuffer midi;
            midi.addEvent(juce::MidiMessage::noteOn(1 + k % 3, 40 + k % 30, 0.7f), 3);
            midi.addEvent(juce::MidiMessage::controllerEvent(1, 21, k % 128), 100);
            midi.addEvent(juce::MidiMessage::noteOff(1 + (k + 1) % 3, 40 + (k + 15) % 30), 200);
            p.setNonRealtime(k % 50 < 10);
            buffer.clear();
            p.processBlock(buffer, midi);
            for (int i = 0; i < 256; ++i)
                if (!std::isfinite(buffer.getSample(0, i))) finite = false;
            ++k;
            blocksDone.fetch_add(1);
        }
    });
    p.parameters().getParameter("hid_input")->setValueNotifyingHost(1.0f);
    // At least 3 s and 150 blocks (a loaded machine under ThreadSanitizer is slow), at most 30 s.
    const auto start = std::chrono::steady_clock::now();
    auto running = [&] {
        const auto t = std::chrono::steady_clock::now() - start;
        return t < std::chrono::seconds(3) || (blocksDone.load() < 150 && t < std::chrono::seconds(30));
    };
    for (int k = 0; running(); ++k) {
        const auto& s = states[static_cast<std::size_t>(k % 4)];
        p.setStateInformation(s.getData(), static_cast<int>(s.getSize()));
        p.loadMapping(k % 2 ? "keyboard" : "mpe");
        p.controllerMap().armLearn(static_cast<int>(engine::Param::BowPosition));
        p.parameters().getParameter("bow_force")->setValueNotifyingHost(static_cast<float>(k % 10) / 10.0f);
        if (k % 5 == 0) p.loadInstrument(RosinProcessor::instrumentNames()[k % 4], true);
        if (k % 7 == 0) plugged = !plugged.load();
        std::this_thread::sleep_for(std::chrono::milliseconds(7));
    }
    done = true;
    audio.join();
    p.parameters().getParameter("hid_input")->setValueNotifyingHost(0.0f);
    EXPECT_TRUE(finite.load());
    EXPECT_GT(blocksDone.load(), 100);
    EXPECT_GT(p.enginesInstalled(), 5);
}

namespace {
/// The rms of `count` blocks of the left channel, played as a host plays them, bypassed or not
/// (JUCE then calls processBlockBypassed); `firstHalfRms` takes the first block's first half.
double blocksRms(RosinProcessor& p, int count, bool bypassed, juce::MidiBuffer midi = {}, float* firstHalfRms = nullptr)
{
    juce::AudioBuffer<float> buffer(2, 256);
    double sum = 0.0;
    for (int b = 0; b < count; ++b) {
        buffer.clear();
        if (bypassed) p.processBlockBypassed(buffer, midi);
        else p.processBlock(buffer, midi);
        midi.clear();
        double half = 0.0;
        for (int i = 0; i < 256; ++i) {
            const double x = buffer.getSample(0, i);
            sum += x * x;
            if (i < 128) half += x * x;
        }
        if (b == 0 && firstHalfRms) *firstHalfRms = static_cast<float>(std::sqrt(half / 128.0));
    }
    return std::sqrt(sum / (count * 256.0));
}
} // namespace

// JUCE's default bypass drops the MIDI: a note released while the host bypassed Rosin sounded at
// full level for ever once the bypass ended (rms 0.13 in the headless host, both formats).
TEST(ProcessorBypass, ANoteReleasedWhileBypassedDoesNotSoundWhenTheBypassEnds)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    p.setNonRealtime(true);
    const double playing = blocksRms(p, 80, false, messages({juce::MidiMessage::noteOn(1, 45, 0.8f)}));
    ASSERT_GT(playing, 0.02);
    // The first bypassed block fades (10 ms = 480 samples) rather than cuts; then silence.
    float fadeStart = 0.0f;
    blocksRms(p, 2, true, {}, &fadeStart);
    EXPECT_GT(fadeStart, 0.2 * playing);
    EXPECT_EQ(blocksRms(p, 20, true, messages({juce::MidiMessage::noteOff(1, 45)})), 0.0);
    // Bypass off: the string was released while bypassed, so it has rung down (0.5 s after).
    blocks(p, 94);
    EXPECT_LT(blocksRms(p, 47, false), 1e-3);
    // A note held through the bypass plays on after it, and the next note plays.
    EXPECT_GT(blocksRms(p, 80, false, messages({juce::MidiMessage::noteOn(1, 50, 0.8f)})), 0.02);
    blocksRms(p, 40, true);
    EXPECT_GT(blocksRms(p, 40, false), 0.02);
}
