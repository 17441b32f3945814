// MIDI 1.0 and MPE in, ControlEvents out. What a message means can depend on what came before
// (an RPN selection, the MSB of a 14-bit pair, a channel's bend range, the MPE zones, a learned
// controller), so the decoder keeps that parsing state; like the Performance it outlives any
// engine. Audio thread; no allocation.
#pragma once
#include <array>
#include <cstdint>

#include "rosin/engine/ControllerMap.h"
#include "rosin/engine/Controls.h"
#include "rosin/engine/Performance.h"

namespace rosin::engine {

class MidiDecoder {
public:
    static constexpr int maxEvents = 4; ///< events one message can make
    static constexpr int memberBendRange = 48, masterBendRange = 2; ///< MPE defaults (M1-100-UM)
    /// Lowest MIDI note that is a keyswitch (C0): articulation n is this note + n.
    static constexpr int keyswitchBase = 12;

    void reset() noexcept;

    /// One message (running status is not expected: hosts expand it) at `frame`. Writes up to
    /// maxEvents events to `out` and returns how many. `learned` is the controller table in
    /// use (nullptr: none); `learnArmed` is the parameter a MIDI-learn waits for, or -1 (the
    /// next controller then yields a Learned event and drives that parameter at once).
    int decode(const std::uint8_t* data, int size, int frame, const Performance& performance, const ParamValues& params,
               const ControllerTable* learned, int learnArmed, ControlEvent* out) noexcept;

    /// The semitones a full pitch bend spans on this channel now.
    float bendRange(int channel, const Performance& performance, const ParamValues& params) const noexcept;

private:
    struct ChannelParse {
        std::array<std::uint8_t, 32> msb{};
        int rpnMsb = 127, rpnLsb = 127;
        float bendRange = -1.0f; ///< from RPN 0, < 0 while unset
    };
    int controller(int ch, int cc, float value, int frame, const ParamValues& params, const ControllerTable* learned, int learnArmed,
                   ControlEvent* out) noexcept;
    int dataEntry(int ch, bool coarse, int value, int frame, const Performance& performance, const ParamValues& params,
                  ControlEvent* out) noexcept;
    std::array<ChannelParse, 16> channels_{};
};

} // namespace rosin::engine
