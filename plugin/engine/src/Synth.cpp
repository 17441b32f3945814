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
constexpr double silence = 1e-5;                 ///< -100 dB: the voice is free
constexpr double harmonicTouch = 3.0;            ///< the light finger's resistance, x Z0 [A]
constexpr int memberBendRange = 48, masterBendRange = 2; ///< MPE defaults (M1-100-UM)

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

    // One prepared string per instrument string, copied into every voice: the temperature
    // tables are built once per string, not once per voice.
    std::array<dsp::BowedString<float>, maxStrings> templates;
    for (int s = 0; s < instrument.stringCount; ++s) templates[static_cast<std::size_t>(s)].prepare(sampleRate, stringConfig(instrument, s, params_));
    for (auto& v : voices_)
        for (int s = 0; s < instrument.stringCount; ++s) v.strings[static_cast<std::size_t>(s)] = templates[static_cast<std::size_t>(s)];

    for (int s = 0; s < maxStrings; ++s) forceScale_[static_cast<std::size_t>(s)] = stringForceScale(instrument, s);
    for (auto& v : voices_) v.gesture.prepare(sampleRate);
    for (auto& b : body_) b.prepare(sampleRate, instrument.body);
    applyBody();
    busL_.assign(chunk, 0.0f);
    busR_.assign(chunk, 0.0f);
    smoothing_ = onePole(controlSmoothingSeconds, sampleRate);
    betaSmoothing_ = onePole(betaSmoothingSeconds, sampleRate / controlInterval);
    ringCoefficient_ = std::exp(std::log(1e-3) / (ringSeconds * sampleRate));
    reset();
}

void Synth::reset() noexcept
{
    watched_ = nullptr;
    for (auto& v : voices_) {
        v.active = false;
        for (int s = 0; s < instrument_.stringCount; ++s) v.strings[static_cast<std::size_t>(s)].reset();
    }
    channels_ = {};
    lastString_.fill(-1);
    nextDirection_.fill(1);
    bowPosition_.fill(0.1);
    mcmLower_ = mcmUpper_ = -1;
    for (auto& b : body_) b.reset();
    gainTarget_ = gain_ = dbToGain(params_[static_cast<int>(Param::Gain)]);
    bodyMix_ = params_[static_cast<int>(Param::BodyMix)];
    noteCounter_ = 0;
}

void Synth::setParameter(int index, float value) noexcept
{
    if (index < 0 || index >= paramCount) return;
    const Param p = static_cast<Param>(index);
    value = sanitise(p, value);
    float& slot = params_[static_cast<std::size_t>(index)];
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
    default: break;
    }
}

void Synth::applyFriction() noexcept
{
    const auto model = static_cast<dsp::FrictionModel>(static_cast<int>(params_[static_cast<int>(Param::FrictionModel)]));
    const auto law = params_[static_cast<int>(Param::ContactLaw)] > 0.5f ? dsp::ContactLaw::PowerLaw : dsp::ContactLaw::Amontons;
    for (auto& v : voices_)
        for (int s = 0; s < instrument_.stringCount; ++s) {
            auto& j = v.strings[static_cast<std::size_t>(s)].junction();
            j.setModel(model);
            j.setContactLaw(law, 2.0 / 3.0);
            j.setGlassTransition(params_[static_cast<int>(Param::RosinTg)]);
            j.setAmbient(params_[static_cast<int>(Param::Ambient)]);
            j.setFootprintRatio(params_[static_cast<int>(Param::Footprint)]);
        }
}

double Synth::noteFrequency(double midiNote) const noexcept
{
    return instrument_.tuningA4 * std::exp2((midiNote - 69.0) / 12.0);
}

bool Synth::reaches(int s, double frequency) const noexcept
{
    if (s < 0 || s >= instrument_.stringCount) return false;
    const double open = instrument_.strings[static_cast<std::size_t>(s)].fundamental();
    // A quarter-tone flat still counts as this string; the top is the highest stop.
    return frequency >= open * std::exp2(-0.5 / 12.0) && frequency <= open * std::exp2(instrument_.maxStopSemitones / 12.0);
}

void Synth::glideTo(Voice& v, int note) noexcept
{
    v.note = note;
    v.glideTarget = note;
    const double time = params_[static_cast<int>(Param::Portamento)];
    v.glideStep = time > 0.0 ? std::abs(v.glideTarget - v.pitch) * controlInterval / (time * fs_) : 1e9;
}

