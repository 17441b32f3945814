#include "rosin/engine/MidiDecoder.h"

#include <algorithm>
#include <cmath>

#include "rosin/dsp/BowGesture.h"

namespace rosin::engine {
namespace {
ControlEvent make(int frame, Control kind, int channel, float value, int note = -1, int index = -1)
{
    ControlEvent e;
    e.frame = frame;
    e.kind = kind;
    e.channel = static_cast<std::int8_t>(channel);
    e.note = static_cast<std::int8_t>(note);
    e.index = static_cast<std::int16_t>(index);
    e.value = value;
    return e;
}
} // namespace

void MidiDecoder::reset() noexcept { channels_ = {}; }

float MidiDecoder::bendRange(int ch, const Performance& performance, const ParamValues& params) const noexcept
{
    const ChannelParse& c = channels_[static_cast<std::size_t>(ch & 15)];
    if (c.bendRange >= 0.0f) return c.bendRange;
    if (performance.masterOf(ch) >= 0) return static_cast<float>(memberBendRange);
    if (performance.isMaster(ch)) return static_cast<float>(masterBendRange);
    return sanitise(Param::BendRange, params[static_cast<std::size_t>(Param::BendRange)]);
}

int MidiDecoder::decode(const std::uint8_t* d, int size, int frame, const Performance& performance, const ParamValues& params,
                        const ControllerTable* learned, int learnArmed, ControlEvent* out) noexcept
{
    if (size < 1 || d == nullptr || (d[0] & 0x80) == 0) return 0;
    const int status = d[0] & 0xF0, ch = d[0] & 0x0F;
    auto byte = [&](int i) { return i < size ? static_cast<int>(d[i] & 0x7F) : 0; };
    switch (status) {
    case 0x90:
    case 0x80: {
        const int note = byte(1);
        const bool on = status == 0x90 && byte(2) > 0;
        if (note >= keyswitchBase && note < keyswitchBase + static_cast<int>(dsp::Articulation::Count)) {
            // A keyswitch chooses the articulation; it is not a note.
            if (!on) return 0;
            out[0] = make(frame, Control::Parameter, ch, static_cast<float>(note - keyswitchBase), -1, static_cast<int>(Param::Articulation));
            return 1;
        }
        out[0] = make(frame, on ? Control::NoteOn : Control::NoteOff, ch, static_cast<float>(byte(2)) / 127.0f, note);
        return 1;
    }
    case 0xB0: {
        ChannelParse& c = channels_[static_cast<std::size_t>(ch)];
        const int cc = byte(1), value = byte(2);
        // RPN: select with 101/100, data with 6 (coarse) and 38 (fine); an NRPN deselects.
        if (cc == 101) { c.rpnMsb = value; return 0; }
        if (cc == 100) { c.rpnLsb = value; return 0; }
        if (cc == 99 || cc == 98) { c.rpnMsb = c.rpnLsb = 127; return 0; }
        if ((cc == 6 || cc == 38) && !(c.rpnMsb == 127 && c.rpnLsb == 127)) return dataEntry(ch, cc == 6, value, frame, performance, params, out);
        // 14-bit pairs: 0-31 MSB, 32-63 LSB. A new MSB stands alone until its LSB refines it.
        if (cc < 32) {
            c.msb[static_cast<std::size_t>(cc)] = static_cast<std::uint8_t>(value);
            return controller(ch, cc, static_cast<float>(value) / 127.0f, frame, params, learned, learnArmed, out);
        }
        if (cc < 64) {
            const int m = cc - 32;
            const int v14 = (c.msb[static_cast<std::size_t>(m)] << 7) | value;
            return controller(ch, m, static_cast<float>(v14) / 16383.0f, frame, params, learned, learnArmed, out);
        }
        return controller(ch, cc, static_cast<float>(value) / 127.0f, frame, params, learned, learnArmed, out);
    }
    case 0xD0: out[0] = make(frame, Control::Force, ch, static_cast<float>(byte(1)) / 127.0f); return 1;
    case 0xA0: out[0] = make(frame, Control::Force, ch, static_cast<float>(byte(2)) / 127.0f, byte(1)); return 1;
    case 0xE0: {
        const int value = byte(1) | (byte(2) << 7);
        const float bend = std::clamp(static_cast<float>(value - 8192) / 8191.0f, -1.0f, 1.0f);
        out[0] = make(frame, Control::Bend, ch, bend * bendRange(ch, performance, params));
        return 1;
    }
    default: return 0;
    }
}

int MidiDecoder::controller(int ch, int cc, float value, int frame, const ParamValues& params, const ControllerTable* learned,
                            int learnArmed, ControlEvent* out) noexcept
{
    // A learned controller drives its parameter and loses its built-in meaning.
    if (learnArmed >= 0 && learnArmed < paramCount && cc < ControllerTable::numControllers) {
        const ParamInfo& info = paramInfo(learnArmed);
        out[0] = make(frame, Control::Learned, ch, 0.0f, cc, learnArmed);
        out[1] = make(frame, Control::Parameter, ch, info.min + (info.max - info.min) * value, -1, learnArmed);
        return 2;
    }
    if (learned) {
        const MappingEntry& e = learned->get(cc);
        if (e.param >= 0 && e.param < paramCount) {
            const float x = e.invert ? 1.0f - value : value;
            out[0] = make(frame, Control::Parameter, ch, e.min + (e.max - e.min) * x, -1, e.param);
            return 1;
        }
    }
    switch (cc) {
    case 1: out[0] = make(frame, Control::Vibrato, ch, value); return 1;
    case 2: out[0] = make(frame, Control::Force, ch, value); return 1;
    case 4:
    case 74: out[0] = make(frame, Control::Position, ch, value); return 1;
    case 7: out[0] = make(frame, Control::Volume, ch, value); return 1;
    case 11: out[0] = make(frame, Control::Speed, ch, value); return 1;
    case 20: { // articulation by controller: the range split evenly
        const float n = static_cast<float>(dsp::Articulation::Count);
        out[0] = make(frame, Control::Parameter, ch, std::min(n - 1.0f, std::floor(value * n)), -1, static_cast<int>(Param::Articulation));
        return 1;
    }
    case 64: out[0] = make(frame, Control::Sustain, ch, value >= 0.5f ? 1.0f : 0.0f); return 1;
    case 120: out[0] = make(frame, Control::SoundOff, ch, 0.0f); return 1;
    case 121: out[0] = make(frame, Control::ResetControls, ch, 0.0f); return 1;
    case 123: out[0] = make(frame, Control::NotesOff, ch, 0.0f); return 1;
    default: return 0;
    }
    (void)params;
}

int MidiDecoder::dataEntry(int ch, bool coarse, int value, int frame, const Performance& performance, const ParamValues& params,
                           ControlEvent* out) noexcept
{
    ChannelParse& c = channels_[static_cast<std::size_t>(ch)];
    if (c.rpnMsb != 0) return 0;
    if (c.rpnLsb == 0) { // pitch-bend sensitivity: semitones (coarse) + cents (fine)
        const float current = bendRange(ch, performance, params);
        c.bendRange = coarse ? static_cast<float>(std::min(value, 96)) : std::floor(current) + static_cast<float>(value) / 100.0f;
        return 0;
    }
    if (c.rpnLsb == 6 && coarse && (ch == 0 || ch == 15)) { // MPE configuration message, on a master channel
        const int members = std::min(value, 15);
        int lower = performance.lowerMembers(), upper = performance.upperMembers();
        if (ch == 0) {
            lower = members;
            if (upper > 14 - members) upper = std::max(0, 14 - members);
        } else {
            upper = members;
            if (lower > 14 - members) lower = std::max(0, 14 - members);
        }
        for (auto& other : channels_) other.bendRange = -1.0f; // the spec resets bend ranges
        out[0] = make(frame, Control::Zones, ch, static_cast<float>(upper), lower);
        return 1;
    }
    return 0;
}

} // namespace rosin::engine
