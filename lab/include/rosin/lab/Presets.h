// String and rosin presets: JSON files under presets/ turned into model parameters.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "rosin/dsp/StringParams.h"

namespace rosin::lab {

/// Where presets live: an explicit directory, else $ROSIN_PRESETS, else the source tree's
/// presets/ (compiled in), else ../share/rosin/presets beside the executable.
std::filesystem::path presetDirectory(const std::string& explicitDir = {});

struct StringPreset {
    std::string id;          ///< "cello-D"
    std::string instrument;  ///< "cello"
    std::string note;        ///< "D3"
    dsp::StringParams params;
};

/// All strings of one instrument file. Throws LabError naming file and field.
std::vector<StringPreset> loadStringFile(const std::filesystem::path& file);

/// Every string of every instrument under dir/strings.
std::vector<StringPreset> loadAllStrings(const std::filesystem::path& presetDir);

/// One string by id ("cello-D", case-insensitive), or a path to an instrument file plus
/// ":NAME". Throws LabError listing what exists when it is not found.
StringPreset findString(const std::filesystem::path& presetDir, const std::string& id);

struct RosinPreset {
    std::string name;
    double glassTransitionCelsius = 49.0;
};

/// A rosin by name ("violin", "bass") under dir/rosin, or a path to a rosin JSON file.
RosinPreset findRosin(const std::filesystem::path& presetDir, const std::string& nameOrPath);

} // namespace rosin::lab
