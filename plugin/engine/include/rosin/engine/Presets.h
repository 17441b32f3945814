// Instrument, exciter and controller-map presets (JSON under presets/). Parsing allocates and
// throws: call it on the message thread or a loader thread, never on the audio thread.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "rosin/dsp/Body.h"
#include "rosin/dsp/BowJunction.h"
#include "rosin/dsp/StringParams.h"

namespace rosin::engine {

inline constexpr int maxStrings = 5; // five-string basses exist; the shipped presets have four

struct InstrumentPreset {
    std::string name = "cello";
    std::filesystem::path file;
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

struct ExciterPreset {
    std::string name;
    dsp::FrictionModel model = dsp::FrictionModel::Thermal;
    dsp::ContactLaw contact = dsp::ContactLaw::Amontons;
    double footprintRatio = 1.0;
    double ambient = 20.0;
};

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

/// By name ("cello") under dir/instruments, or a path to a .json file. Throws
/// std::runtime_error naming the file and field at fault.
InstrumentPreset loadInstrument(const std::filesystem::path& presetDir, const std::string& nameOrPath);
ExciterPreset loadExciter(const std::filesystem::path& presetDir, const std::string& nameOrPath);
MappingPreset loadMapping(const std::filesystem::path& presetDir, const std::string& nameOrPath);

/// Names of the presets of one kind ("instruments", "exciters", "mappings"), sorted.
std::vector<std::string> listPresets(const std::filesystem::path& presetDir, const std::string& kind);

/// The preset directory: explicit, $ROSIN_PRESETS, the source tree, or beside the binary.
std::filesystem::path presetDirectory(const std::string& explicitDir = {});

} // namespace rosin::engine
