// Host-automatable parameters of the instrument, in physical units. The IDs are stable: hosts
// store automation and sessions under them, so never rename or reuse one.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rosin::engine {

enum class Param : int {
    BowForce,        ///< nominal bow force (N)
    BowSpeed,        ///< nominal bow speed (m/s)
    BowPosition,     ///< nominal bow position beta (fraction of the vibrating length)
    FrictionModel,   ///< 0 friction curve, 1 thermal, 2 enhanced thermal
    ContactLaw,      ///< 0 Amontons, 1 Hertzian (A ~ F^2/3)
    RosinTg,         ///< rosin glass transition (C)
    Ambient,         ///< room temperature (C)
    Footprint,       ///< footprint ratio r_A (bow / steady-sliding test)
    AttackAccel,     ///< bow acceleration at full velocity (m/s^2), Guettler's a
    AttackForce,     ///< extra initial force at full velocity (fraction of nominal)
    ReleaseTime,     ///< bow lift time after note-off (s)
    Portamento,      ///< glide time for legato notes on one string (s)
    Legato,          ///< 0 off, 1 on (a held note hands its bow to the next on the same channel)
    StringPolicy,    ///< 0 lowest position, 1 stay on string, 2 fixed string
    FixedString,     ///< string used by the fixed policy (1 = lowest)
    BendRange,       ///< pitch-bend range for non-MPE channels (semitones)
    VibratoRate,     ///< Hz
    VibratoDepth,    ///< cents at full CC1
    BodyMix,         ///< 0 bare bridge force, 1 full body
    Width,           ///< stereo spread of the strings (0 mono, 1 full)
    Gain,            ///< output gain (dB)
    Mpe,             ///< 0 off, 1 on (lower zone, 15 member channels) until an MCM says otherwise
    Intonation,      ///< 0: the string's own pitch (flattens with force); 1: the finger corrects by ear
    Articulation,    ///< dsp::Articulation: detache, martele, spiccato, tremolo, col legno, pizzicato
    TremoloRate,     ///< bow strokes per second
    SpiccatoRate,    ///< bounces per second
    BowLength,       ///< usable hair (m): long notes change bow when it runs out
    VibratoAuto,     ///< automatic vibrato amount (0-1 of vibrato_depth), besides CC1
    VibratoDelay,    ///< s after the note start before the automatic vibrato sets in
    Mute,            ///< sordino: a mass on the bridge
    ArticulationChannels, ///< 0 off, 1: MIDI channel n plays articulation n (1 = detache)
    Count
};

inline constexpr int paramCount = static_cast<int>(Param::Count);

struct ParamInfo {
    std::string_view id;    ///< stable host ID
    std::string_view name;  ///< shown to people
    std::string_view unit;
    float min, max, def;
    float centre;           ///< value at the middle of a slider (skew), = (min+max)/2 for linear
    /// 0 continuous; n > 0 a choice with n host slots. A choice that may grow has more slots
    /// than names: the spare ones play the last choice, and a choice added later takes a spare
    /// slot, so the normalised value of every existing choice (automation, sessions) stays put.
    int steps;
    std::string_view choices; ///< '|'-separated names of the choices min..max, empty if not a choice
};

/// The table of every parameter, indexed by Param.
const ParamInfo& paramInfo(Param p) noexcept;
inline const ParamInfo& paramInfo(int i) noexcept { return paramInfo(static_cast<Param>(i)); }

/// Index of a parameter by its stable ID, or -1.
int paramIndex(std::string_view id) noexcept;

/// The names of a choice parameter's steps, in order (empty for a continuous one).
std::vector<std::string> choiceNames(Param p);
/// The step of a choice parameter named `name` (case-insensitive), or -1.
int choiceIndex(Param p, std::string_view name);

/// Clamp into range, snap choices, and replace NaN/inf by the default: whatever a host or a
/// controller sends, the model gets a playable value.
float sanitise(Param p, float value) noexcept;

using ParamValues = std::array<float, paramCount>;
ParamValues defaultParams() noexcept;

} // namespace rosin::engine
