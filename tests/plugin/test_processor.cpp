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
    blockRms(p, 10); // the body's own modes ring on for a few ms after the string is free
    EXPECT_LT(blockRms(p, 10), 1e-6);

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
