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

dsp::BowedStringConfig stringConfig(const InstrumentPreset& instrument, int s, const ParamValues& params)
{
    const auto p = [&](Param q) { return sanitise(q, params[static_cast<std::size_t>(q)]); };
    dsp::BowedStringConfig c;
    c.string = instrument.strings[static_cast<std::size_t>(std::clamp(s, 0, std::max(0, instrument.stringCount - 1)))];
    c.waveguide.lowestPitchRatio = 0.5; // an octave of bend below the open string
    c.waveguide.dispersion = false;     // the allpass fit is not redone per stop
    c.friction.switchable = true;
    c.friction.model = static_cast<dsp::FrictionModel>(static_cast<int>(p(Param::FrictionModel)));
    c.friction.contactLaw = p(Param::ContactLaw) > 0.5f ? dsp::ContactLaw::PowerLaw : dsp::ContactLaw::Amontons;
    c.friction.thermal.glassTransitionCelsius = p(Param::RosinTg);
    c.friction.thermal.ambientCelsius = p(Param::Ambient);
    c.friction.thermal.footprintRatio = p(Param::Footprint);
    return c;
}

double stringForceScale(const InstrumentPreset& instrument, int s)
{
    if (s < 0 || s >= instrument.stringCount) return 1.0;
    const double zRef = instrument.strings[static_cast<std::size_t>(std::min(2, instrument.stringCount - 1))].impedance();
    return instrument.strings[static_cast<std::size_t>(s)].impedance() / zRef;
}

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

void Synth::releaseSustained(int ch) noexcept
{
    for (auto& v : voices_) {
        if (!v.active() || !v.sustained() || v.keyDown()) continue;
        if (v.channel() == ch || performance_->masterOf(v.channel()) == ch) {
            bowPosition_[static_cast<std::size_t>(v.channel())] = v.bowPosition();
            v.release();
        }
    }
}

Voice* Synth::findVoiceToStart() noexcept
{
    Voice* free = nullptr;
    int sounding = 0;
    for (auto& v : voices_) {
        if (!v.active()) { if (!free) free = &v; }
        else if (!v.stolen()) ++sounding;
    }
    if (free && sounding < maxVoices) return free;
    // Steal: the oldest released note, else the oldest; it fades out over a few ms in its slot.
    Voice* victim = nullptr;
    for (auto& v : voices_)
        if (v.active() && !v.stolen() && v.released() && (!victim || v.order() < victim->order())) victim = &v;
    if (!victim)
        for (auto& v : voices_)
            if (v.active() && !v.stolen() && (!victim || v.order() < victim->order())) victim = &v;
    if (victim) victim->steal();
    if (free) return free;
    // Every slot busy, spares too: the oldest of the fading notes is cut.
    Voice* oldest = nullptr;
    for (auto& v : voices_)
        if (v.stolen() && (!oldest || v.order() < oldest->order())) oldest = &v;
    return oldest ? oldest : victim;
}

void Synth::noteOn(int ch, int note, float velocity) noexcept
{
    const double f = noteFrequency(note);
    if (params_[index(Param::Legato)] > 0.5f) {
        // A held note on this channel hands its bow over: glide on its string if it reaches.
        for (auto& v : voices_) {
            if (!v.active() || v.channel() != ch || !v.keyDown() || v.released()) continue;
            if (chooser_.reaches(v.string(), f)) {
                v.pushHeld(note);
                v.glideTo(note, params_[index(Param::Portamento)], fs_);
                return;
            }
            bowPosition_[static_cast<std::size_t>(ch)] = v.bowPosition();
            v.release(); // string crossing: this string's bow lifts, the next one starts
        }
    }
    unsigned occupied = 0;
    for (auto& v : voices_)
        if (v.active() && !v.released() && v.channel() == ch) occupied |= 1u << v.string();
    const int s = chooser_.choose(f, static_cast<StringPolicy>(static_cast<int>(params_[index(Param::StringPolicy)])),
                                  static_cast<int>(params_[index(Param::FixedString)]), performance_->effective(ch).preferredString,
                                  lastString_[static_cast<std::size_t>(ch)], occupied);
    Voice* v = findVoiceToStart();
    if (!v) return;
    startVoice(*v, ch, note, velocity, s);
    lastString_[static_cast<std::size_t>(ch)] = s;
}