int Synth::chooseString(double frequency, int preferred, unsigned occupiedMask) const noexcept
{
    const int n = instrument_.stringCount;
    if (n <= 0) return 0;
    auto open = [&](int s) { return instrument_.strings[static_cast<std::size_t>(s)].fundamental(); };
    auto reachable = [&](int s) { return reaches(s, frequency); };
    if (external_.active && reachable(external_.string)) return external_.string; // the controller picked it
    const auto policy = static_cast<StringPolicy>(static_cast<int>(params_[static_cast<int>(Param::StringPolicy)]));
    if (policy == StringPolicy::StayOnString && reachable(preferred)) return preferred;
    if (policy == StringPolicy::FixedString) {
        const int fixed = std::clamp(static_cast<int>(params_[static_cast<int>(Param::FixedString)]) - 1, 0, n - 1);
        if (reachable(fixed)) return fixed;
    }
    // Lowest position: the highest open string at or below the note, a free one first.
    for (int pass = 0; pass < 2; ++pass)
        for (int s = n - 1; s >= 0; --s)
            if (reachable(s) && (pass == 1 || !(occupiedMask & (1u << s)))) return s;
    return frequency < open(0) ? 0 : n - 1; // below the instrument: the lowest string, tuned down
}

int Synth::chooseHarmonic(double frequency, int& string) const noexcept
{
    // Natural harmonics an octave and a twelfth up (the ones that speak readily on an open
    // string); beyond that an artificial harmonic: a stopped note touched a fourth (n = 4), a
    // fifth (3) or an octave (2) above, on a string that is really stopped.
    for (int n = 2; n <= 3; ++n)
        for (int s = instrument_.stringCount - 1; s >= 0; --s) {
            const double open = instrument_.strings[static_cast<std::size_t>(s)].fundamental();
            if (std::abs(1200.0 * std::log2(frequency / (n * open))) < 30.0) {
                string = s;
                return n;
            }
        }
    for (int n = 4; n >= 2; --n) {
        const int s = chooseString(frequency / n, -1, 0u);
        const double open = instrument_.strings[static_cast<std::size_t>(s)].fundamental();
        if (frequency / n > open * std::exp2(1.0 / 12.0)) { // at least a semitone up: a finger stops it
            string = s;
            return n;
        }
    }
    string = 0;
    return 2;
}

bool Synth::mpeMemberChannel(int channel) const noexcept { return masterOf(channel) >= 0; }

int Synth::masterOf(int channel) const noexcept
{
    const bool mpeOn = params_[static_cast<int>(Param::Mpe)] > 0.5f;
    const int lower = mcmLower_ >= 0 ? mcmLower_ : (mpeOn ? 15 : 0);
    const int upper = mcmUpper_ >= 0 ? mcmUpper_ : 0;
    if (lower > 0 && channel >= 1 && channel <= lower) return 0;
    if (upper > 0 && channel <= 14 && channel >= 15 - upper) return 15;
    return -1;
}

float Synth::bendRangeOf(int channel) const noexcept
{
    const ChannelState& c = channels_[static_cast<std::size_t>(channel)];
    if (c.bendRange >= 0.0f) return c.bendRange;
    if (masterOf(channel) >= 0) return static_cast<float>(memberBendRange);
    const bool isMaster = (channel == 0 && (mcmLower_ > 0 || (mcmLower_ < 0 && params_[static_cast<int>(Param::Mpe)] > 0.5f)))
                          || (channel == 15 && mcmUpper_ > 0);
    return isMaster ? static_cast<float>(masterBendRange) : params_[static_cast<int>(Param::BendRange)];
}

void Synth::panFor(int stringIndex, float& l, float& r) const noexcept
{
    const int n = std::max(1, instrument_.stringCount);
    const double centred = n > 1 ? (stringIndex - 0.5 * (n - 1)) / (0.5 * (n - 1)) : 0.0; // -1 low .. +1 high
    const double pan = std::clamp(centred * instrument_.panSpread * params_[static_cast<int>(Param::Width)], -1.0, 1.0);
    const double angle = 0.25 * std::numbers::pi * (pan + 1.0); // equal power
    l = static_cast<float>(std::cos(angle));
    r = static_cast<float>(std::sin(angle));
}

