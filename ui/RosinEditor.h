// The plugin window for now: every parameter (JUCE's generic editor), preset pickers and
// MIDI learn. The full editor with live physics views is issue 7.
#pragma once
#include <juce_audio_processors/juce_audio_processors.h>
#include <juce_audio_utils/juce_audio_utils.h>

namespace rosin::plugin { class RosinProcessor; }

namespace rosin::ui {

class RosinEditor : public juce::AudioProcessorEditor, private juce::Timer {
public:
    explicit RosinEditor(plugin::RosinProcessor& processor);
    void resized() override;
    void paint(juce::Graphics& g) override;

private:
    void timerCallback() override;
    void refreshMappings();
    void addPresetPicker(juce::ComboBox& box, const std::string& kind, const juce::String& prompt,
                         std::function<void(const juce::String&)> load);

    plugin::RosinProcessor& processor_;
    juce::GenericAudioProcessorEditor generic_;
    juce::ComboBox exciter_, mapping_, controller_, learn_;
    juce::TextButton clearMappings_{"Clear mappings"};
    juce::Label status_;
    juce::String lastMappings_;
};

} // namespace rosin::ui
