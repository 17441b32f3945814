#include "rosin/engine/Presets.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "rosin/engine/Parameters.h"
#include "rosin/lab/Error.h"
#include "rosin/lab/Presets.h"

namespace rosin::engine {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
struct Reader {
    fs::path file;
    json root;

    [[noreturn]] void fail(const std::string& what) const { throw std::runtime_error(file.string() + ": " + what); }

    double number(const json& obj, const std::string& key, const std::string& where, bool required = true,
                  double def = 0.0, double lo = -1e300, double hi = 1e300) const
    {
        if (!obj.is_object() || !obj.contains(key)) {
            if (required) fail(where + "field '" + key + "' is missing");
            return def;
        }
        const json& v = obj[key];
        if (!v.is_number()) fail(where + "field '" + key + "' must be a number");
        const double x = v.get<double>();
        if (!std::isfinite(x) || x < lo || x > hi)
            fail(where + "field '" + key + "' = " + v.dump() + " is outside [" + json(lo).dump() + ", " + json(hi).dump() + "]");
        return x;
    }

    std::string text(const json& obj, const std::string& key, const std::string& where, bool required = true,
                     const std::string& def = {}) const
    {
        if (!obj.is_object() || !obj.contains(key)) {
            if (required) fail(where + "field '" + key + "' is missing");
            return def;
        }
        if (!obj[key].is_string()) fail(where + "field '" + key + "' must be a string");
        return obj[key].get<std::string>();
    }
};

Reader open(const fs::path& file, const std::string& format)
{
    std::ifstream in(file);
    if (!in) throw std::runtime_error(file.string() + ": cannot open file");
    Reader r{file, {}};
    try {
        r.root = json::parse(in);
    } catch (const json::parse_error& e) {
        throw std::runtime_error(file.string() + ": not valid JSON (" + e.what() + ")");
    }
    if (!r.root.is_object()) r.fail("the top level must be an object");
    const std::string got = r.text(r.root, "format", "");
    if (got != format) r.fail("field 'format' is '" + got + "', expected '" + format + "'");
    return r;
}

fs::path resolve(const fs::path& dir, const std::string& kind, const std::string& nameOrPath)
{
    const fs::path asPath(nameOrPath);
    if (asPath.extension() == ".json" || asPath.has_parent_path()) return asPath;
    const fs::path file = dir / kind / (nameOrPath + ".json");
    if (!fs::exists(file)) {
        std::string known;
        for (const auto& n : listPresets(dir, kind)) known += (known.empty() ? "" : ", ") + n;
        throw std::runtime_error("no " + kind + " preset '" + nameOrPath + "' in " + (dir / kind).string() +
                                 " (known: " + known + ")");
    }
    return file;
}
} // namespace

fs::path presetDirectory(const std::string& explicitDir) { return lab::presetDirectory(explicitDir); }

std::vector<std::string> listPresets(const fs::path& presetDir, const std::string& kind)
{
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(presetDir / kind, ec))
        if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
}

InstrumentPreset loadInstrument(const fs::path& presetDir, const std::string& nameOrPath)
{
    const fs::path file = resolve(presetDir, "instruments", nameOrPath);
    Reader r = open(file, "rosin-instrument/1");
    const json& j = r.root;
    InstrumentPreset p;
    p.file = file;
    p.name = r.text(j, "name", "");
    p.tuningA4 = r.number(j, "tuning_a4_hz", "", false, 440.0, 380.0, 480.0);
    p.maxStopSemitones = r.number(j, "max_stop_semitones", "", false, 24.0, 0.0, 48.0);
    p.panSpread = r.number(j, "pan_spread", "", false, 0.5, 0.0, 1.0);

    // Strings: a strings/*.json file, relative to the preset directory (or absolute).
    fs::path stringsFile = r.text(j, "strings", "");
    if (stringsFile.is_relative()) stringsFile = presetDir / stringsFile;
    std::vector<lab::StringPreset> strings;
    try {
        strings = lab::loadStringFile(stringsFile);
    } catch (const lab::LabError& e) {
        r.fail(std::string("field 'strings': ") + e.what());
    }
    if (strings.empty() || strings.size() > static_cast<std::size_t>(maxStrings))
        r.fail("field 'strings': " + stringsFile.string() + " has " + std::to_string(strings.size()) +
               " strings; an instrument needs 1-" + std::to_string(maxStrings));
    std::sort(strings.begin(), strings.end(),
              [](const auto& a, const auto& b) { return a.params.fundamental() < b.params.fundamental(); });
    p.stringCount = static_cast<int>(strings.size());
    for (std::size_t i = 0; i < strings.size(); ++i) {
        p.strings[i] = strings[i].params;
        p.stringNames[i] = strings[i].id.substr(strings[i].instrument.size() + 1);
    }

    if (j.contains("bow")) {
        const json& b = j["bow"];
        p.bowForce = r.number(b, "force_N", "bow: ", false, p.bowForce, 0.0, 5.0);
        p.bowSpeed = r.number(b, "speed_m_s", "bow: ", false, p.bowSpeed, 0.0, 1.0);
        p.bowPosition = r.number(b, "position", "bow: ", false, p.bowPosition, 0.02, 0.3);
        p.attackAccel = r.number(b, "attack_accel_m_s2", "bow: ", false, p.attackAccel, 0.1, 30.0);
        if (b.contains("note") && !b["note"].is_string()) r.fail("bow: field 'note' must be text");
    }
    if (j.contains("rosin")) {
        try {
            p.rosinTg = lab::findRosin(presetDir, r.text(j, "rosin", "")).glassTransitionCelsius;
        } catch (const lab::LabError& e) {
            r.fail(std::string("field 'rosin': ") + e.what());
        }
    }
    if (!j.contains("body") || !j["body"].is_object()) r.fail("field 'body' is missing or not an object");
    const json& body = j["body"];
    p.body.direct = r.number(body, "direct", "body: ", false, 0.25, 0.0, 10.0);
    p.body.outputScale = r.number(body, "output_scale", "body: ", false, 1.0, 1e-6, 100.0);
    if (!body.contains("modes") || !body["modes"].is_array()) r.fail("body: field 'modes' must be an array");
    const json& modes = body["modes"];
    if (modes.size() > static_cast<std::size_t>(dsp::BodyParams::maxModes))
        r.fail("body: field 'modes' has " + std::to_string(modes.size()) + " entries; at most " +
               std::to_string(dsp::BodyParams::maxModes));
    p.body.count = static_cast<int>(modes.size());
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const std::string where = "body.modes[" + std::to_string(i) + "]: ";
        p.body.modes[i] = {r.number(modes[i], "f_hz", where, true, 0.0, 10.0, 20000.0),
                           r.number(modes[i], "q", where, true, 0.0, 0.5, 1000.0),
                           r.number(modes[i], "gain", where, true, 0.0, 0.0, 100.0)};
    }
    return p;
}