void Synth::startVoice(Voice& v, int ch, int note, float velocity, int s) noexcept
{
    if (tapVoice_ == &v) tapVoice_ = nullptr;
    Voice::Start start;
    start.channel = ch;
    start.note = note;
    start.velocity = velocity;
    const bool byChannel = params_[index(Param::ArticulationChannels)] > 0.5f;
    const int articulation = byChannel && ch < static_cast<int>(dsp::Articulation::Count) ? ch : static_cast<int>(params_[index(Param::Articulation)]);
    start.articulation = static_cast<dsp::Articulation>(articulation);
    if (start.articulation == dsp::Articulation::Harmonic && !byChannel) {
        int hs = s;
        start.harmonic = chooser_.harmonic(noteFrequency(note), hs);
        s = hs;
    }
    start.string = s;
    dsp::GestureSettings& gs = start.gesture;
    gs.bowLength = params_[index(Param::BowLength)];
    gs.acceleration = params_[index(Param::AttackAccel)];
    gs.attackBoost = params_[index(Param::AttackForce)];
    gs.releaseTime = params_[index(Param::ReleaseTime)];
    gs.tremoloRate = params_[index(Param::TremoloRate)];
    gs.spiccatoRate = params_[index(Param::SpiccatoRate)];
    // Consecutive notes on a channel alternate down and up bow and continue from where on the
    // bow the last one ended.
    const auto cs = static_cast<std::size_t>(ch);
    start.direction = nextDirection_[cs] >= 0 ? 1 : -1;
    start.bowPosition = std::clamp(bowPosition_[cs], 0.0, gs.bowLength);
    nextDirection_[cs] = -start.direction;
    start.order = ++noteCounter_;
    panFor(s, start.gainL, start.gainR);
    v.start(start, context());
    watched_ = &v; // the views follow the newest note
    watchedIsNew_ = true;
    if (tapArmed_) {
        tapArmed_ = false;
        tapVoice_ = &v;
        tap_.count = 0;
    }
}

void Synth::noteOff(int ch, int note) noexcept
{
    for (auto& v : voices_) {
        if (!v.active() || v.channel() != ch || !v.keyDown() || !v.holds(note)) continue;
        const int back = v.popHeld(note);
        if (back >= 0) { // legato: back to the note still held
            if (back != v.note()) v.glideTo(back, params_[index(Param::Portamento)], fs_);
            continue;
        }
        const int master = performance_->masterOf(ch);
        const bool pedal = performance_->channel(ch).sustain || (master >= 0 && performance_->channel(master).sustain);
        if (pedal) {
            v.setKeyUp(true);
        } else {
            bowPosition_[static_cast<std::size_t>(ch)] = v.bowPosition();
            v.release();
        }
    }
}

void Synth::resumeHeldNotes() noexcept
{
    for (int i = 0; i < performance_->heldCount(); ++i) {
        const Performance::Held h = performance_->held(i);
        if (!chooser_.playable(noteFrequency(h.note))) continue;
        noteOn(h.channel, h.note, h.velocity);
        if (h.sustained)
            for (auto& v : voices_)
                if (v.active() && v.channel() == h.channel && v.note() == h.note && v.keyDown()) v.setKeyUp(true);
    }
}

void Synth::setVoiceTap(float* bridgeForce, std::uint8_t* stick, int capacity) noexcept
{
    tap_.bridge = bridgeForce;
    tap_.stick = stick;
    tap_.capacity = bridgeForce ? capacity : 0;
    tap_.count = 0;
    tapVoice_ = nullptr;
    tapArmed_ = bridgeForce != nullptr;
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

void Synth::chooseWatched() noexcept
{
    // The watched note ended: follow the newest one still sounding.
    const Voice* best = nullptr;
    for (const auto& v : voices_)
        if (v.active() && !v.stolen() && (best == nullptr || v.order() > best->order())) best = &v;
    if (best != watched_) watchedIsNew_ = best != nullptr;
    watched_ = best;
}

int Synth::activeVoiceCount() const noexcept
{
    int n = 0;
    for (const auto& v : voices_) n += v.active() ? 1 : 0;
    return n;
}

VoiceInfo Synth::voiceInfo(int i) const noexcept
{
    if (i < 0 || i >= static_cast<int>(voices_.size())) return {};
    return voices_[static_cast<std::size_t>(i)].info();
}

} // namespace rosin::engine