void Synth::handleMidi(const std::uint8_t* d, int size) noexcept
{
    if (size < 1 || d == nullptr) return;
    const int status = d[0] & 0xF0, ch = d[0] & 0x0F;
    auto byte = [&](int i) { return i < size ? static_cast<int>(d[i] & 0x7F) : 0; };
    switch (status) {
    case 0x90:
        if (byte(2) > 0) noteOn(ch, byte(1), byte(2));
        else noteOff(ch, byte(1));
        break;
    case 0x80: noteOff(ch, byte(1)); break;
    case 0xB0: controlChange(ch, byte(1), byte(2)); break;
    case 0xD0: channels_[static_cast<std::size_t>(ch)].pressure = static_cast<float>(byte(1)) / 127.0f; break;
    case 0xA0:
        for (auto& v : voices_)
            if (v.active && v.channel == ch && v.note == byte(1)) v.polyPressure = static_cast<float>(byte(2)) / 127.0f;
        break;
    case 0xE0: {
        const int value = byte(1) | (byte(2) << 7);
        channels_[static_cast<std::size_t>(ch)].bend = std::clamp(static_cast<float>(value - 8192) / 8191.0f, -1.0f, 1.0f);
        break;
    }
    default: break;
    }
}

void Synth::controlChange(int ch, int cc, int value) noexcept
{
    ChannelState& c = channels_[static_cast<std::size_t>(ch)];
    // RPN: select with 101/100, data with 6 (coarse) and 38 (fine); an NRPN deselects.
    if (cc == 101) { c.rpnMsb = value; return; }
    if (cc == 100) { c.rpnLsb = value; return; }
    if (cc == 99 || cc == 98) { c.rpnMsb = c.rpnLsb = 127; return; }
    if ((cc == 6 || cc == 38) && !(c.rpnMsb == 127 && c.rpnLsb == 127)) {
        dataEntry(ch, cc == 6, value);
        return;
    }
    // 14-bit pairs: 0-31 MSB, 32-63 LSB. A new MSB clears the LSB; an LSB refines the MSB.
    if (cc < 32) {
        c.msb[static_cast<std::size_t>(cc)] = static_cast<std::uint8_t>(value);
        c.lsb[static_cast<std::size_t>(cc)] = 0;
        c.lsbSeen[static_cast<std::size_t>(cc)] = false;
        controller(ch, cc, static_cast<float>(value) / 127.0f);
        return;
    }
    if (cc < 64) {
        const int m = cc - 32;
        c.lsb[static_cast<std::size_t>(m)] = static_cast<std::uint8_t>(value);
        c.lsbSeen[static_cast<std::size_t>(m)] = true;
        const int v14 = (c.msb[static_cast<std::size_t>(m)] << 7) | value;
        controller(ch, m, static_cast<float>(v14) / 16383.0f);
        return;
    }
    controller(ch, cc, static_cast<float>(value) / 127.0f);
}

void Synth::dataEntry(int ch, bool coarse, int value) noexcept
{
    ChannelState& c = channels_[static_cast<std::size_t>(ch)];
    if (c.rpnMsb != 0) return;
    if (c.rpnLsb == 0) { // pitch-bend sensitivity: semitones (coarse) + cents (fine)
        const float current = c.bendRange >= 0.0f ? c.bendRange : bendRangeOf(ch);
        if (coarse) c.bendRange = static_cast<float>(std::min(value, 96));
        else c.bendRange = std::floor(current) + static_cast<float>(value) / 100.0f;
    } else if (c.rpnLsb == 6 && coarse) { // MPE configuration message, on a master channel
        const int members = std::min(value, 15);
        if (ch == 0) { mcmLower_ = members; if (mcmUpper_ > 14 - members) mcmUpper_ = std::max(0, 14 - members); }
        if (ch == 15) { mcmUpper_ = members; if (mcmLower_ > 14 - members) mcmLower_ = std::max(0, 14 - members); }
        for (auto& other : channels_) other.bendRange = -1.0f; // the spec resets bend ranges
    }
}

