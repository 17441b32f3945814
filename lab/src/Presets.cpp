#include "rosin/lab/Presets.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "rosin/lab/Error.h"

namespace rosin::lab {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
std::string lower(std::string s)
{
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

json readJson(const fs::path& file)
{
    std::ifstream in(file);
    if (!in) throw LabError(file.string() + ": cannot open file");
    try {
        return json::parse(in);
    } catch (const json::parse_error& e) {
        throw LabError(file.string() + ": not valid JSON (" + e.what() + ")");
    }
}

double number(const json& obj, const json& fallback, const std::string& key, const fs::path& file,
              const std::string& where, bool required = true, double def = 0.0)
{
    const json* src = obj.contains(key) ? &obj : (fallback.is_object() && fallback.contains(key) ? &fallback : nullptr);
    if (!src) {
        if (required) throw LabError(file.string() + ": " + where + "field '" + key + "' is missing");
        return def;
    }
    const json& v = (*src)[key];
    if (!v.is_number()) throw LabError(file.string() + ": " + where + "field '" + key + "' must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) throw LabError(file.string() + ": " + where + "field '" + key + "' is not finite");
    return x;
}
} // namespace

fs::path presetDirectory(const std::string& explicitDir)
{
    if (!explicitDir.empty()) return explicitDir;
    if (const char* env = std::getenv("ROSIN_PRESETS"); env && *env) return env;
#ifdef ROSIN_DEFAULT_PRESET_DIR
    if (fs::is_directory(ROSIN_DEFAULT_PRESET_DIR)) return ROSIN_DEFAULT_PRESET_DIR;
#endif
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const fs::path installed = exe.parent_path() / ".." / "share" / "rosin" / "presets";
        if (fs::is_directory(installed)) return installed;
    }
    throw LabError("cannot find the presets directory: pass --presets DIR or set ROSIN_PRESETS");
}

std::vector<StringPreset> loadStringFile(const fs::path& file)
{
    const json doc = readJson(file);
    if (!doc.is_object() || doc.value("format", "") != "rosin-strings/1")
        throw LabError(file.string() + ": field 'format' must be \"rosin-strings/1\"");
    const std::string instrument = doc.value("instrument", file.stem().string());
    const json defaults = doc.value("defaults", json::object());
    if (!doc.contains("strings") || !doc["strings"].is_array() || doc["strings"].empty())
        throw LabError(file.string() + ": field 'strings' must be a non-empty array");
    std::vector<StringPreset> out;
    int index = 0;
    for (const json& s : doc["strings"]) {
        const std::string where = "strings[" + std::to_string(index++) + "].";
        if (!s.is_object() || !s.contains("name") || !s["name"].is_string())
            throw LabError(file.string() + ": " + where + "name must be a string");
        json fallback = defaults;
        if (doc.contains("length_m")) fallback["length_m"] = doc["length_m"];
        StringPreset p;
        p.instrument = instrument;
        p.id = instrument + "-" + s["name"].get<std::string>();
        p.note = s.value("note", "");
        dsp::StringParams& q = p.params;
        q.name = p.id;
        const double f0 = number(s, fallback, "frequency_hz", file, where);
        q.length = number(s, fallback, "length_m", file, where);
        q.tension = number(s, fallback, "tension_N", file, where);
        q.radius = number(s, fallback, "radius_m", file, where);
        const double derivedMass = q.tension / std::pow(2.0 * q.length * f0, 2.0);
        q.massPerLength = number(s, fallback, "mass_per_length_kg_m", file, where, false, derivedMass);
        q.torsionSpeedRatio = number(s, fallback, "torsion_speed_ratio", file, where);
        q.torsionImpedanceRatio = number(s, fallback, "torsion_impedance_ratio", file, where);
        q.qLow = number(s, fallback, "q_low", file, where);
        q.qHigh = number(s, fallback, "q_high", file, where);
        q.qHighFrequency = number(s, fallback, "q_high_frequency_hz", file, where);
        q.qTorsion = number(s, fallback, "q_torsion", file, where);
        q.inharmonicity = number(s, fallback, "inharmonicity", file, where);
        if (const std::string problem = q.validate(); !problem.empty())
            throw LabError(file.string() + ": " + where + problem);
        if (std::abs(q.fundamental() / f0 - 1.0) > 1e-3)
            throw LabError(file.string() + ": " + where + "mass_per_length_kg_m contradicts frequency_hz, length_m and tension_N");
        out.push_back(p);
    }
    return out;
}

std::vector<StringPreset> loadAllStrings(const fs::path& presetDir)
{
    const fs::path dir = presetDir / "strings";
    if (!fs::is_directory(dir)) throw LabError(dir.string() + ": no such presets directory");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".json") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    std::vector<StringPreset> all;
    for (const auto& f : files) {
        auto some = loadStringFile(f);
        all.insert(all.end(), some.begin(), some.end());
    }
    return all;
}

StringPreset findString(const fs::path& presetDir, const std::string& id)
{
    // "path/to/file.json:NAME" picks a string from an instrument file outside the presets.
    if (const auto colon = id.rfind(':'); colon != std::string::npos && id.find(".json") != std::string::npos) {
        const fs::path file = id.substr(0, colon);
        const std::string name = lower(id.substr(colon + 1));
        for (const auto& p : loadStringFile(file))
            if (lower(p.id.substr(p.instrument.size() + 1)) == name) return p;
        throw LabError(file.string() + ": no string named '" + id.substr(colon + 1) + "'");
    }
    const auto all = loadAllStrings(presetDir);
    for (const auto& p : all)
        if (lower(p.id) == lower(id)) return p;
    std::string known;
    for (const auto& p : all) known += (known.empty() ? "" : ", ") + p.id;
    throw LabError("unknown string '" + id + "' (known: " + known + ")");
}

RosinPreset findRosin(const fs::path& presetDir, const std::string& nameOrPath)
{
    fs::path file = nameOrPath;
    if (file.extension() != ".json") file = presetDir / "rosin" / (lower(nameOrPath) + ".json");
    if (!fs::exists(file)) throw LabError("unknown rosin '" + nameOrPath + "' (no file " + file.string() + ")");
    const json doc = readJson(file);
    if (!doc.is_object() || doc.value("format", "") != "rosin-rosin/1")
        throw LabError(file.string() + ": field 'format' must be \"rosin-rosin/1\"");
    RosinPreset r;
    r.name = doc.value("name", file.stem().string());
    r.glassTransitionCelsius = number(doc, json(), "glass_transition_C", file, "");
    if (r.glassTransitionCelsius < -50 || r.glassTransitionCelsius > 150)
        throw LabError(file.string() + ": field 'glass_transition_C' must be within -50..150 C");
    return r;
}

} // namespace rosin::lab
