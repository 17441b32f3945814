// The instrument engine: a pool of voices (dsp/ bowed strings) and the mixer (pan, a modal body
// per output channel, gain). Events come from the parameter layer (Controls.h) already decoded
// and normalised; the player's state they build (Performance) may belong to the caller, so it
// outlives the engine. JUCE-free: the plugin, the headless renderer and the tests share it.
//
// Threading: prepare() allocates (a setup thread). Everything else is for the audio thread: no
// allocation, no locks, no exceptions, and any parameter value survives.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "rosin/dsp/Body.h"
#include "rosin/engine/ControllerMap.h"
#include "rosin/engine/Controls.h"
#include "rosin/engine/MidiDecoder.h"
#include "rosin/engine/Parameters.h"
#include "rosin/engine/Performance.h"
#include "rosin/engine/Presets.h"
#include "rosin/engine/StringChooser.h"
#include "rosin/engine/ViewTap.h"
#include "rosin/engine/Voice.h"

namespace rosin::engine {

/// How the engine configures string `s` of an instrument for these parameters (model, contact,
/// rosin, ambient, footprint): the voices and the editor's playability map use the same one.
dsp::BowedStringConfig stringConfig(const InstrumentPreset& instrument, int s, const ParamValues& params);

/// The nominal bow force is the third string's; a player leans harder on thicker strings, and
/// Schelleng's force limits scale with the string's impedance, so string s gets Z0(s) / Z0(third).
double stringForceScale(const InstrumentPreset& instrument, int s);

class Synth {
public:
    static constexpr int maxVoices = 16;   ///< notes sounding at once
    static constexpr int spareVoices = 4;  ///< extra slots where stolen notes fade out (no click)
    static constexpr int controlInterval = Voice::controlInterval;
    static constexpr int chunk = 256;      ///< internal mixing buffer length
    static constexpr int keyswitchBase = MidiDecoder::keyswitchBase;

    Synth() = default;
    Synth(const Synth&) = delete; // it points into itself (its own performance)
    Synth& operator=(const Synth&) = delete;

    /// [setup thread] Allocates every voice for this instrument and rate. `map` serves
    /// handleMidi() only (one-thread use).
    void prepare(double sampleRate, const InstrumentPreset& instrument, const ParamValues& params, ControllerMap* map = nullptr);
    void reset() noexcept;

    /// The player's state this engine reads and updates (nullptr: its own).
    void attach(Performance* performance) noexcept;
    Performance& performance() noexcept { return *performance_; }

    /// [audio thread] Sanitised: NaN becomes the default, values are clamped to the range.
    void setParameter(int index, float value) noexcept;
    float parameter(int index) const noexcept { return params_[static_cast<std::size_t>(index)]; }
    const ParamValues& parameters() const noexcept { return params_; }

    /// [audio thread] One event of the parameter layer: the performance first, then the voices.
    void apply(const ControlEvent& e) noexcept;
    /// [one thread] MIDI 1.0 through this engine's own decoder, for tests and offline rendering;
    /// a completed MIDI-learn updates the map given to prepare() at once. The plugin decodes
    /// itself (MidiDecoder) and calls apply().
    void handleMidi(const std::uint8_t* data, int size) noexcept;
    /// [audio thread] Writes numSamples to both outputs (any length: mixed in chunks).
    void render(float* left, float* right, int numSamples) noexcept;

    void releaseAll() noexcept; ///< bow lift on every voice
    /// [audio thread] After an engine swap: the performance's held notes start again on this
    /// engine where the instrument can play them (sustained ones stay sustained).
    void resumeHeldNotes() noexcept;

    int activeVoiceCount() const noexcept;
    VoiceInfo voiceInfo(int index) const noexcept;
    Voice& voice(int index) noexcept { return voices_[static_cast<std::size_t>(index)]; }
    static constexpr int voiceSlots = maxVoices + spareVoices;
    double sampleRate() const noexcept { return fs_; }
    const InstrumentPreset& instrument() const noexcept { return instrument_; }
    bool mpeMemberChannel(int channel) const noexcept { return performance_->masterOf(channel) >= 0; }
    /// A number the owner attaches (the plugin: which instrument this engine was built for).
    void setTag(int tag) noexcept { tag_ = tag; }
    int tag() const noexcept { return tag_; }

    /// The string a note of `frequency` goes to: policy, a preferred string (stay-on-string, or
    /// -1), and a mask of strings already sounding.
    int chooseString(double frequency, int preferred, unsigned occupiedMask) const noexcept;
    /// Where to play a harmonic at `frequency` (StringChooser::harmonic). Returns n.
    int chooseHarmonic(double frequency, int& string) const noexcept { return chooser_.harmonic(frequency, string); }
    double noteFrequency(double midiNote) const noexcept;

    /// Analysis tap: the next voice to start writes its bridge force (N, before body and pan)
    /// and stick flags into these caller-owned buffers, up to `capacity` samples.
    void setVoiceTap(float* bridgeForce, std::uint8_t* stick, int capacity) noexcept;
    /// Live views: the newest sounding voice writes one ViewFrame per sample into `ring` while
    /// the ring has a listener (nullptr stops it). The ring outlives this engine.
    void setViewTap(ViewRing* ring) noexcept { viewRing_ = ring; }
    /// Every voice runs its string one sample at a time (the reference the fast path must equal).
    void setPerSample(bool on) noexcept;

private:
    void noteOn(int channel, int note, float velocity) noexcept;
    void noteOff(int channel, int note) noexcept;
    void startVoice(Voice& v, int channel, int note, float velocity, int stringIndex) noexcept;
    void releaseSustained(int channel) noexcept;
    Voice* findVoiceToStart() noexcept;
    void applyFriction() noexcept;
    void applyBody() noexcept;
    void chooseWatched() noexcept;
    void panFor(int stringIndex, float& l, float& r) const noexcept;
    VoiceContext context() const noexcept;

    double fs_ = 48000.0;
    InstrumentPreset instrument_;
    ParamValues params_ = defaultParams();
    StringChooser chooser_;
    Performance ownPerformance_;
    Performance* performance_ = &ownPerformance_;
    MidiDecoder ownDecoder_;
    ControllerMap* map_ = nullptr;
    std::array<Voice, maxVoices + spareVoices> voices_;
    std::array<int, 16> lastString_{};
    std::uint64_t noteCounter_ = 0;
    std::array<dsp::ModalBody<float>, 2> body_;
    std::vector<float> busL_, busR_;
    double gain_ = 1.0, gainTarget_ = 1.0, bodyMix_ = 1.0, smoothing_ = 0.0, betaSmoothing_ = 0.0;
    double ringCoefficient_ = 0.999, stealCoefficient_ = 0.99;
    int tag_ = -1;
    std::array<double, maxStrings> stringScale_{}; ///< Z0(string) / Z0(third string)
    std::array<int, 16> nextDirection_{};          ///< per channel: the next note's bow direction
    std::array<double, 16> bowPosition_{};         ///< per channel: where on the bow the last note ended (m)
    VoiceTaps tap_;
    const Voice* tapVoice_ = nullptr;
    bool tapArmed_ = false;
    ViewRing* viewRing_ = nullptr;
    const Voice* watched_ = nullptr;
    bool watchedIsNew_ = false;
    std::array<ViewFrame, chunk> viewChunk_{};
};

} // namespace rosin::engine
