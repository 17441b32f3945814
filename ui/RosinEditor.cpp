#include "RosinEditor.h"

#include "../plugin/src/RosinProcessor.h"
#include "rosin/engine/Presets.h"

namespace rosin::ui {

RosinEditor::RosinEditor(plugin::RosinProcessor& processor)
    : AudioProcessorEditor(processor), processor_(processor), generic_(processor)
{
    addAndMakeVisible(generic_);
    addPresetPicker(exciter_, "exciters", "Exciter preset...", [this](const juce::String& n) { processor_.loadExciter(n); });
    addPresetPicker(mapping_, "mappings", "Controller map...", [this](const juce::String& n) { processor_.loadMapping(n); });
    addPresetPicker(controller_, "controllers", "HID controller map...",
                    [this](const juce::String& n) { processor_.loadHidMapping(n); });
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

void RosinEditor::addPresetPicker(juce::ComboBox& box, const std::string& kind, const juce::String& prompt,
                                  std::function<void(const juce::String&)> load)
{
    box.setTextWhenNothingSelected(prompt);
    int id = 1;
    for (const auto& name : engine::listPresets(engine::presetDirectory(), kind)) box.addItem(name, id++);
    box.onChange = [this, &box, load = std::move(load)] {
        try {
            load(box.getText());
        } catch (const std::exception& e) { // a broken preset file: say which, keep playing
            status_.setText(e.what(), juce::dontSendNotification);
        }
    };
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
