// The parameter layer's common currency. Every source - MIDI 1.0 controllers and pressure, MPE
// per-note messages, HID controllers, learned controllers, the on-screen keyboard - arrives as a
// ControlEvent: a normalised value with a frame offset inside the block. Turning the normalised
// bow controls into newtons, m/s and a bow position happens in one place, mapBow(), with the
// same string scaling and the same limits (dsp::config) for every source.
#pragma once
#include <cstdint>

#include "rosin/engine/Parameters.h"

namespace rosin::engine {

enum class Control : std::uint8_t {
    NoteOn,       ///< `note`; value = velocity 0..1
    NoteOff,      ///< `note`
    Force,        ///< 0..1, 0.5 = the nominal bow force; per note when `note` >= 0 (MPE, poly pressure)
    Speed,        ///< 0..1, 0.5 = the nominal bow speed (the virtual player chooses the direction)
    Position,     ///< 0..1, 0.5 = the nominal bow position
    Vibrato,      ///< 0..1 (CC1)
    Volume,       ///< 0..1 (CC7)
    Bend,         ///< semitones (the decoder applied the channel's bend range)
    Sustain,      ///< 0 or 1
    DirectSpeed,  ///< a controller's hand holds the bow: signed -1..1, 0.5 = nominal, sign = direction
    Engage,       ///< a held bow touches the string (1) or not (0)
    DirectRelease,///< the controller has let go of the bow: the virtual player bows again
    DirectForce,  ///< 0..1 like Force, from the controller that holds the bow; forgotten when it lets go
    DirectPosition,///< 0..1 like Position, from the controller that holds the bow; forgotten when it lets go
    StringChoice, ///< value = the string new notes on this channel prefer (0 = lowest), -1 none
    Parameter,    ///< host parameter `index` takes `value` in its own units (a learned controller, a keyswitch)
    Learned,      ///< a MIDI-learn completed: controller `note` now drives parameter `index`
    SoundOff,     ///< all sound off on the channel (CC120)
    NotesOff,     ///< all notes off on the channel (CC123)
    ResetControls,///< reset all controllers (CC121)
    Zones,        ///< MPE zones from a configuration message: `note` = lower-zone members, value = upper-zone members
};

struct ControlEvent {
    int frame = 0;            ///< offset inside the block
    Control kind = Control::Force;
    std::int8_t channel = 0;  ///< 0-15
    std::int8_t note = -1;    ///< the note (or the controller of a Learned event); -1 channel-wide
    std::int16_t index = -1;  ///< Parameter / Learned: the Param index
    float value = 0.0f;
};

/// A bow in physical units.
struct BowTarget {
    double force = 0.0, speed = 0.0, beta = 0.1; ///< N, m/s (signed), fraction of the string
};

/// The one mapping from normalised bow controls to the model's units. force01, position01 in
/// 0..1 and speed in -1..1 (0.5 = the nominal parameter; sign = direction); a negative force or
/// position means "not sent": the nominal. `stringScale` is Z0(string) / Z0(reference string),
/// so every string sits at the same place in Schelleng's diagram. Results are clamped to the
/// model's own limits (dsp::config).
BowTarget mapBow(const ParamValues& params, double stringScale, float force01, float speed, float position01) noexcept;

} // namespace rosin::engine
