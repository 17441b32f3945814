#include "RosinEditor.h"

#include "../plugin/src/RosinProcessor.h"
#include "rosin/engine/Presets.h"

namespace rosin::ui {

RosinEditor::RosinEditor(plugin::RosinProcessor& processor)
    : AudioProcessorEditor(processor), processor_(processor), generic_(processor)
{
    addAndMakeVisible(generic_);
    const auto dir = engine::presetDirectory();
    int id = 1;
    exciter_.setTextWhenNothingSelected("Exciter preset...");
    for (const auto& name : engine::listPresets(dir, "exciters")) exciter_.addItem(name, id++);
    exciter_.onChange = [this] {
        try {
            processor_.loadExciter(exciter_.getText());
        } catch (const std::exception& e) {
            status_.setText(e.what(), juce::dontSendNotification);
        }
    };
    id = 1;
    mapping_.setTextWhenNothingSelected("Controller map...");
    for (const auto& name : engine::listPresets(dir, "mappings")) mapping_.addItem(name, id++);
    mapping_.onChange = [this] {
        try {
            processor_.loadMapping(mapping_.getText());
        } catch (const std::exception& e) {
            status_.setText(e.what(), juce::dontSendNotification);
        }
    };
    id = 1;
    controller_.setTextWhenNothingSelected("HID controller map...");
    for (const auto& name : engine::listPresets(dir, "controllers")) controller_.addItem(name, id++);
    controller_.onChange = [this] {
        try {
            processor_.loadHidMapping(controller_.getText());
        } catch (const std::exception& e) {
            status_.setText(e.what(), juce::dontSendNotification);
        }
    };
    learn_.setTextWhenNothingSelected("MIDI learn: pick a parameter, move a controller");
    for (int i = 0; i < engine::paramCount; ++i) {
        const auto& info = engine::paramInfo(i);
        if (info.steps == 0) learn_.addItem(juce::String(info.name.data(), info.name.size()), i + 1);
    }
    learn_.onChange = [this] {
        if (learn_.getSelectedId() > 0) processor_.controllerMap().armLearn(learn_.getSelectedId() - 1);
    };
    clearMappings_.onClick = [this] { processor_.controllerMap().assign({}); };
    for (auto* c : std::initializer_list<juce::Component*>{&exciter_, &mapping_, &controller_, &learn_, &clearMappings_, &status_})
        addAndMakeVisible(c);
    setResizable(true, true);
    setSize(640, 720);
    startTimerHz(10);
}

void RosinEditor::paint(juce::Graphics& g) { g.fillAll(getLookAndFeel().findColour(juce::ResizableWindow::backgroundColourId)); }

void RosinEditor::resized()
{
    auto area = getLocalBounds().reduced(6);
    auto row = area.removeFromTop(28);
    const int third = row.getWidth() / 3;
    exciter_.setBounds(row.removeFromLeft(third).reduced(2));
    mapping_.setBounds(row.removeFromLeft(third).reduced(2));
    controller_.setBounds(row.reduced(2));
    row = area.removeFromTop(28);
    clearMappings_.setBounds(row.removeFromRight(130).reduced(2));
    learn_.setBounds(row.reduced(2));
    status_.setBounds(area.removeFromBottom(48));
    generic_.setBounds(area);
}

void RosinEditor::timerCallback()
{
    if (processor_.controllerMap().learning() < 0 && learn_.getSelectedId() > 0)
        learn_.setSelectedId(0, juce::dontSendNotification);
    refreshMappings();
}

void RosinEditor::refreshMappings()
{
    juce::String text = processor_.currentInstrument() + ", " + juce::String(processor_.activeVoices()) + " voices. HID: " +
                        juce::String(processor_.hidInput().status()) + ". Learned: ";
    const auto entries = processor_.controllerMap().entries();
    if (entries.empty()) text << "none";
    for (const auto& e : entries) {
        const auto& info = engine::paramInfo(e.param);
        text << "CC" << e.cc << " -> " << juce::String(info.name.data(), info.name.size()) << "  ";
    }
    if (text != lastMappings_) {
        lastMappings_ = text;
        status_.setText(text, juce::dontSendNotification);
    }
}

} // namespace rosin::ui
