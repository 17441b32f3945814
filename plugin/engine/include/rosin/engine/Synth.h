// The instrument engine: fixed voices of dsp/ bowed strings, the parameter layer that turns
// MIDI 1.0 and MPE into physical units, a modal body per output channel, stereo placement.
// JUCE-free, so the plugin, the headless renderer and fast tests share it.
//
// Threading: prepare() allocates (message or loader thread). Everything else is for the audio
// thread: no allocation, no locks, no exceptions, any parameter value survives.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "rosin/dsp/Body.h"
#include "rosin/dsp/BowGesture.h"
#include "rosin/dsp/BowedString.h"
#include "rosin/engine/ControllerMap.h"
#include "rosin/engine/Parameters.h"
#include "rosin/engine/Presets.h"
#include "rosin/engine/ViewTap.h"

namespace rosin::engine {

enum class StringPolicy { LowestPosition = 0, StayOnString = 1, FixedString = 2 };

/// A bow played from outside MIDI (a HID controller): while active it replaces the nominal
/// force, speed and position and the controller scaling; speed is signed (its sign is the bow
/// direction, so a sign change is a bow change).
struct ExternalBow {
    bool active = false, engaged = false;
    float force = 0.0f, speed = 0.0f, beta = 0.1f; ///< N, m/s, fraction of the string
    int string = -1;                               ///< string new notes prefer, -1 none
};

/// What a test or an editor may want to know about a voice.
/// How the engine configures string `s` of an instrument for these parameters (model, contact,
/// rosin, ambient, footprint): the voices and the editor's playability map use the same one.
dsp::BowedStringConfig stringConfig(const InstrumentPreset& instrument, int s, const ParamValues& params);

/// The nominal bow force is the third string's; a player leans harder on thicker strings, and
/// Schelleng's force limits scale with the string's impedance, so string s gets Z0(s) / Z0(third).
double stringForceScale(const InstrumentPreset& instrument, int s);

struct VoiceInfo {
    bool active = false;
    int channel = -1, note = -1, stringIndex = -1;
    bool keyDown = false, released = false;
    double frequency = 0.0;   ///< stopped-string fundamental (Hz) after bend, glide, vibrato, intonation
    double correctionCents = 0.0; ///< how far the finger moved to correct the pitch by ear
    int bowDirection = 0;         ///< +1 down bow, -1 up bow, 0 still
    double bowPosition = 0.0;     ///< where on the bow the string is (m from the frog)
    double force = 0.0, speed = 0.0, beta = 0.0; ///< what the string got last sample
    double temperature = 0.0; ///< contact temperature rise (K)
};

class Synth {
public:
    static constexpr int maxVoices = 16;
    static constexpr int controlInterval = 32; ///< samples between pitch/beta updates (per voice clock)
    static constexpr int chunk = 256;          ///< internal mixing buffer length

    /// [setup thread] Allocates every voice for this instrument and rate.
    void prepare(double sampleRate, const InstrumentPreset& instrument, const ParamValues& params,
                 ControllerMap* map = nullptr);
    void reset() noexcept;

    /// [audio thread] Sanitised: NaN becomes the default, values are clamped to the range.
    void setParameter(int index, float value) noexcept;
    float parameter(int index) const noexcept { return params_[static_cast<std::size_t>(index)]; }
    const ParamValues& parameters() const noexcept { return params_; }

    /// [audio thread] One MIDI 1.0 message (running status is not expected: hosts expand it).
    void handleMidi(const std::uint8_t* data, int size) noexcept;
    /// [audio thread] Writes numSamples to both outputs (any length: mixed in chunks).
    void render(float* left, float* right, int numSamples) noexcept;

    /// [audio thread] The controller's bow (applied at the next control tick of every voice).
    void setExternalBow(const ExternalBow& bow) noexcept;
    const ExternalBow& externalBow() const noexcept { return external_; }

    void releaseAll() noexcept; ///< bow lift on every voice (all notes off)
    void killAll() noexcept;    ///< silence now (all sound off)

    int activeVoiceCount() const noexcept;
    VoiceInfo voiceInfo(int index) const noexcept;
    double sampleRate() const noexcept { return fs_; }
    const InstrumentPreset& instrument() const noexcept { return instrument_; }
    bool mpeMemberChannel(int channel) const noexcept;
    /// A number the owner attaches (the plugin: which instrument this engine was built for).
    void setTag(int tag) noexcept { tag_ = tag; }
    int tag() const noexcept { return tag_; }

    /// The string a note of `frequency` goes to: policy, a preferred string (stay-on-string, or
    /// -1), and a mask of strings already sounding (a free string is preferred, as in a chord).
    int chooseString(double frequency, int preferred, unsigned occupiedMask) const noexcept;
    /// Where to play a harmonic at `frequency`: a natural one (string s, n = 2-4, open string) or
    /// else an artificial one (stopped at f/4, touched a fourth above: n = 4). Returns n.
    int chooseHarmonic(double frequency, int& string) const noexcept;

