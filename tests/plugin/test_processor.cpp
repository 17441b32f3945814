// The JUCE processor itself, in-process: what a host cannot reach from outside (MIDI learn
// driven by the editor, mapping and exciter presets) and how it lands in the saved state.
#include <gtest/gtest.h>

#include "RosinProcessor.h"
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
    ASSERT_EQ(a.controllerMap().get(21).param, static_cast<int>(engine::Param::BowPosition));

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
}

TEST(Processor, LoadingAnInstrumentPresetSetsItsBowDefaults)
{
    juce::ScopedJuceInitialiser_GUI juce;
    RosinProcessor p;
    p.setPlayConfigDetails(0, 2, 48000.0, 256);
    p.prepareToPlay(48000.0, 256);
    p.loadInstrument("double-bass", true);
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("bow_force")->load(), 1.5f);
    EXPECT_FLOAT_EQ(p.parameters().getRawParameterValue("rosin_tg")->load(), 16.0f);
    EXPECT_EQ(p.currentInstrument(), "double-bass");
    play(p, {juce::MidiMessage::noteOn(1, 40, 0.8f)}, 8);
    EXPECT_EQ(p.activeVoices(), 1);
}
