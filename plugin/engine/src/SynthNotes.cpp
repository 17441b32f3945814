// The Synth's note lifecycle: which voice a note gets (a free one, else the quietest released
// one, faded out over a few ms in a spare slot), which string and position, the legato hand-over
// of a sounding string, release, the sustain pedal, and notes resumed after an engine swap.
// Audio thread; no allocation.
#include <algorithm>
#include <cmath>

#include "rosin/engine/Synth.h"

namespace rosin::engine {
namespace {
constexpr std::size_t index(Param p) { return static_cast<std::size_t>(p); }
} // namespace

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
                                  static_cast<int>(params_[index(Param::FixedString)]), performance_->effective(ch).hand.preferredString,
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

} // namespace rosin::engine