void Synth::controller(int ch, int cc, float value) noexcept
{
    if (map_) {
        const ParamInfo* info = nullptr;
        if (const int armed = map_->learning(); armed >= 0 && armed < paramCount) info = &paramInfo(armed);
        if (info) map_->offerForLearn(cc, info->min, info->max);
        const MappingEntry e = map_->get(cc);
        if (e.param >= 0 && e.param < paramCount) {
            const float x = e.invert ? 1.0f - value : value;
            setParameter(e.param, e.min + (e.max - e.min) * x);
            return; // a learned controller loses its built-in meaning
        }
    }
    ChannelState& c = channels_[static_cast<std::size_t>(ch)];
    switch (cc) {
    case 1: c.vibrato = value; break;
    case 2: c.pressure = value; break;
    case 4:
    case 74: c.position = value; break;
    case 7: c.volume = value; break;
    case 20: // articulation by controller: the range split evenly
        setParameter(static_cast<int>(Param::Articulation),
                     std::min(static_cast<float>(dsp::Articulation::Count) - 1.0f, std::floor(value * static_cast<float>(dsp::Articulation::Count))));
        break;
    case 11: c.expression = value; break;
    case 64: {
        const bool on = value >= 0.5f;
        if (c.sustain && !on) { c.sustain = false; sustainOff(ch); }
        c.sustain = on;
        break;
    }
    case 120:
        for (auto& v : voices_)
            if (v.active && v.channel == ch) v.active = false;
        break;
    case 121: {
        const float range = c.bendRange;
        const auto msb = c.msb;
        c = ChannelState{};
        c.bendRange = range;
        c.msb = msb;
        sustainOff(ch);
        break;
    }
    case 123:
        for (auto& v : voices_)
            if (v.active && v.channel == ch) releaseVoice(v);
        break;
    default: break;
    }
}

void Synth::sustainOff(int ch) noexcept
{
    for (auto& v : voices_) {
        if (!v.active || !v.sustained || v.keyDown) continue;
        if (v.channel == ch || masterOf(v.channel) == ch) releaseVoice(v);
    }
}

Synth::Voice* Synth::findVoiceToStart() noexcept
{
    for (auto& v : voices_)
        if (!v.active) return &v;
    Voice* best = nullptr; // steal: the oldest released voice, else the oldest
    for (auto& v : voices_)
        if (v.released && (!best || v.order < best->order)) best = &v;
    if (best) return best;
    for (auto& v : voices_)
        if (!best || v.order < best->order) best = &v;
    return best;
}

void Synth::noteOn(int ch, int note, int velocity) noexcept
{
    if (note >= keyswitchBase && note < keyswitchBase + static_cast<int>(dsp::Articulation::Count)) {
        setParameter(static_cast<int>(Param::Articulation), static_cast<float>(note - keyswitchBase)); // a keyswitch, not a note
        return;
    }
    const double f = noteFrequency(note);
    const bool legato = params_[static_cast<int>(Param::Legato)] > 0.5f;
    if (legato) {
        // A held note on this channel hands its bow over: glide on its string if it reaches.
        for (auto& v : voices_) {
            if (!v.active || v.channel != ch || !v.keyDown || v.released) continue;
            if (reaches(v.stringIndex, f)) {
                if (v.heldCount < static_cast<int>(v.held.size())) v.held[static_cast<std::size_t>(v.heldCount++)] = note;
                else v.held.back() = note;
                glideTo(v, note);
                v.polyPressure = -1.0f;
                return;
            }
            releaseVoice(v); // string crossing: this string's bow lifts, the next one starts
        }
    }
    unsigned occupied = 0;
    for (auto& v : voices_)
        if (v.active && !v.released && v.channel == ch) occupied |= 1u << v.stringIndex;
    const int s = chooseString(f, lastString_[static_cast<std::size_t>(ch)], occupied);
    Voice* v = findVoiceToStart();
    startVoice(*v, ch, note, velocity, s);
    lastString_[static_cast<std::size_t>(ch)] = s;
}

