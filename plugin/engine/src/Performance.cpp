#include "rosin/engine/Performance.h"

#include <algorithm>
#include <cmath>

namespace rosin::engine {

void Performance::reset() noexcept
{
    channels_ = {};
    lower_ = upper_ = -1;
    heldCount_ = 0;
}

void Performance::stop() noexcept
{
    channels_ = {};
    heldCount_ = 0;
}

int Performance::masterOf(int channel) const noexcept
{
    const int lower = lowerMembers(), upper = upperMembers();
    if (lower > 0 && channel >= 1 && channel <= lower) return 0;
    if (upper > 0 && channel <= 14 && channel >= 15 - upper) return 15;
    return -1;
}

bool Performance::isMaster(int channel) const noexcept
{
    return (channel == 0 && lowerMembers() > 0) || (channel == 15 && upperMembers() > 0);
}

Performance::Channel Performance::effective(int c) const noexcept
{
    Channel e = channel(c);
    const int master = masterOf(c);
    if (master < 0) return e;
    const Channel& m = channel(master);
    if (e.force < 0.0f) e.force = m.force;
    if (e.speed < 0.0f) e.speed = m.speed;
    if (e.position < 0.0f) e.position = m.position;
    e.vibrato = std::max(e.vibrato, m.vibrato);
    e.volume *= m.volume;
    e.bend += m.bend;
    e.sustain = e.sustain || m.sustain;
    if (!e.hand.holds && m.hand.holds) e.hand = m.hand;
    return e;
}

void Performance::removeHeld(int channel, int note) noexcept
{
    for (int i = 0; i < heldCount_; ++i)
        if (held_[static_cast<std::size_t>(i)].channel == channel && (note < 0 || held_[static_cast<std::size_t>(i)].note == note)) {
            held_[static_cast<std::size_t>(i)] = held_[static_cast<std::size_t>(--heldCount_)];
            --i;
        }
}

void Performance::releaseSustained(int channel) noexcept
{
    for (int i = 0; i < heldCount_; ++i) {
        const Held& h = held_[static_cast<std::size_t>(i)];
        if (h.sustained && (h.channel == channel || masterOf(h.channel) == channel)) {
            held_[static_cast<std::size_t>(i)] = held_[static_cast<std::size_t>(--heldCount_)];
            --i;
        }
    }
}

void Performance::apply(const ControlEvent& e) noexcept
{
    const int c = e.channel & 15;
    Channel& ch = channels_[static_cast<std::size_t>(c)];
    const float v = std::isfinite(e.value) ? e.value : 0.0f;
    switch (e.kind) {
    case Control::NoteOn: {
        removeHeld(c, e.note);
        if (heldCount_ < maxHeld) held_[static_cast<std::size_t>(heldCount_++)] = {static_cast<std::int8_t>(c), e.note, std::clamp(v, 0.0f, 1.0f), false};
        break;
    }
    case Control::NoteOff: {
        const bool pedal = ch.sustain || (masterOf(c) >= 0 && channel(masterOf(c)).sustain);
        if (!pedal) {
            removeHeld(c, e.note);
            break;
        }
        for (int i = 0; i < heldCount_; ++i)
            if (held_[static_cast<std::size_t>(i)].channel == c && held_[static_cast<std::size_t>(i)].note == e.note)
                held_[static_cast<std::size_t>(i)].sustained = true;
        break;
    }
    case Control::Force:
        if (e.note < 0) ch.force = std::clamp(v, 0.0f, 1.0f);
        break;
    case Control::Speed: ch.speed = std::clamp(v, 0.0f, 1.0f); break;
    case Control::Position: ch.position = std::clamp(v, 0.0f, 1.0f); break;
    case Control::Vibrato: ch.vibrato = std::clamp(v, 0.0f, 1.0f); break;
    case Control::Volume: ch.volume = std::clamp(v, 0.0f, 1.0f); break;
    case Control::Bend: ch.bend = std::clamp(v, -96.0f, 96.0f); break;
    case Control::Sustain: {
        const bool on = v >= 0.5f;
        if (ch.sustain && !on) {
            ch.sustain = false;
            releaseSustained(c);
        }
        ch.sustain = on;
        break;
    }
    case Control::DirectSpeed:
        ch.hand.holds = true;
        ch.hand.speed = std::clamp(v, -1.0f, 1.0f);
        break;
    case Control::Engage:
        ch.hand.holds = true;
        ch.hand.engaged = v >= 0.5f;
        break;
    case Control::DirectRelease: ch.hand = {}; break;
    case Control::DirectForce: ch.hand.force = std::clamp(v, 0.0f, 1.0f); break;
    case Control::DirectPosition: ch.hand.position = std::clamp(v, 0.0f, 1.0f); break;
    case Control::StringChoice: ch.hand.preferredString = v >= 0.0f ? static_cast<int>(v) : -1; break;
    case Control::SoundOff:
    case Control::NotesOff: removeHeld(c, -1); break;
    case Control::ResetControls: {
        // RP-015: controllers back to their defaults; the bend range and the pedal's notes go too.
        const Channel::Hand kept = ch.hand;
        ch = Channel{};
        ch.hand = kept;
        releaseSustained(c);
        break;
    }
    case Control::Zones: {
        lower_ = std::clamp(static_cast<int>(e.note), 0, 15);
        upper_ = std::clamp(static_cast<int>(v), 0, 15);
        break;
    }
    case Control::Parameter:
    case Control::Learned: break;
    }
}

} // namespace rosin::engine
