// The preset kinds and their readers: strings (rosin-strings/1), rosin (rosin-rosin/1),
// instruments (rosin-instrument/1), exciters (rosin-exciter/1) and MIDI controller maps
// (rosin-mapping/1). Every reader goes through Document, so a broken file is refused with its
// origin and the field named. Setup threads only.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "rosin/dsp/Body.h"
#include "rosin/dsp/BowJunction.h"
#include "rosin/dsp/StringParams.h"
#include "rosin/presets/Library.h"

namespace rosin::presets {

struct StringPreset {
    std::string id;          ///< "cello-D"
    std::string instrument;  ///< "cello"
    std::string note;        ///< "D3"
    dsp::StringParams params;
};

/// All strings of one strings/ preset ("cello") or file. Throws PresetError naming it and the field.
std::vector<StringPreset> loadStrings(const Library& lib, const std::string& nameOrPath);
/// Every string of every strings/ preset.
std::vector<StringPreset> allStrings(const Library& lib);
/// One string by id ("cello-D", case-insensitive), or "path/to/file.json:NAME". Throws
/// PresetError listing what exists when it is not found.
StringPreset findString(const Library& lib, const std::string& id);

struct RosinPreset {
    std::string name;
    double glassTransitionCelsius = 49.0;
};
/// A rosin by name ("violin", "bass") or a path to a rosin JSON file.
RosinPreset findRosin(const Library& lib, const std::string& nameOrPath);

inline constexpr int maxStrings = 5; // five-string basses exist; the shipped presets have four

struct InstrumentPreset {
    std::string name = "cello";
    std::string origin;
    int stringCount = 0;
    std::array<dsp::StringParams, maxStrings> strings{};
    std::array<std::string, maxStrings> stringNames{};
    double tuningA4 = 440.0;
    double maxStopSemitones = 24.0; ///< highest stop on a string, above its open pitch
    dsp::BodyParams body;
    double panSpread = 0.5;
    // Defaults the preset gives the bow parameters when it is loaded.
    double bowForce = 0.8, bowSpeed = 0.15, bowPosition = 0.09, attackAccel = 4.0;
    double rosinTg = 49.0;
};
InstrumentPreset loadInstrument(const Library& lib, const std::string& nameOrPath);

struct ExciterPreset {
    std::string name;
    dsp::FrictionModel model = dsp::FrictionModel::Thermal;
    dsp::ContactLaw contact = dsp::ContactLaw::Amontons;
    double footprintRatio = 1.0;
    double ambient = 20.0;
};
ExciterPreset loadExciter(const Library& lib, const std::string& nameOrPath);

/// A MIDI controller map as written: parameters by their host ID (the engine resolves them).
struct MappingPreset {
    struct Entry {
        int cc = -1;
        std::string param;
        bool hasMin = false, hasMax = false;
        double min = 0.0, max = 1.0;
        bool invert = false;
    };
    std::string name, origin;
    bool mpe = false, mpeGiven = false;
    std::string articulation;      ///< articulation name the map selects, empty = leave it
    int articulationChannels = -1; ///< 1: MIDI channel n plays articulation n, 0 off, -1 leave it
    std::vector<Entry> entries;
};
MappingPreset loadMapping(const Library& lib, const std::string& nameOrPath);

} // namespace rosin::presets
