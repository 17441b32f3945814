// The plugin window: instrument and preset browser, the bow and the rosin in physical units,
// the MIDI/HID mapping panel with learn, live physics views, and a keyboard to play from.
// Resizable; every size (text included) follows the window, and hosts' scale factors apply.
#pragma once
#include <juce_audio_processors/juce_audio_processors.h>
#include <juce_audio_utils/juce_audio_utils.h>

#include <memory>
#include <vector>

#include "LiveViews.h"

namespace rosin::plugin { class RosinProcessor; }

namespace rosin::ui {

/// Colours and a font size that follows the window.
class RosinLook : public juce::LookAndFeel_V4 {
public:
    RosinLook();
    float fontSize = 14.0f;
    juce::Font getLabelFont(juce::Label&) override { return juce::Font(fontSize); }
    juce::Font getComboBoxFont(juce::ComboBox&) override { return juce::Font(fontSize); }
    juce::Font getPopupMenuFont() override { return juce::Font(fontSize); }
    juce::Font getTextButtonFont(juce::TextButton&, int) override { return juce::Font(fontSize); }
    juce::Label* createSliderTextBox(juce::Slider& s) override;
};

class RosinEditor : public juce::AudioProcessorEditor, private juce::Timer, private juce::MidiKeyboardState::Listener {
public:
    explicit RosinEditor(plugin::RosinProcessor& owner);
    ~RosinEditor() override;
    void resized() override;
    void paint(juce::Graphics& g) override;

    static constexpr int defaultWidth = 1100, defaultHeight = 740, minWidth = 820, minHeight = 560;
    /// Smallest text on screen in logical pixels (a host's scale factor multiplies it).
    float smallestTextHeight() const;
    LiveViews& views() noexcept { return views_; }
    juce::MidiKeyboardComponent& keyboard() noexcept { return keyboard_; }
    juce::MidiKeyboardState& keyboardState() noexcept { return keyboardState_; }

private:
    struct ParamSlider {
        std::unique_ptr<juce::Label> label;
        std::unique_ptr<juce::Slider> slider;
        std::unique_ptr<juce::AudioProcessorValueTreeState::SliderAttachment> attachment;
    };
    struct ParamChoice {
        std::unique_ptr<juce::Label> label;
        std::unique_ptr<juce::ComboBox> box;
        std::unique_ptr<juce::AudioProcessorValueTreeState::ComboBoxAttachment> attachment;
    };
    void timerCallback() override;
    void handleNoteOn(juce::MidiKeyboardState*, int channel, int note, float velocity) override;
    void handleNoteOff(juce::MidiKeyboardState*, int channel, int note, float velocity) override;
    void refreshStatus();
    void addPresetPicker(juce::ComboBox& box, const std::string& kind, const juce::String& prompt,
                         std::function<void(const juce::String&)> load);
    ParamSlider& addSlider(const char* id, const juce::String& text, const juce::String& suffix, int decimals);
    ParamChoice& addChoice(const char* id, const juce::String& text);
    void showAllParameters(bool on);

    plugin::RosinProcessor& processor_;
    RosinLook look_;
    juce::Label title_, bowHeading_, rosinHeading_, playHeading_, mappingHeading_, status_;
    juce::ComboBox exciter_, mapping_, controller_, learn_, mapKind_;
    juce::TextButton clearMappings_{"Clear learned"}, allParams_{"All parameters"};
    std::vector<std::unique_ptr<ParamSlider>> sliders_;
    std::vector<std::unique_ptr<ParamChoice>> choices_;
    ParamChoice* instrument_ = nullptr;
    LiveViews views_;
    juce::MidiKeyboardState keyboardState_;
    juce::MidiKeyboardComponent keyboard_{keyboardState_, juce::MidiKeyboardComponent::horizontalKeyboard};
    std::unique_ptr<juce::GenericAudioProcessorEditor> generic_;
    juce::String lastStatus_;
};

} // namespace rosin::ui