void Synth::startVoice(Voice& v, int ch, int note, int velocity, int s) noexcept
{
    if (v.active) v.strings[static_cast<std::size_t>(v.stringIndex)].reset(); // stolen
    v.harmonic = 0;
    if (static_cast<int>(params_[static_cast<int>(Param::Articulation)]) == static_cast<int>(dsp::Articulation::Harmonic) &&
        !(params_[static_cast<int>(Param::ArticulationChannels)] > 0.5f)) {
        int hs = s;
        v.harmonic = chooseHarmonic(noteFrequency(note), hs);
        s = hs;
    }
    v.strings[static_cast<std::size_t>(s)].reset();
    v.strings[static_cast<std::size_t>(s)].waveguide().setHarmonic(v.harmonic, harmonicTouch);
    v.active = true;
    v.keyDown = true;
    v.sustained = false;
    v.released = false;
    v.channel = ch;
    v.note = note;
    v.stringIndex = s;
    v.velocity = static_cast<float>(velocity) / 127.0f;
    v.polyPressure = -1.0f;
    v.order = ++noteCounter_;
    v.held[0] = note;
    v.heldCount = 1;
    v.pitch = v.glideTarget = note;
    v.glideStep = 0.0;
    // Velocity is the attack: Guettler's constant bow acceleration from rest, and a force that
    // starts above the nominal and settles (a player "bites" harder for a louder attack). The
    // articulation shapes the stroke; consecutive notes on a channel alternate down and up bow
    // and continue from where on the bow the last one ended.
    dsp::GestureSettings gs;
    gs.bowLength = params_[static_cast<int>(Param::BowLength)];
    gs.acceleration = params_[static_cast<int>(Param::AttackAccel)];
    gs.attackBoost = params_[static_cast<int>(Param::AttackForce)];
    gs.releaseTime = params_[static_cast<int>(Param::ReleaseTime)];
    gs.tremoloRate = params_[static_cast<int>(Param::TremoloRate)];
    gs.spiccatoRate = params_[static_cast<int>(Param::SpiccatoRate)];
    const bool byChannel = params_[static_cast<int>(Param::ArticulationChannels)] > 0.5f;
    const int articulation = byChannel && ch < static_cast<int>(dsp::Articulation::Count)
                                 ? ch
                                 : static_cast<int>(params_[static_cast<int>(Param::Articulation)]);
    const auto cs = static_cast<std::size_t>(ch);
    const int direction = nextDirection_[cs] >= 0 ? 1 : -1;
    v.gesture.start(static_cast<dsp::Articulation>(articulation), v.velocity, gs, direction,
                    std::clamp(bowPosition_[cs], 0.0, gs.bowLength));
    nextDirection_[cs] = -direction;
    v.speed = 0.0;
    v.force = 0.0;
    v.aimForce = 0.0;
    v.lift = 1.0;
    v.fade = 1.0;
    v.age = 0.0;
    v.peak = 0.0;
    watched_ = &v; // the views follow the newest note
    watchedIsNew_ = true;
    if (tapArmed_) {
        tapArmed_ = false;
        tapVoice_ = &v;
        tapCount_ = 0;
    }
    v.vibratoPhase = 0.0;
    v.wasStick = true;
    v.samplesSinceSlip = v.periodsHeard = 0;
    v.heardPeriod = v.correctionCents = 0.0;
    v.beta = params_[static_cast<int>(Param::BowPosition)];
    v.untilControl = 0;
    panFor(s, v.gainL, v.gainR);
    updateControl(v);
    v.beta = std::clamp(v.beta, 0.02, 0.3); // start at the target, no glide of the bow point
}

void Synth::noteOff(int ch, int note) noexcept
{
    for (auto& v : voices_) {
        if (!v.active || v.channel != ch || !v.keyDown) continue;
        int at = -1;
        for (int i = 0; i < v.heldCount; ++i)
            if (v.held[static_cast<std::size_t>(i)] == note) at = i;
        if (at < 0) continue;
        for (int i = at; i + 1 < v.heldCount; ++i) v.held[static_cast<std::size_t>(i)] = v.held[static_cast<std::size_t>(i + 1)];
        --v.heldCount;
        if (v.heldCount > 0) { // legato: back to the note still held
            const int back = v.held[static_cast<std::size_t>(v.heldCount - 1)];
            if (back != v.note) glideTo(v, back);
            continue;
        }
        v.keyDown = false;
        const int master = masterOf(ch);
        const bool sustain = channels_[static_cast<std::size_t>(ch)].sustain ||
                             (master >= 0 && channels_[static_cast<std::size_t>(master)].sustain);
        if (sustain) v.sustained = true;
        else releaseVoice(v);
    }
}

void Synth::releaseVoice(Voice& v) noexcept
{
    v.keyDown = false;
    v.sustained = false;
    v.released = true;
    v.gesture.release();
    bowPosition_[static_cast<std::size_t>(v.channel)] = v.gesture.bowPosition();
}

void Synth::setVoiceTap(float* bridgeForce, std::uint8_t* stick, int capacity) noexcept
{
    tapBridge_ = bridgeForce;
    tapStick_ = stick;
    tapCapacity_ = bridgeForce ? capacity : 0;
    tapCount_ = 0;
    tapVoice_ = nullptr;
    tapArmed_ = bridgeForce != nullptr;
}

void Synth::applyBody() noexcept
{
    // A mute is a mass clamped on the bridge: the bridge hill and the upper body modes move down
    // and lose most of their output (Euphonics ch. 10's account of the mute; the factors are [A]).
    dsp::BodyParams b = instrument_.body;
    if (params_[static_cast<int>(Param::Mute)] > 0.5f)
        for (int i = 0; i < b.count; ++i) {
            auto& m = b.modes[static_cast<std::size_t>(i)];
            m.frequency *= m.frequency > 600.0 ? 0.8 : 0.95;
            if (m.frequency > 800.0) m.gain *= 0.3;
        }
    for (auto& body : body_) body.retune(fs_, b);
}