    /// Analysis tap: the next voice to start writes its bridge force (N, before body and pan)
    /// and stick flags into these caller-owned buffers, up to `capacity` samples.
    void setVoiceTap(float* bridgeForce, std::uint8_t* stick, int capacity) noexcept;
    int voiceTapCount() const noexcept { return tapCount_; }
    /// Live views: the newest sounding voice writes one ViewFrame per sample into `ring` while
    /// the ring has a listener (nullptr stops it). The ring outlives this engine.
    void setViewTap(ViewRing* ring) noexcept { viewRing_ = ring; }
    /// Lowest MIDI note that is a keyswitch (C0); articulation n is this note + n.
    static constexpr int keyswitchBase = 12;
    double noteFrequency(double midiNote) const noexcept;

private:
    struct ChannelState {
        float bend = 0.0f;            ///< -1..1
        float bendRange = -1.0f;      ///< semitones from RPN 0, < 0 while unset
        float pressure = -1.0f;       ///< force source 0..1 (channel pressure, CC2), < 0 unseen
        float expression = -1.0f;     ///< speed source 0..1 (CC11)
        float position = -1.0f;       ///< bow-position source 0..1 (CC4, CC74)
        float vibrato = 0.0f;         ///< CC1
        float volume = 1.0f;          ///< CC7
        bool sustain = false;
        std::array<std::uint8_t, 32> msb{}, lsb{};
        std::array<bool, 32> lsbSeen{};
        int rpnMsb = 127, rpnLsb = 127;
    };

    struct Voice {
        std::array<dsp::BowedString<float>, maxStrings> strings;
        bool active = false, keyDown = false, sustained = false, released = false;
        int channel = 0, note = 0, stringIndex = 0;
        float velocity = 0.0f, polyPressure = -1.0f;
        std::uint64_t order = 0;
        std::array<int, 8> held{}; ///< legato note stack on this voice (top = sounding)
        int heldCount = 0;
        double pitch = 0.0, glideTarget = 0.0, glideStep = 0.0; ///< MIDI note numbers
        dsp::BowGesture gesture; ///< the right arm: articulation, bow direction, bow length
        int harmonic = 0;        ///< n when a light finger makes the n-th harmonic, else 0
        double speed = 0.0, force = 0.0, aimForce = 0.0, lift = 1.0, fade = 1.0, age = 0.0;
        double targetForce = 0.0, targetSpeed = 0.0, beta = 0.1, frequency = 0.0;
        double vibratoPhase = 0.0, peak = 0.0;
        float gainL = 0.7f, gainR = 0.7f, volume = 1.0f;
        int untilControl = 0;
        float lastTemperature = 0.0f;
        // Intonation by ear: the Helmholtz period is the time between slip onsets at the bow.
        bool wasStick = true;
        int samplesSinceSlip = 0, periodsHeard = 0;
        double heardPeriod = 0.0, targetPeriod = 0.0, correctionCents = 0.0;
    };

    void noteOn(int channel, int note, int velocity) noexcept;
    void noteOff(int channel, int note) noexcept;
    void controller(int channel, int cc, float value) noexcept;
    void controlChange(int channel, int cc, int value) noexcept;
    void dataEntry(int channel, bool coarse, int value) noexcept;
    void sustainOff(int channel) noexcept;
    void releaseVoice(Voice& v) noexcept;
    void startVoice(Voice& v, int channel, int note, int velocity, int stringIndex) noexcept;
    void updateControl(Voice& v) noexcept;
    void renderVoice(Voice& v, float* busL, float* busR, int n) noexcept;
    bool reaches(int string, double frequency) const noexcept; ///< open pitch (a quarter-tone flat) up to the highest stop
    void glideTo(Voice& v, int note) noexcept;                  ///< legato: the finger moves over `portamento`
    void listen(Voice& v, bool stick) noexcept;
    void applyFriction() noexcept;
    Voice* findVoiceToStart() noexcept;
    int masterOf(int channel) const noexcept; ///< MPE master of a member channel, else -1
    float bendRangeOf(int channel) const noexcept;
    void panFor(int stringIndex, float& l, float& r) const noexcept;

    double fs_ = 48000.0;
    InstrumentPreset instrument_;
    ParamValues params_ = defaultParams();
    ControllerMap* map_ = nullptr;
    std::array<Voice, maxVoices> voices_;
    std::array<ChannelState, 16> channels_{};
    std::array<int, 16> lastString_{};
    int mcmLower_ = -1, mcmUpper_ = -1; ///< member counts from MPE configuration messages
    std::uint64_t noteCounter_ = 0;
    std::array<dsp::ModalBody<float>, 2> body_;
    std::vector<float> busL_, busR_;
    double gain_ = 1.0, gainTarget_ = 1.0, bodyMix_ = 1.0, smoothing_ = 0.0, betaSmoothing_ = 0.0;
    double ringCoefficient_ = 0.999;
    int tag_ = -1;
    ExternalBow external_;
    std::array<double, maxStrings> forceScale_{}; ///< Z0(string) / Z0(third string): same place in Schelleng's diagram
    std::array<int, 16> nextDirection_{};      ///< per channel: the next note's bow direction
    std::array<double, 16> bowPosition_{};     ///< per channel: where on the bow the last note ended (m)
    float* tapBridge_ = nullptr;
    std::uint8_t* tapStick_ = nullptr;
    int tapCapacity_ = 0, tapCount_ = 0;
    const Voice* tapVoice_ = nullptr;
    bool tapArmed_ = false;
    ViewRing* viewRing_ = nullptr;
    const Voice* watched_ = nullptr;
    bool watchedIsNew_ = false;
    std::array<ViewFrame, chunk> viewChunk_{};
    void chooseWatched() noexcept;
    void applyBody() noexcept;
};

} // namespace rosin::engine
