#include "rosin/engine/Synth.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#endif

namespace rosin::engine {
namespace {
constexpr double controlSmoothingSeconds = 0.01; ///< force/speed/gain one-pole time constant
constexpr double betaSmoothingSeconds = 0.02;    ///< at control rate: beta redesigns the loss filters
constexpr double ringSeconds = 0.6;              ///< 60 dB decay of a string after the bow lifts
constexpr double stealSeconds = 0.005;           ///< 100 dB fade of a stolen note: no click, no delay

/// Flush denormals to zero for the scope (the string's losses decay into them after release).
struct NoDenormals {
#if defined(__SSE__) || defined(__x86_64__)
    unsigned int saved = _mm_getcsr();
    NoDenormals() noexcept { _mm_setcsr(saved | 0x8040); }
    ~NoDenormals() { _mm_setcsr(saved); }
#endif
};

double onePole(double seconds, double fs) { return 1.0 - std::exp(-1.0 / (seconds * fs)); }
double dbToGain(double db) { return std::pow(10.0, db / 20.0); }
constexpr std::size_t index(Param p) { return static_cast<std::size_t>(p); }
} // namespace

void Synth::prepare(double sampleRate, const InstrumentPreset& instrument, const ParamValues& params, ControllerMap* map)
{
    fs_ = sampleRate;
    instrument_ = instrument;
    map_ = map;
    for (int i = 0; i < paramCount; ++i) params_[static_cast<std::size_t>(i)] = sanitise(static_cast<Param>(i), params[static_cast<std::size_t>(i)]);
    chooser_.prepare(instrument);

    // One prepared string per instrument string, copied into every voice: the temperature
    // tables are built once per string, not once per voice.
    std::array<dsp::BowedString<float>, maxStrings> templates;
    for (int s = 0; s < instrument.stringCount; ++s) templates[static_cast<std::size_t>(s)].prepare(sampleRate, stringConfig(instrument, s, params_));
    for (auto& v : voices_) v.prepare(sampleRate, templates, instrument.stringCount);

    for (int s = 0; s < maxStrings; ++s) stringScale_[static_cast<std::size_t>(s)] = stringForceScale(instrument, s);
    for (auto& b : body_) b.prepare(sampleRate, instrument.body);
    applyBody();
    busL_.assign(chunk, 0.0f);
    busR_.assign(chunk, 0.0f);
    smoothing_ = onePole(controlSmoothingSeconds, sampleRate);
    betaSmoothing_ = onePole(betaSmoothingSeconds, sampleRate / controlInterval);
    ringCoefficient_ = std::exp(std::log(1e-3) / (ringSeconds * sampleRate));
    stealCoefficient_ = std::exp(std::log(1e-5) / (stealSeconds * sampleRate));
    reset();
}

void Synth::reset() noexcept
{
    watched_ = nullptr;
    for (auto& v : voices_) v.reset();
    ownPerformance_.reset();
    ownDecoder_.reset();
    performance_->setMpeDefault(params_[index(Param::Mpe)] > 0.5f);
    lastString_.fill(-1);
    nextDirection_.fill(1);
    bowPosition_.fill(0.1);
    for (auto& b : body_) b.reset();
    gainTarget_ = gain_ = dbToGain(params_[index(Param::Gain)]);
    bodyMix_ = params_[index(Param::BodyMix)];
    noteCounter_ = 0;
}

void Synth::attach(Performance* performance) noexcept
{
    performance_ = performance ? performance : &ownPerformance_;
    performance_->setMpeDefault(params_[index(Param::Mpe)] > 0.5f);
}

void Synth::setPerSample(bool on) noexcept
{
    for (auto& v : voices_) v.setPerSample(on);
}

void Synth::setParameter(int i, float value) noexcept
{
    if (i < 0 || i >= paramCount) return;
    const Param p = static_cast<Param>(i);
    value = sanitise(p, value);
    float& slot = params_[static_cast<std::size_t>(i)];
    if (slot == value) return;
    slot = value;
    switch (p) {
    case Param::FrictionModel:
    case Param::ContactLaw:
    case Param::RosinTg:
    case Param::Ambient:
    case Param::Footprint: applyFriction(); break;
    case Param::Gain: gainTarget_ = dbToGain(value); break;
    case Param::Mute: applyBody(); break;
    case Param::Mpe: performance_->setMpeDefault(value > 0.5f); break;
    default: break;
    }
}

void Synth::applyFriction() noexcept
{
    const auto model = static_cast<dsp::FrictionModel>(static_cast<int>(params_[index(Param::FrictionModel)]));
    const auto law = params_[index(Param::ContactLaw)] > 0.5f ? dsp::ContactLaw::PowerLaw : dsp::ContactLaw::Amontons;
    for (auto& v : voices_)
        v.configureFriction(model, law, params_[index(Param::RosinTg)], params_[index(Param::Ambient)], params_[index(Param::Footprint)]);
}

double Synth::noteFrequency(double midiNote) const noexcept { return instrument_.tuningA4 * std::exp2((midiNote - 69.0) / 12.0); }

int Synth::chooseString(double frequency, int preferred, unsigned occupiedMask) const noexcept
{
    return chooser_.choose(frequency, static_cast<StringPolicy>(static_cast<int>(params_[index(Param::StringPolicy)])),
                           static_cast<int>(params_[index(Param::FixedString)]), -1, preferred, occupiedMask);
}

void Synth::panFor(int stringIndex, float& l, float& r) const noexcept
{
    const int n = std::max(1, instrument_.stringCount);
    const double centred = n > 1 ? (stringIndex - 0.5 * (n - 1)) / (0.5 * (n - 1)) : 0.0; // -1 low .. +1 high
    const double pan = std::clamp(centred * instrument_.panSpread * params_[index(Param::Width)], -1.0, 1.0);
    const double angle = 0.25 * std::numbers::pi * (pan + 1.0); // equal power
    l = static_cast<float>(std::cos(angle));
    r = static_cast<float>(std::sin(angle));
}

VoiceContext Synth::context() const noexcept
{
    VoiceContext c;
    c.params = &params_;
    c.performance = performance_;
    c.stringScale = &stringScale_;
    c.sampleRate = fs_;
    c.tuningA4 = instrument_.tuningA4;
    c.smoothing = smoothing_;
    c.betaSmoothing = betaSmoothing_;
    c.ringCoefficient = ringCoefficient_;
    c.stealCoefficient = stealCoefficient_;
    return c;
}

void Synth::handleMidi(const std::uint8_t* data, int size) noexcept
{
    ControlEvent events[MidiDecoder::maxEvents];
    const ControllerTable* table = map_ ? &map_->acquire() : nullptr;
    const int armed = map_ ? map_->learning() : -1;
    const int n = ownDecoder_.decode(data, size, 0, *performance_, params_, table, armed, events);
    for (int k = 0; k < n; ++k) {
        if (events[k].kind == Control::Learned && map_ && map_->claimLearn() >= 0) {
            const ParamInfo& info = paramInfo(events[k].index);
            map_->set(events[k].note, events[k].index, info.min, info.max, false); // one thread: the caller's
        }
        apply(events[k]);
    }
}

void Synth::apply(const ControlEvent& e) noexcept
{
    performance_->apply(e);
    const int ch = e.channel & 15;
    switch (e.kind) {
    case Control::NoteOn: noteOn(ch, e.note, e.value); break;
    case Control::NoteOff: noteOff(ch, e.note); break;
    case Control::Force:
        if (e.note >= 0) // per note: polyphonic pressure
            for (auto& v : voices_)
                if (v.active() && v.channel() == ch && v.note() == e.note) v.setPolyPressure(std::clamp(e.value, 0.0f, 1.0f));
        break;
    case Control::Sustain:
        if (e.value < 0.5f) releaseSustained(ch);
        break;
    case Control::ResetControls: releaseSustained(ch); break;
    case Control::SoundOff:
        for (auto& v : voices_)
            if (v.active() && v.channel() == ch) v.steal(); // silence within a few ms, without a click
        break;
    case Control::NotesOff:
        for (auto& v : voices_)
            if (v.active() && v.channel() == ch && !v.released()) v.release();
        break;
    case Control::Parameter: setParameter(e.index, e.value); break;
    default: break;
    }
}

void Synth::applyBody() noexcept
{
    // A mute is a mass clamped on the bridge: the bridge hill and the upper body modes move down
    // and lose most of their output (Euphonics ch. 10's account of the mute; the factors are [A]).
    dsp::BodyParams b = instrument_.body;
    if (params_[index(Param::Mute)] > 0.5f)
        for (int i = 0; i < b.count; ++i) {
            auto& m = b.modes[static_cast<std::size_t>(i)];
            m.frequency *= m.frequency > 600.0 ? 0.8 : 0.95;
            if (m.frequency > 800.0) m.gain *= 0.3;
        }
    for (auto& body : body_) body.retune(fs_, b);
}

void Synth::releaseAll() noexcept
{
    for (auto& v : voices_)
        if (v.active() && !v.released()) v.release();
}

void Synth::render(float* left, float* right, int numSamples) noexcept
{
    NoDenormals guard;
    const double bodyTarget = params_[index(Param::BodyMix)];
    const float direct = static_cast<float>(instrument_.body.outputScale);
    const VoiceContext ctx = context();
    for (int start = 0; start < numSamples; start += chunk) {
        const int n = std::min(chunk, numSamples - start);
        std::fill_n(busL_.data(), n, 0.0f);
        std::fill_n(busR_.data(), n, 0.0f);
        if (viewRing_ != nullptr && (watched_ == nullptr || !watched_->active())) chooseWatched();
        const bool viewing = viewRing_ != nullptr && viewRing_->listening();
        for (auto& v : voices_) {
            if (!v.active()) continue;
            VoiceTaps viewTaps;
            VoiceTaps* taps = nullptr;
            if (&v == tapVoice_) taps = &tap_;
            if (viewing && &v == watched_) {
                viewTaps = tapVoice_ == &v ? tap_ : VoiceTaps{};
                viewTaps.view = viewChunk_.data();
                viewTaps.viewCount = 0;
                taps = &viewTaps;
            }
            v.processBlock(busL_.data(), busR_.data(), n, ctx, taps);
            if (taps == &viewTaps) {
                if (tapVoice_ == &v) tap_.count = viewTaps.count;
                if (viewTaps.viewCount > 0) {
                    viewChunk_[0].noteStart = watchedIsNew_ ? 1 : 0;
                    watchedIsNew_ = false;
                    viewRing_->write(viewChunk_.data(), static_cast<std::size_t>(viewTaps.viewCount));
                }
            }
            if (!v.active() && tapVoice_ == &v) tapVoice_ = nullptr;
        }
        // Gain and body mix glide only while they move; settled, they are constants of the chunk.
        const bool gliding = gain_ != gainTarget_ || bodyMix_ != bodyTarget;
        float mix = static_cast<float>(bodyMix_), g = static_cast<float>(gain_);
        bool finite = true;
        for (int i = 0; i < n; ++i) {
            if (gliding) {
                gain_ += (gainTarget_ - gain_) * smoothing_;
                bodyMix_ += (bodyTarget - bodyMix_) * smoothing_;
                if (std::abs(gain_ - gainTarget_) < 1e-7 * gainTarget_) gain_ = gainTarget_;
                if (std::abs(bodyMix_ - bodyTarget) < 1e-7) bodyMix_ = bodyTarget;
                mix = static_cast<float>(bodyMix_);
                g = static_cast<float>(gain_);
            }
            const float l = busL_[static_cast<std::size_t>(i)], r = busR_[static_cast<std::size_t>(i)];
            const float bl = body_[0].processSample(l), br = body_[1].processSample(r);
            const float outL = g * (mix * bl + (1.0f - mix) * direct * l);
            const float outR = g * (mix * br + (1.0f - mix) * direct * r);
            left[start + i] = std::clamp(outL, -4.0f, 4.0f);
            right[start + i] = std::clamp(outR, -4.0f, 4.0f);
            finite = finite && std::isfinite(outL + outR);
        }
        // Last line of defence: whatever went wrong upstream, the host gets no NaN or a blast.
        if (!finite) {
            for (int i = 0; i < n; ++i) {
                if (!std::isfinite(left[start + i])) left[start + i] = 0.0f;
                if (!std::isfinite(right[start + i])) right[start + i] = 0.0f;
            }
            body_[0].reset();
            body_[1].reset();
        }
    }
}

} // namespace rosin::engine