void Synth::setExternalBow(const ExternalBow& bow) noexcept
{
    external_ = bow;
    if (!std::isfinite(external_.force)) external_.force = 0.0f;
    if (!std::isfinite(external_.speed)) external_.speed = 0.0f;
    if (!std::isfinite(external_.beta)) external_.beta = 0.1f;
    external_.force = std::clamp(external_.force, 0.0f, 20.0f);
    external_.speed = std::clamp(external_.speed, -10.0f, 10.0f);
    external_.beta = std::clamp(external_.beta, 0.02f, 0.3f);
}

void Synth::releaseAll() noexcept
{
    for (auto& v : voices_)
        if (v.active) releaseVoice(v);
}

void Synth::killAll() noexcept
{
    for (auto& v : voices_) v.active = false;
}

void Synth::updateControl(Voice& v) noexcept
{
    const ChannelState& c = channels_[static_cast<std::size_t>(v.channel)];
    const int master = masterOf(v.channel);
    const ChannelState* m = master >= 0 ? &channels_[static_cast<std::size_t>(master)] : nullptr;
    auto pick = [&](float own, float fromMaster) { return own >= 0.0f ? own : (m ? fromMaster : -1.0f); };

    // Controllers scale the nominal parameters: a source at its middle (64) gives the nominal.
    float pressure = v.polyPressure >= 0.0f ? v.polyPressure : pick(c.pressure, m ? m->pressure : -1.0f);
    const float expression = pick(c.expression, m ? m->expression : -1.0f);
    const float position = pick(c.position, m ? m->position : -1.0f);
    if (external_.active) { // the controller is the bow: its values, in newtons and m/s
        v.targetForce = external_.engaged ? external_.force : 0.0;
        v.targetSpeed = external_.speed;
        v.beta += (external_.beta - v.beta) * betaSmoothing_;
        pressure = -1.0f;
    }
    const double forceScale = pressure < 0.0f ? 1.0 : 2.0 * pressure;
    const double speedScale = expression < 0.0f ? 1.0 : 2.0 * expression;
    const double betaScale = position < 0.0f ? 1.0 : std::exp2(2.0 * (position - 0.5));
    if (!external_.active) {
        v.targetForce = params_[static_cast<int>(Param::BowForce)] * forceScale * forceScale_[static_cast<std::size_t>(v.stringIndex)];
        v.targetSpeed = params_[static_cast<int>(Param::BowSpeed)] * speedScale;
        const double betaTarget = std::clamp(params_[static_cast<int>(Param::BowPosition)] * betaScale, 0.02, 0.3);
        v.beta += (betaTarget - v.beta) * betaSmoothing_;
    }
    v.volume = (m ? m->volume : 1.0f) * c.volume;

    // Pitch: glide (portamento), bend (channel, plus the zone master's in MPE), vibrato.
    if (v.pitch != v.glideTarget) {
        const double d = v.glideTarget - v.pitch;
        v.pitch = std::abs(d) <= v.glideStep ? v.glideTarget : v.pitch + std::copysign(v.glideStep, d);
    }
    double bend = c.bend * bendRangeOf(v.channel);
    if (m) bend += m->bend * bendRangeOf(master);
    v.age += controlInterval / fs_;
    const double onset = std::clamp((v.age - params_[static_cast<int>(Param::VibratoDelay)]) / 0.3, 0.0, 1.0);
    const double vibratoAmount = std::max({static_cast<double>(c.vibrato), m ? static_cast<double>(m->vibrato) : 0.0,
                                           params_[static_cast<int>(Param::VibratoAuto)] * onset});
    double vibrato = 0.0;
    if (vibratoAmount > 0.0) {
        vibrato = params_[static_cast<int>(Param::VibratoDepth)] / 100.0 * vibratoAmount * std::sin(v.vibratoPhase);
        v.vibratoPhase += 2.0 * std::numbers::pi * params_[static_cast<int>(Param::VibratoRate)] * controlInterval / fs_;
        if (v.vibratoPhase > 2.0 * std::numbers::pi) v.vibratoPhase -= 2.0 * std::numbers::pi;
    } else {
        v.vibratoPhase = 0.0;
    }
    v.targetPeriod = fs_ / noteFrequency(v.pitch + bend);
    const double intonation = params_[static_cast<int>(Param::Intonation)];
    if (v.gesture.plucked()) v.beta = 0.25; // plucked over the end of the fingerboard, struck likewise
    v.frequency = noteFrequency(v.pitch + bend + vibrato + intonation * v.correctionCents / 100.0);
    // Re-stopping redesigns the loss filters: skip moves below 0.02 cent (the ear's correction
    // creeps by less than that between periods once it has settled).
    auto& waveguide = v.strings[static_cast<std::size_t>(v.stringIndex)].waveguide();
    const double stopped = v.harmonic > 0 ? v.frequency / v.harmonic : v.frequency; // a harmonic: the string under it
    if (std::abs(stopped - waveguide.fundamental()) > 1e-5 * stopped) waveguide.setFundamental(stopped);
}

