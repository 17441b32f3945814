#include "RosinEditor.h"

#include "RosinProcessor.h"
#include "rosin/engine/Presets.h"

namespace rosin::ui {

RosinLook::RosinLook()
{
    // Dark like the views; warm accents like rosin.
    setColourScheme({0xff17171a, 0xff202024, 0xff26262b, 0xff55555c, 0xffece6dc, 0xff2c2c31, 0xffece6dc, 0xffd9a443, 0xffece6dc});
    setColour(juce::Slider::thumbColourId, juce::Colour(0xffd9a443));
    setColour(juce::Slider::trackColourId, juce::Colour(0xff8a6a30));
}

juce::Label* RosinLook::createSliderTextBox(juce::Slider& s)
{
    auto* l = LookAndFeel_V4::createSliderTextBox(s);
    l->setFont(juce::Font(fontSize));
    return l;
}

RosinEditor::RosinEditor(plugin::RosinProcessor& owner)
    : AudioProcessorEditor(owner), processor_(owner), views_(owner)
{
    setLookAndFeel(&look_);
    title_.setText("Rosin", juce::dontSendNotification);
    title_.setColour(juce::Label::textColourId, juce::Colour(0xffd9a443));
    for (auto* h : {&title_, &bowHeading_, &rosinHeading_, &playHeading_, &mappingHeading_, &status_}) addAndMakeVisible(h);
    bowHeading_.setText("Bow", juce::dontSendNotification);
    rosinHeading_.setText("Rosin and contact", juce::dontSendNotification);
    playHeading_.setText("Playing", juce::dontSendNotification);
    mappingHeading_.setText("MIDI / HID mapping", juce::dontSendNotification);
    status_.setJustificationType(juce::Justification::topLeft);
    status_.setMinimumHorizontalScale(1.0f);

    instrument_ = &addChoice(plugin::RosinProcessor::instrumentParamId, "Instrument");
    addPresetPicker(exciter_, "exciters", "Exciter preset", [this](const juce::String& n) { processor_.loadExciter(n); });
    addPresetPicker(mapping_, "mappings", "Controller map", [this](const juce::String& n) { processor_.loadMapping(n); });
    addPresetPicker(controller_, "controllers", "HID device map", [this](const juce::String& n) { processor_.loadHidMapping(n); });

    // The parameters' own text carries the units (N, m/s, C).
    addSlider("bow_force", "Force", "", 2);
    addSlider("bow_speed", "Speed", "", 3);
    addSlider("bow_position", juce::String::fromUTF8("Position \u03B2"), "", 3);
    addSlider("attack_accel", "Attack accel.", "", 2);
    addChoice("friction_model", "Model");
    addChoice("contact_law", "Contact");
    addSlider("rosin_tg", "Rosin Tg", "", 1);
    addSlider("ambient", "Ambient", "", 1);
    addSlider("footprint_ratio", "Footprint r_A", "", 2);
    addChoice("articulation", "Articulation");
    addChoice(plugin::RosinProcessor::hidParamId, "HID input");

    learn_.setTextWhenNothingSelected("MIDI learn...");
    for (int i = 0; i < engine::paramCount; ++i) {
        const auto& info = engine::paramInfo(i);
        if (info.steps == 0) learn_.addItem(juce::String(info.name.data(), info.name.size()), i + 1);
    }
    learn_.onChange = [this] {
        if (learn_.getSelectedId() > 0) processor_.controllerMap().armLearn(learn_.getSelectedId() - 1);
    };
    clearMappings_.onClick = [this] { processor_.controllerMap().assign({}); };
    mapKind_.addItem(juce::String::fromUTF8("Schelleng map (\u03B2 vs force)"), 1);
    mapKind_.addItem("Guettler map (attack vs force)", 2);
    mapKind_.setSelectedId(1, juce::dontSendNotification);
    mapKind_.onChange = [this] { views_.setMapKind(mapKind_.getSelectedId() == 2 ? lab::MapKind::Guettler : lab::MapKind::Schelleng); };
    allParams_.setClickingTogglesState(true);
    allParams_.onClick = [this] { showAllParameters(allParams_.getToggleState()); };
    for (juce::Component* c : std::initializer_list<juce::Component*>{&exciter_, &mapping_, &controller_, &learn_, &clearMappings_,
                                                                      &mapKind_, &allParams_, &views_, &keyboard_})
        addAndMakeVisible(c);

    keyboardState_.addListener(this);
    keyboard_.setAvailableRange(24, 108);
    keyboard_.setLowestVisibleKey(36);

    setResizable(true, true);
    setResizeLimits(minWidth, minHeight, 2400, 1600);
    if (auto* c = getConstrainer()) c->setMinimumOnscreenAmounts(50, 50, 50, 50);
    setSize(defaultWidth, defaultHeight);
    startTimerHz(8);
}

RosinEditor::~RosinEditor()
{
    keyboardState_.removeListener(this);
    setLookAndFeel(nullptr);
}

RosinEditor::ParamSlider& RosinEditor::addSlider(const char* id, const juce::String& text, const juce::String& suffix, int decimals)
{
    auto p = std::make_unique<ParamSlider>();
    p->label = std::make_unique<juce::Label>(juce::String(), text);
    p->slider = std::make_unique<juce::Slider>(juce::Slider::LinearHorizontal, juce::Slider::TextBoxRight);
    p->slider->setTextValueSuffix(suffix);
    p->attachment = std::make_unique<juce::AudioProcessorValueTreeState::SliderAttachment>(processor_.parameters(), id, *p->slider);
    p->slider->setNumDecimalPlacesToDisplay(decimals);
    addAndMakeVisible(*p->label);
    addAndMakeVisible(*p->slider);
    sliders_.push_back(std::move(p));
    return *sliders_.back();
}

RosinEditor::ParamChoice& RosinEditor::addChoice(const char* id, const juce::String& text)
{
    auto p = std::make_unique<ParamChoice>();
    p->label = std::make_unique<juce::Label>(juce::String(), text);
    p->box = std::make_unique<juce::ComboBox>();
    // The engine's choices without their spare slots (Parameters.h); the plugin's own ones as they are.
    if (const int index = engine::paramIndex(id); index >= 0) {
        int item = 1;
        for (const auto& name : engine::choiceNames(static_cast<engine::Param>(index))) p->box->addItem(name, item++);
    } else if (auto* param = dynamic_cast<juce::AudioParameterChoice*>(processor_.parameters().getParameter(id))) {
        p->box->addItemList(param->choices, 1);
    }
    p->attachment = std::make_unique<juce::AudioProcessorValueTreeState::ComboBoxAttachment>(processor_.parameters(), id, *p->box);
    addAndMakeVisible(*p->label);
    addAndMakeVisible(*p->box);
    choices_.push_back(std::move(p));
    return *choices_.back();
}

void RosinEditor::addPresetPicker(juce::ComboBox& box, const std::string& kind, const juce::String& prompt,
                                  std::function<void(const juce::String&)> load)
{
    box.setTextWhenNothingSelected(prompt);
    int id = 1;
    for (const auto& name : processor_.presetLibrary().list(kind)) box.addItem(name, id++);
    box.onChange = [this, &box, load = std::move(load)] {
        try {
            load(box.getText());
        } catch (const std::exception& e) { // a broken preset file: say which, keep playing
            status_.setText(e.what(), juce::dontSendNotification);
        }
    };
}

void RosinEditor::showAllParameters(bool on)
{
    if (on && !generic_) {
        generic_ = std::make_unique<juce::GenericAudioProcessorEditor>(processor_);
        addAndMakeVisible(*generic_);
    }
    if (generic_) generic_->setVisible(on);
    views_.setVisible(!on);
    resized();
}

float RosinEditor::smallestTextHeight() const
{
    return std::min(look_.fontSize, static_cast<float>(views_.fontSize()) * 0.85f); // tick labels are 0.85 of the views' size
}

void RosinEditor::paint(juce::Graphics& g)
{
    g.fillAll(juce::Colour(0xff111113));
    g.setColour(juce::Colour(0xff1c1c20));
    g.fillRect(sliders_.front()->label->getBounds().getUnion(status_.getBounds()).withX(0).expanded(0, 8));
}

void RosinEditor::resized()
{
    // One row height drives every size: text grows and shrinks with the window.
    const int row = juce::jlimit(24, 44, juce::jmin(getHeight() / 26, getWidth() / 40));
    look_.fontSize = static_cast<float>(row) * 0.58f;
    auto area = getLocalBounds().reduced(row / 4);

    auto top = area.removeFromTop(row + 4);
    title_.setFont(juce::Font(look_.fontSize * 1.4f, juce::Font::bold));
    title_.setBounds(top.removeFromLeft(row * 4));
    instrument_->label->setBounds(top.removeFromLeft(row * 4));
    const int picker = (top.getWidth() - row * 5) / 4;
    instrument_->box->setBounds(top.removeFromLeft(picker).reduced(2));
    exciter_.setBounds(top.removeFromLeft(picker).reduced(2));
    mapping_.setBounds(top.removeFromLeft(picker).reduced(2));
    controller_.setBounds(top.removeFromLeft(picker).reduced(2));
    allParams_.setBounds(top.reduced(2));
    area.removeFromTop(row / 4);

    keyboard_.setBounds(area.removeFromBottom(juce::jmax(48, row * 2)).withTrimmedRight(18)); // clear of the resize corner
    keyboard_.setKeyWidth(juce::jmax(12.0f, static_cast<float>(keyboard_.getWidth()) / 52.0f));
    area.removeFromBottom(row / 4);

    auto side = area.removeFromLeft(juce::jlimit(row * 11, row * 16, area.getWidth() * 34 / 100));
    area.removeFromLeft(row / 3);
    const auto place = [&](juce::Component& label, juce::Component& control) {
        auto r = side.removeFromTop(row);
        label.setBounds(r.removeFromLeft(r.getWidth() * 36 / 100));
        control.setBounds(r.reduced(0, 2));
        if (auto* s = dynamic_cast<juce::Slider*>(&control)) s->setTextBoxStyle(juce::Slider::TextBoxRight, false, row * 4, row - 4);
    };
    const auto heading = [&](juce::Label& l) {
        l.setFont(juce::Font(look_.fontSize, juce::Font::bold));
        l.setBounds(side.removeFromTop(row));
    };
    const auto slider = [&](int i) { place(*sliders_[static_cast<std::size_t>(i)]->label, *sliders_[static_cast<std::size_t>(i)]->slider); };
    const auto choice = [&](int i) { place(*choices_[static_cast<std::size_t>(i)]->label, *choices_[static_cast<std::size_t>(i)]->box); };
    heading(bowHeading_);
    for (int i = 0; i < 4; ++i) slider(i);
    heading(rosinHeading_);
    choice(1);
    choice(2);
    for (int i = 4; i < 7; ++i) slider(i);
    heading(playHeading_);
    choice(3);
    mapKind_.setBounds(side.removeFromTop(row).reduced(0, 2));
    heading(mappingHeading_);
    {
        auto r = side.removeFromTop(row);
        clearMappings_.setBounds(r.removeFromRight(r.getWidth() * 40 / 100).reduced(2, 2));
        learn_.setBounds(r.reduced(0, 2));
    }
    choice(4);
    status_.setBounds(side);
    for (auto* l : {&bowHeading_, &rosinHeading_, &playHeading_, &mappingHeading_, &status_}) l->setFont(juce::Font(look_.fontSize, l == &status_ ? juce::Font::plain : juce::Font::bold));
    for (auto& s : sliders_) s->label->setFont(juce::Font(look_.fontSize));
    for (auto& c : choices_) c->label->setFont(juce::Font(look_.fontSize));
    instrument_->label->setJustificationType(juce::Justification::centredRight);

    views_.setBounds(area);
    if (generic_) generic_->setBounds(area);
}

void RosinEditor::handleNoteOn(juce::MidiKeyboardState*, int channel, int note, float velocity)
{
    const std::uint8_t m[3] = {static_cast<std::uint8_t>(0x90 | ((channel - 1) & 15)), static_cast<std::uint8_t>(note),
                               static_cast<std::uint8_t>(juce::jlimit(1, 127, juce::roundToInt(velocity * 127.0f)))};
    processor_.pushUiMidi(m, 3);
}

void RosinEditor::handleNoteOff(juce::MidiKeyboardState*, int channel, int note, float)
{
    const std::uint8_t m[3] = {static_cast<std::uint8_t>(0x80 | ((channel - 1) & 15)), static_cast<std::uint8_t>(note), 0};
    processor_.pushUiMidi(m, 3);
}

void RosinEditor::timerCallback()
{
    if (processor_.controllerMap().learning() < 0 && learn_.getSelectedId() > 0)
        learn_.setSelectedId(0, juce::dontSendNotification);
    refreshStatus();
}

void RosinEditor::refreshStatus()
{
    juce::String text = processor_.currentInstrument() + ", " + juce::String(processor_.activeVoices()) + " voices sounding\nHID: " +
                        juce::String(processor_.hidInput().status()) + (processor_.hidInput().hotplug() ? " (hot-plug)" : "") + "\n";
    // Per device: what it is, and what stands in the way (for a missing permission, the line
    // to add to /etc/udev/rules.d/70-rosin-hid.rules).
    for (const auto& d : processor_.hidInput().devices()) {
        if (d.state == hid::DeviceStatus::State::Unsupported || d.state == hid::DeviceStatus::State::NotABow) continue;
        text << "  " << juce::String(d.name) << ": " << hid::stateName(d.state);
        if (!d.kind.empty()) text << " (" << juce::String(d.kind) << ")";
        if (!d.detail.empty()) text << juce::String::fromUTF8(" \u2014 ") << juce::String(d.detail).trim().fromLastOccurrenceOf("\n", false, false);
        text << "\n";
    }
    text << "Learned: ";
    const auto entries = processor_.controllerMap().entries();
    if (entries.empty()) text << "none";
    for (const auto& e : entries) {
        const auto& info = engine::paramInfo(e.param);
        text << "CC" << e.cc << juce::String::fromUTF8(" \u2192 ") << juce::String(info.name.data(), info.name.size()) << "  ";
    }
    if (text != lastStatus_) {
        lastStatus_ = text;
        status_.setText(text, juce::dontSendNotification);
    }
}

} // namespace rosin::ui
