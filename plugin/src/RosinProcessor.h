// The JUCE AudioProcessor: host parameters, MIDI, state and presets around engine::Synth.
//
// Threads. The audio thread owns the current Synth. A new Synth (other instrument or rate)
// is built off the audio thread and handed over through one atomic pointer; the audio thread
// swaps it in at the top of a block, fades the old one out over a few milliseconds and gives
// it back through an SPSC queue, to be freed by the loader thread. Parameters are the host's
// atomics; MIDI-learn slots are single-word atomics (engine::ControllerMap).
#pragma once
#include <juce_audio_processors/juce_audio_processors.h>
#include <juce_audio_utils/juce_audio_utils.h>

#include <array>
#include <atomic>
#include <memory>
#include <mutex>

#include "rosin/presets/Library.h"
#include "rosin/rt/SpscQueue.h"
#include "rosin/engine/ControllerMap.h"
#include "rosin/engine/Synth.h"
#include "rosin/engine/ViewTap.h"
#include "rosin/hid/HidInput.h"

namespace rosin::plugin {

class RosinProcessor : public juce::AudioProcessor {
public:
    static constexpr const char* instrumentParamId = "instrument";
    static constexpr const char* hidParamId = "hid_input";
    static const juce::StringArray& instrumentNames();

    RosinProcessor();
    ~RosinProcessor() override;

    void prepareToPlay(double sampleRate, int maximumExpectedSamplesPerBlock) override;
    void releaseResources() override;
    bool isBusesLayoutSupported(const BusesLayout& layouts) const override;
    void processBlock(juce::AudioBuffer<float>&, juce::MidiBuffer&) override;
    using AudioProcessor::processBlock;

    juce::AudioProcessorEditor* createEditor() override;
    bool hasEditor() const override { return true; }

    const juce::String getName() const override { return "Rosin"; }
    bool acceptsMidi() const override { return true; }
    bool producesMidi() const override { return false; }
    bool isMidiEffect() const override { return false; }
    double getTailLengthSeconds() const override { return 2.0; }

    int getNumPrograms() override { return 1; }
    int getCurrentProgram() override { return 0; }
    void setCurrentProgram(int) override {}
    const juce::String getProgramName(int) override { return "Default"; }
    void changeProgramName(int, const juce::String&) override {}

    void getStateInformation(juce::MemoryBlock& destData) override;
    void setStateInformation(const void* data, int sizeInBytes) override;

    /// [any thread but audio] Load an instrument preset by name; applyDefaults also sets the
    /// bow parameters and rosin the preset suggests. Throws std::runtime_error on a bad file.
    void loadInstrument(const juce::String& name, bool applyDefaults);
    void loadExciter(const juce::String& name);
    void loadMapping(const juce::String& name);

    /// [any thread but audio] A controller map from presets/controllers (rosin-hid/1).
    void loadHidMapping(const juce::String& name);
    /// The HID controller input (its thread starts when the hid_input parameter is on).
    hid::HidInput& hidInput() noexcept { return *hid_; }

    /// The one preset lookup (factory set compiled in, then user folders): the editor asks here.
    const presets::Library& presetLibrary() const noexcept { return library_; }
    juce::AudioProcessorValueTreeState& parameters() noexcept { return state_; }
    engine::ControllerMap& controllerMap() noexcept { return map_; }
    juce::String currentInstrument() const;
    engine::ParamValues currentParams() const; ///< [any thread] the host parameters in engine units
    int activeVoices() const noexcept { return activeVoices_.load(std::memory_order_relaxed); }

    /// The live views' channel: the audio thread writes frames of the newest note while the
    /// editor listens (ViewRing::setListening); the editor's timer reads them.
    engine::ViewRing& viewRing() noexcept { return *viewRing_; }
    double currentSampleRate() const noexcept { return sampleRate_.load(std::memory_order_relaxed); }
    /// [message thread] A note from the window's keyboard: queued, played at the next block's start.
    bool pushUiMidi(const std::uint8_t* data, int size) noexcept;

private:
    class Loader;
    static juce::AudioProcessorValueTreeState::ParameterLayout createLayout();
    std::unique_ptr<engine::Synth> buildSynth(const engine::InstrumentPreset& preset, double sampleRate, int tag);
    void handOver(std::unique_ptr<engine::Synth> synth);
    void collectGarbage();
    void setPhysical(engine::Param p, double value); ///< [not audio] a parameter by its value in the engine's units
    void pollHid(); ///< [loader thread] start or stop the HID input with its parameter
    void drainHid(engine::Synth& synth) noexcept;
    void renderSynth(engine::Synth& synth, juce::AudioBuffer<float>& buffer, const juce::MidiBuffer* midi,
                     bool pushParams) noexcept;

    juce::AudioProcessorValueTreeState state_;
    engine::ControllerMap map_;
    std::array<std::atomic<float>*, engine::paramCount> raw_{};
    std::array<float, engine::paramCount> pushed_{};
    std::atomic<float>* instrumentRaw_ = nullptr;
    std::atomic<float>* hidRaw_ = nullptr;
    std::unique_ptr<hid::HidInput> hid_;
    engine::ExternalBow external_; ///< [audio thread] the controller's bow, re-applied after an engine swap

    // Audio-thread owned.
    engine::Synth* current_ = nullptr;
    engine::Synth* retiring_ = nullptr;
    int retiringLeft_ = 0;
    juce::AudioBuffer<float> fadeBuffer_;
    static constexpr int fadeSamples = 512;

    // Crossing threads.
    std::unique_ptr<engine::ViewRing> viewRing_ = std::make_unique<engine::ViewRing>(1u << 15);
    struct UiMidi {
        std::array<std::uint8_t, 3> bytes{};
        int size = 0;
    };
    rt::SpscQueue<UiMidi, 256> uiMidi_;
    std::atomic<engine::Synth*> pending_{nullptr};
    rt::SpscQueue<engine::Synth*, 16> trash_;
    std::atomic<double> sampleRate_{0.0};
    std::atomic<int> loadedInstrument_{-1};   ///< index of the instrument whose Synth is installed or pending
    int installedInstrument_ = -1;            ///< [audio thread] index of current_'s instrument
    std::atomic<int> activeVoices_{0};

    mutable std::mutex loadMutex_; ///< serialises loaders (never taken on the audio thread)
    juce::String instrumentName_{"cello"};
    std::unique_ptr<Loader> loader_;
    const presets::Library library_ = presets::Library::standard(); ///< factory set + user folders, fixed at construction

    JUCE_DECLARE_NON_COPYABLE_WITH_LEAK_DETECTOR(RosinProcessor)
};

} // namespace rosin::plugin