ExciterPreset loadExciter(const fs::path& presetDir, const std::string& nameOrPath)
{
    const fs::path file = resolve(presetDir, "exciters", nameOrPath);
    Reader r = open(file, "rosin-exciter/1");
    ExciterPreset e;
    e.name = r.text(r.root, "name", "");
    const std::string model = r.text(r.root, "friction_model", "");
    if (model == "friction-curve") e.model = dsp::FrictionModel::FrictionCurve;
    else if (model == "thermal") e.model = dsp::FrictionModel::Thermal;
    else if (model == "enhanced") e.model = dsp::FrictionModel::Enhanced;
    else r.fail("field 'friction_model' is '" + model + "'; use friction-curve, thermal or enhanced");
    const std::string contact = r.text(r.root, "contact_law", "", false, "amontons");
    if (contact == "amontons") e.contact = dsp::ContactLaw::Amontons;
    else if (contact == "hertz") e.contact = dsp::ContactLaw::PowerLaw;
    else r.fail("field 'contact_law' is '" + contact + "'; use amontons or hertz");
    e.footprintRatio = r.number(r.root, "footprint_ratio", "", false, 1.0, 0.25, 2.0);
    e.ambient = r.number(r.root, "ambient_C", "", false, 20.0, 0.0, 40.0);
    return e;
}

MappingPreset loadMapping(const fs::path& presetDir, const std::string& nameOrPath)
{
    const fs::path file = resolve(presetDir, "mappings", nameOrPath);
    Reader r = open(file, "rosin-mapping/1");
    MappingPreset m;
    m.name = r.text(r.root, "name", "");
    if (r.root.contains("mpe")) {
        if (!r.root["mpe"].is_boolean()) r.fail("field 'mpe' must be true or false");
        m.mpe = r.root["mpe"].get<bool>();
        m.mpeGiven = true;
    }
    if (r.root.contains("articulation")) {
        const std::string a = r.text(r.root, "articulation", "");
        const auto& info = paramInfo(Param::Articulation);
        int index = 0;
        std::string choices(info.choices), known;
        for (std::size_t start = 0; start <= choices.size(); ++index) {
            const std::size_t bar = std::min(choices.find('|', start), choices.size());
            std::string name = choices.substr(start, bar - start);
            std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
            if (name == a) m.articulation = index;
            known += (known.empty() ? "" : ", ") + name;
            start = bar + 1;
        }
        if (m.articulation < 0) r.fail("field 'articulation' is '" + a + "'; use one of: " + known);
    }
    if (r.root.contains("articulation_by_channel")) {
        if (!r.root["articulation_by_channel"].is_boolean()) r.fail("field 'articulation_by_channel' must be true or false");
        m.articulationChannels = r.root["articulation_by_channel"].get<bool>() ? 1 : 0;
    }
    if (!r.root.contains("mappings") || !r.root["mappings"].is_array()) r.fail("field 'mappings' must be an array");
    const json& list = r.root["mappings"];
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string where = "mappings[" + std::to_string(i) + "]: ";
        MappingEntry e;
        e.cc = static_cast<int>(r.number(list[i], "cc", where, true, 0.0, 0.0, 119.0));
        const std::string id = r.text(list[i], "param", where);
        e.param = paramIndex(id);
        if (e.param < 0) r.fail(where + "field 'param' = '" + id + "' is not a parameter ID");
        const ParamInfo& info = paramInfo(e.param);
        e.min = static_cast<float>(r.number(list[i], "min", where, false, info.min, info.min, info.max));
        e.max = static_cast<float>(r.number(list[i], "max", where, false, info.max, info.min, info.max));
        if (list[i].contains("invert")) {
            if (!list[i]["invert"].is_boolean()) r.fail(where + "field 'invert' must be true or false");
            e.invert = list[i]["invert"].get<bool>();
        }
        m.entries.push_back(e);
    }
    return m;
}

} // namespace rosin::engine