void Synth::renderVoice(Voice& v, float* busL, float* busR, int n) noexcept
{
    auto& string = v.strings[static_cast<std::size_t>(v.stringIndex)];
    const double dt = 1.0 / fs_;
    const double liftStep = dt / std::max(0.005, static_cast<double>(params_[static_cast<int>(Param::ReleaseTime)]));
    const float gl = v.gainL * v.volume * v.volume, gr = v.gainR * v.volume * v.volume;
    float theta = v.lastTemperature;
    const bool tapped = tapVoice_ == &v;
    const bool watched = viewRing_ != nullptr && watched_ == &v && viewRing_->listening();
    int viewed = 0;
    for (int i = 0; i < n; ++i) {
        if (v.untilControl-- <= 0) {
            updateControl(v);
            v.untilControl = controlInterval - 1;
        }
        double pluck = 0.0;
        bool bowOff = false;
        if (external_.active) { // a controller's hand is its own gesture (and may reverse): follow it
            v.speed += (v.targetSpeed - v.speed) * smoothing_;
            v.force += (v.targetForce - v.force) * smoothing_;
            if (v.released) v.lift = std::max(0.0, v.lift - liftStep);
            bowOff = v.released && v.lift <= 0.0;
        } else {
            v.aimForce += (v.targetForce - v.aimForce) * smoothing_;
            const dsp::GestureFrame g = v.gesture.next({v.aimForce, v.targetSpeed, v.beta});
            v.speed = g.speed;
            v.force = g.force;
            v.lift = 1.0;
            pluck = g.pluck;
            bowOff = v.gesture.off();
        }
        if (v.released && bowOff) v.fade *= ringCoefficient_;
        dsp::BowFrame<float> frame;
        float y = 0.0f;
        if (pluck != 0.0) { // the finger or the stick pushes the string; no friction
            string.waveguide().setBeta(v.beta);
            string.processForce(static_cast<float>(pluck));
            y = string.waveguide().bridgeForce();
            frame.stick = false;
        } else {
            y = string.processSample(static_cast<float>(v.force * v.lift), static_cast<float>(v.speed), static_cast<float>(v.beta), &frame);
        }
        theta = frame.temperature;
        listen(v, frame.stick);
        if (tapped && tapCount_ < tapCapacity_) {
            tapBridge_[tapCount_] = y;
            if (tapStick_) tapStick_[tapCount_] = frame.stick ? 1 : 0;
            ++tapCount_;
        }
        if (watched) {
            ViewFrame& f = viewChunk_[static_cast<std::size_t>(viewed++)];
            f.bridgeForce = y;
            f.velocity = frame.velocity;
            f.bowSpeed = static_cast<float>(v.speed);
            f.friction = frame.friction;
            f.force = pluck != 0.0 ? 0.0f : static_cast<float>(v.force * v.lift);
            f.temperature = frame.temperature;
            f.beta = static_cast<float>(v.beta);
            f.frequency = static_cast<float>(v.frequency);
            f.stick = frame.stick ? 1 : 0;
            f.string = static_cast<std::uint8_t>(v.stringIndex);
            f.noteStart = watchedIsNew_ ? 1 : 0;
            f.bowed = pluck != 0.0 ? 0 : 1;
            watchedIsNew_ = false;
        }
        const float out = static_cast<float>(y * v.fade);
        busL[i] += gl * out;
        busR[i] += gr * out;
        const double a = std::abs(static_cast<double>(out));
        v.peak = std::max(v.peak, a);
        if (v.released && bowOff && v.fade < silence) {
            v.active = false;
            string.reset();
            if (tapped) tapVoice_ = nullptr;
            break;
        }
    }
    if (viewed > 0) viewRing_->write(viewChunk_.data(), static_cast<std::size_t>(viewed));
    v.lastTemperature = theta;
}

