// The JUCE AudioProcessor: host parameters, the parameter layer's sources (MIDI, the window's
// keyboard, HID), state and presets around engine::Synth.
//
// Threads and the only channels between them:
// - The audio thread owns the playing Synth, the Performance (what the player holds, zones,
//   pedal: it outlives engines) and the MIDI decoder. A new Synth (another instrument or rate)
//   is built off the audio thread and handed over with rt::Handoff; the audio thread swaps it in
//   at the top of a block, fades the old one out and retires it.
// - The housekeeping thread ("loader") builds engines when the instrument parameter moves, frees
//   what the audio thread retired (the only consumer of the retire queues), moves host
//   parameters for learned controllers and keyswitches, and records completed MIDI-learns.
// - SPSC queues: window keyboard -> audio; audio -> housekeeping (parameter changes, learns);
//   HID thread -> audio (events).
#pragma once
#include <juce_audio_processors/juce_audio_processors.h>
#include <juce_audio_utils/juce_audio_utils.h>

#include <array>
#include <atomic>
#include <memory>
#include <mutex>

#include "rosin/engine/ControllerMap.h"
#include "rosin/engine/MidiDecoder.h"
#include "rosin/engine/Performance.h"
#include "rosin/engine/Synth.h"
#include "rosin/engine/ViewTap.h"
#include "rosin/hid/HidInput.h"
#include "rosin/presets/Library.h"
#include "rosin/rt/Handoff.h"
#include "rosin/rt/SpscQueue.h"

namespace rosin::plugin {

class RosinProcessor : public juce::AudioProcessor {
public:
    static constexpr const char* instrumentParamId = "instrument";
    static constexpr const char* hidParamId = "hid_input";
    /// The state's version: written on save, checked on load (older ones are migrated).
    static constexpr int stateVersion = 2;
    static const juce::StringArray& instrumentNames();

    RosinProcessor();
    ~RosinProcessor() override;

    void prepareToPlay(double sampleRate, int maximumExpectedSamplesPerBlock) override;
    void releaseResources() override;
    bool isBusesLayoutSupported(const BusesLayout& layouts) const override;
    void processBlock(juce::AudioBuffer<float>&, juce::MidiBuffer&) override;
    using AudioProcessor::processBlock;
    /// The host's bypass. JUCE's default drops the MIDI, so a note released while bypassed
    /// sounded on for ever once the bypass ended; Rosin keeps following the keys and fades its
    /// output out (and in again after) over swapFadeSeconds, at the cost of its CPU while bypassed.
    void processBlockBypassed(juce::AudioBuffer<float>&, juce::MidiBuffer&) override;
    using AudioProcessor::processBlockBypassed;

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
    /// The last state that could not be loaded, in words ("" when the last one loaded).
    juce::String lastStateProblem() const;

    /// [any thread but audio] Load an instrument preset by name; applyDefaults also sets the
    /// bow parameters and rosin the preset suggests. Throws presets::PresetError on a bad file.
    void loadInstrument(const juce::String& name, bool applyDefaults);
    void loadExciter(const juce::String& name);
    void loadMapping(const juce::String& name);

    /// [any thread but audio] A controller map from the presets' controllers (rosin-hid/2 or 1).
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
    /// How many engines have been installed (a rebuild is one more): for tests and diagnostics.
    int enginesInstalled() const noexcept { return enginesInstalled_.load(std::memory_order_relaxed); }
    /// [audio thread, or a test between blocks] What the player holds, and the MIDI decoder.
    const engine::Performance& performance() const noexcept { return performance_; }
    const engine::MidiDecoder& decoder() const noexcept { return decoder_; }
    /// [audio thread, or a test between blocks] A parameter as the playing engine has it (engine units).
    float engineParameter(engine::Param p) const noexcept;

    /// The live views' channel: the audio thread writes frames of the newest note while the
    /// editor listens (ViewRing::setListening); the editor's timer reads them.
    engine::ViewRing& viewRing() noexcept { return *viewRing_; }
    double currentSampleRate() const noexcept { return sampleRate_.load(std::memory_order_relaxed); }
    /// [message thread] A note from the window's keyboard: queued, played at the next block's start.
    bool pushUiMidi(const std::uint8_t* data, int size) noexcept;

private:
    class Loader;
    struct HostChange {
        int param = -1;
        float value = 0.0f;            ///< engine units
        std::uint32_t generation = 0;  ///< the state it was made on (stateGeneration_)
    };
    struct Learn {
        int cc = -1, param = -1;
    };

