// One sounding note: the strings it may play on, the player's right arm (BowGesture) or a
// controller's hand, the left hand (stop, glide, bend, vibrato, intonation by ear) and the fade
// when the bow has left. prepare / reset / processBlock like every unit; between control updates
// (every controlInterval samples) the string runs a whole sub-block through
// BowedString::processBlock, the model's fast path.
#pragma once
#include <array>
#include <cstdint>

#include "rosin/dsp/BowGesture.h"
#include "rosin/dsp/BowedString.h"
#include "rosin/engine/Controls.h"
#include "rosin/engine/Performance.h"
#include "rosin/engine/Presets.h"
#include "rosin/engine/ViewTap.h"

namespace rosin::engine {

/// What a test or an editor may want to know about a voice.
struct VoiceInfo {
    bool active = false;
    int channel = -1, note = -1, stringIndex = -1;
    bool keyDown = false, released = false;
    double frequency = 0.0;       ///< stopped-string fundamental (Hz) after bend, glide, vibrato, intonation
    double correctionCents = 0.0; ///< how far the finger moved to correct the pitch by ear
    int bowDirection = 0;         ///< +1 down bow, -1 up bow, 0 still
    double bowPosition = 0.0;     ///< where on the bow the string is (m from the frog)
    double force = 0.0, speed = 0.0, beta = 0.0; ///< what the string got last sample
    double temperature = 0.0;     ///< contact temperature rise (K)
};

/// What every voice of one engine shares, fixed for a render call.
struct VoiceContext {
    const ParamValues* params = nullptr;
    const Performance* performance = nullptr;
    const std::array<double, maxStrings>* stringScale = nullptr; ///< Z0(string) / Z0(reference)
    double sampleRate = 48000.0, tuningA4 = 440.0;
    double smoothing = 0.0, betaSmoothing = 0.0; ///< one-pole coefficients: per sample, per control tick
    double ringCoefficient = 0.999;              ///< per-sample decay once the bow has left
    double stealCoefficient = 0.99;              ///< per-sample decay of a stolen voice (a few ms)
};

/// Where the views and the analysis tap want this voice's samples.
struct VoiceTaps {
    ViewFrame* view = nullptr; ///< per-sample frames (the watched voice while someone listens)
    int viewCount = 0;
    float* bridge = nullptr;   ///< bridge force and stick flags (tests)
    std::uint8_t* stick = nullptr;
    int capacity = 0, count = 0;
};

class Voice {
public:
    static constexpr int controlInterval = 32; ///< samples between pitch and bow-position updates

    struct Start {
        int channel = 0, note = 60, string = 0, harmonic = 0;
        float velocity = 0.8f;
        dsp::Articulation articulation = dsp::Articulation::Detache;
        dsp::GestureSettings gesture;
        int direction = 1;
        double bowPosition = 0.1; ///< m from the frog
        float gainL = 0.7f, gainR = 0.7f;
        std::uint64_t order = 0;
    };

    /// [setup thread] Copies the instrument's prepared strings (their tables are built once).
    void prepare(double sampleRate, const std::array<dsp::BowedString<float>, maxStrings>& strings, int stringCount);
    void reset() noexcept;

    void start(const Start& s, const VoiceContext& ctx) noexcept;
    void release() noexcept;     ///< the bow lifts; the string rings down
    void steal() noexcept;       ///< faded out over a few ms (its slot was needed), then free
    void glideTo(int note, double seconds, double sampleRate) noexcept; ///< legato: the finger moves
    void setPolyPressure(float p) noexcept { polyPressure_ = p; }
    /// The friction switches every string of this voice follows (they change at run time).
    void configureFriction(dsp::FrictionModel model, dsp::ContactLaw law, double glassTransition, double ambient, double footprint) noexcept;

    /// Adds n samples to the buses. Per sub-block it checks its own output: a voice that goes
    /// non-finite is reset and freed, and the others play on.
    void processBlock(float* busL, float* busR, int n, const VoiceContext& ctx, VoiceTaps* taps = nullptr) noexcept;
    /// The reference path: the string one sample at a time (the block path must equal it).
    void setPerSample(bool on) noexcept { perSample_ = on; }

    bool active() const noexcept { return active_; }
    bool stolen() const noexcept { return stolen_; }
    bool keyDown() const noexcept { return keyDown_; }
    bool sustained() const noexcept { return sustained_; }
    bool released() const noexcept { return released_; }
    void setKeyUp(bool sustainedByPedal) noexcept { keyDown_ = false; sustained_ = sustainedByPedal; }
    int channel() const noexcept { return channel_; }
    int note() const noexcept { return note_; }
    int string() const noexcept { return string_; }
    std::uint64_t order() const noexcept { return order_; }
    double bowPosition() const noexcept { return gesture_.bowPosition(); }
    /// Legato note stack (top = sounding).
    bool pushHeld(int note) noexcept;
    bool holds(int note) const noexcept;
    int popHeld(int note) noexcept; ///< removes `note`; returns the note now on top, or -1 when none is held
    VoiceInfo info() const noexcept;
    /// The string model of string s (research and tests: its state, or a deliberate fault).
    dsp::BowedString<float>& stringModel(int s) noexcept { return strings_[static_cast<std::size_t>(s)]; }

private:
    void updateControl(const VoiceContext& ctx) noexcept;
    void listen(bool stick) noexcept;
    int renderBlock(float* out, std::uint8_t* stick, int m, const VoiceContext& ctx, VoiceTaps* taps) noexcept;

    std::array<dsp::BowedString<float>, maxStrings> strings_;
    int stringCount_ = 0;
    bool active_ = false, keyDown_ = false, sustained_ = false, released_ = false, stolen_ = false, perSample_ = false;
    int channel_ = 0, note_ = 0, string_ = 0, harmonic_ = 0;
    float velocity_ = 0.0f, polyPressure_ = -1.0f;
    std::uint64_t order_ = 0;
    std::array<int, 8> held_{};
    int heldCount_ = 0;
    double pitch_ = 0.0, glideTarget_ = 0.0, glideStep_ = 0.0; ///< MIDI note numbers
    dsp::BowGesture gesture_;
    double speed_ = 0.0, force_ = 0.0, aimForce_ = 0.0, lift_ = 1.0, fade_ = 1.0, age_ = 0.0;
    double targetForce_ = 0.0, targetSpeed_ = 0.0, beta_ = 0.1, frequency_ = 0.0;
    double vibratoPhase_ = 0.0, liftStep_ = 0.0;
    bool direct_ = false, engaged_ = false;
    float gainL_ = 0.7f, gainR_ = 0.7f, volume_ = 1.0f;
    int untilControl_ = 0;
    float lastTemperature_ = 0.0f;
    // Intonation by ear: the Helmholtz period is the time between slip onsets at the bow.
    bool wasStick_ = true;
    int samplesSinceSlip_ = 0, periodsHeard_ = 0;
    double heardPeriod_ = 0.0, targetPeriod_ = 0.0, correctionCents_ = 0.0;
};

} // namespace rosin::engine
