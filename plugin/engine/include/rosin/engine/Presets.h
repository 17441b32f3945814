// The instrument's presets come from the presets library (rosin/presets: one JSON reader, the
// factory set in the binary, user folders). What the engine adds: a controller map resolved
// against its own parameter table.
#pragma once
#include <string>
#include <vector>

#include "rosin/presets/Presets.h"

namespace rosin::engine {

using presets::ExciterPreset;
using presets::InstrumentPreset;
using presets::maxStrings;

struct MappingEntry {
    int cc = -1;          ///< controller number 0-119 (an MSB number for 14-bit pairs)
    int param = -1;       ///< Param index
    float min = 0.0f, max = 1.0f;
    bool invert = false;
};

struct MappingPreset {
    std::string name;
    bool mpe = false;
    bool mpeGiven = false;
    int articulation = -1;         ///< articulation index the map selects, -1 = leave it
    int articulationChannels = -1; ///< 1: MIDI channel n plays articulation n, 0 off, -1 leave it
    std::vector<MappingEntry> entries;
};

/// A controller map with its parameter IDs and articulation name looked up in the engine's
/// table; ranges default to the parameter's own and must lie inside it. Throws
/// presets::PresetError naming the map and the entry at fault.
MappingPreset resolveMapping(const presets::MappingPreset& written);
inline MappingPreset loadControllerMap(const presets::Library& lib, const std::string& nameOrPath)
{
    return resolveMapping(presets::loadMapping(lib, nameOrPath));
}

} // namespace rosin::engine