    static juce::AudioProcessorValueTreeState::ParameterLayout createLayout();
    std::unique_ptr<engine::Synth> buildSynth(const presets::InstrumentPreset& preset, double sampleRate, int tag);
    void setPhysical(engine::Param p, double value); ///< [not audio] a parameter by its value in the engine's units
    void housekeeping(); ///< [loader thread] free retired objects, move host parameters, record learns
    void pollHid();      ///< [loader thread] start or stop the HID input with its parameter
    void swapEngine() noexcept;
    void process(juce::AudioBuffer<float>& buffer, juce::MidiBuffer& midi, bool bypassed);
    void gatherEvents(const juce::MidiBuffer& midi, int numSamples) noexcept;
    void hidEvents(int numSamples) noexcept;
    void renderCurrent(float* left, float* right, int from, int to) noexcept;
    int wantedInstrument() const noexcept; ///< the instrument parameter, as an index
    /// [housekeeping thread] Builds the instrument the parameter names when it moved.
    void followInstrumentParameter();
    void loadInstrumentLocked(const juce::String& name, bool applyDefaults); ///< loadMutex_ held
    void addEvent(const engine::ControlEvent& e) noexcept;
    void handle(engine::Synth& synth, const engine::ControlEvent& e) noexcept;
    void pushParameters(engine::Synth& synth, bool all) noexcept;

    juce::AudioProcessorValueTreeState state_;
    const presets::Library library_ = presets::Library::standard(); ///< factory set + user folders, fixed at construction
    engine::ControllerMap map_;
    std::array<std::atomic<float>*, engine::paramCount> raw_{};
    std::array<float, engine::paramCount> pushed_{};
    std::atomic<float>* instrumentRaw_ = nullptr;
    std::atomic<float>* hidRaw_ = nullptr;
    std::unique_ptr<hid::HidInput> hid_;

    // Audio-thread owned.
    engine::Synth* current_ = nullptr;
    engine::Synth* retiring_ = nullptr;
    int retiringLeft_ = 0, fadeLength_ = 480;
    float outputGain_ = 1.0f; ///< 0 while the host bypasses Rosin, ramped over fadeLength_ either way
    juce::AudioBuffer<float> fadeBuffer_;
    engine::Performance performance_;
    engine::MidiDecoder decoder_;
    int installedInstrument_ = -1;
    std::uint32_t pushedGeneration_ = 0;     ///< the state generation the engine last took every parameter of
    double lastBlockStart_ = -1.0;           ///< steady-clock seconds: HID events are placed against it
    static constexpr int maxBlockEvents = 4096;
    std::array<engine::ControlEvent, maxBlockEvents> events_{};
    int eventCount_ = 0;
    std::uint64_t droppedEvents_ = 0;

    // Crossing threads.
    std::unique_ptr<engine::ViewRing> viewRing_ = std::make_unique<engine::ViewRing>(1u << 15);
    struct UiMidi {
        std::array<std::uint8_t, 3> bytes{};
        int size = 0;
    };
    rt::SpscQueue<UiMidi, 256> uiMidi_;
    rt::Handoff<engine::Synth> engines_;
    rt::SpscQueue<HostChange, 1024> toHost_;        ///< audio -> housekeeping
    rt::SpscQueue<Learn, 64> learned_;              ///< audio -> housekeeping
    std::array<std::atomic<int>, engine::paramCount> inFlight_{}; ///< host changes queued, not yet made
    /// One more for every restored state: a controller move made before a restore must not
    /// land on the host parameter after it (the housekeeping thread drops it).
    std::atomic<std::uint32_t> stateGeneration_{0};
    std::mutex hostChangeMutex_; ///< [not audio] a restore and the moving of host parameters, one at a time
    std::atomic<double> sampleRate_{0.0};
    std::atomic<int> requestedInstrument_{-1}; ///< [loader] the instrument it last started to build
    std::atomic<int> settledInstrument_{-1};   ///< the instrument whose build finished (an engine, or a failure)
    std::atomic<int> activeVoices_{0};
    std::atomic<int> enginesInstalled_{0};

    mutable std::mutex loadMutex_; ///< serialises loaders (never taken on the audio thread)
    juce::String instrumentName_{"cello"};
    juce::String stateProblem_;
    std::unique_ptr<Loader> loader_;

    JUCE_DECLARE_NON_COPYABLE_WITH_LEAK_DETECTOR(RosinProcessor)
};

} // namespace rosin::plugin