void Synth::listen(Voice& v, bool stick) noexcept
{
    // A slip onset each Helmholtz period: the interval between onsets is the sounding period.
    // Bowed strings play flat as the force rises (the corner rounds and is delayed at each
    // capture); a player hears it and moves the finger. Intervals far from the target (a
    // double slip, raucous motion, a glide) are ignored, and the finger moves a little each period.
    ++v.samplesSinceSlip;
    if (v.wasStick && !stick && v.targetPeriod > 0.0) {
        // A secondary slip inside the period (a double slip, a ripple that broke free) does
        // not end the period: keep counting to the next onset about one period later.
        const double interval = v.samplesSinceSlip;
        if (interval >= 0.85 * v.targetPeriod) {
            if (interval < 1.15 * v.targetPeriod) {
                v.heardPeriod = v.periodsHeard == 0 ? interval : v.heardPeriod + 0.2 * (interval - v.heardPeriod);
                if (++v.periodsHeard > 4) {
                    const double errorCents = 1200.0 * std::log2(v.heardPeriod / v.targetPeriod); // > 0: flat
                    v.correctionCents = std::clamp(v.correctionCents + 0.08 * errorCents, -50.0, 100.0);
                }
            }
            v.samplesSinceSlip = 0;
        }
    }
    v.wasStick = stick;
}

void Synth::render(float* left, float* right, int numSamples) noexcept
{
    NoDenormals guard;
    const double bodyTarget = params_[static_cast<int>(Param::BodyMix)];
    const float direct = static_cast<float>(instrument_.body.outputScale);
    for (int start = 0; start < numSamples; start += chunk) {
        const int n = std::min(chunk, numSamples - start);
        std::fill_n(busL_.data(), n, 0.0f);
        std::fill_n(busR_.data(), n, 0.0f);
        if (viewRing_ != nullptr && (watched_ == nullptr || !watched_->active)) chooseWatched();
        for (auto& v : voices_)
            if (v.active) renderVoice(v, busL_.data(), busR_.data(), n);
        for (int i = 0; i < n; ++i) {
            gain_ += (gainTarget_ - gain_) * smoothing_;
            bodyMix_ += (bodyTarget - bodyMix_) * smoothing_;
            const float mix = static_cast<float>(bodyMix_), g = static_cast<float>(gain_);
            const float l = busL_[static_cast<std::size_t>(i)], r = busR_[static_cast<std::size_t>(i)];
            const float bl = body_[0].processSample(l), br = body_[1].processSample(r);
            float outL = g * (mix * bl + (1.0f - mix) * direct * l);
            float outR = g * (mix * br + (1.0f - mix) * direct * r);
            // Last line of defence: whatever went wrong upstream, the host gets no NaN or a blast.
            if (!std::isfinite(outL) || !std::isfinite(outR)) { outL = outR = 0.0f; body_[0].reset(); body_[1].reset(); }
            left[start + i] = std::clamp(outL, -4.0f, 4.0f);
            right[start + i] = std::clamp(outR, -4.0f, 4.0f);
        }
    }
}

void Synth::chooseWatched() noexcept
{
    // The watched note ended: follow the newest one still sounding.
    const Voice* best = nullptr;
    for (const auto& v : voices_)
        if (v.active && (best == nullptr || v.order > best->order)) best = &v;
    if (best != watched_) watchedIsNew_ = best != nullptr;
    watched_ = best;
}

int Synth::activeVoiceCount() const noexcept
{
    int n = 0;
    for (const auto& v : voices_) n += v.active ? 1 : 0;
    return n;
}

VoiceInfo Synth::voiceInfo(int index) const noexcept
{
    VoiceInfo info;
    if (index < 0 || index >= maxVoices) return info;
    const Voice& v = voices_[static_cast<std::size_t>(index)];
    info.active = v.active;
    if (!v.active) return info;
    info.channel = v.channel;
    info.note = v.note;
    info.stringIndex = v.stringIndex;
    info.keyDown = v.keyDown;
    info.released = v.released;
    info.frequency = v.frequency;
    info.correctionCents = v.correctionCents;
    info.force = v.force * v.lift;
    info.bowDirection = v.speed > 0.0 ? 1 : v.speed < 0.0 ? -1 : 0;
    info.bowPosition = v.gesture.bowPosition();
    info.speed = v.speed;
    info.beta = v.beta;
    info.temperature = v.lastTemperature;
    return info;
}

} // namespace rosin::engine
