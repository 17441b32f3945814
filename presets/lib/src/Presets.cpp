#include "rosin/presets/Presets.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace rosin::presets {
using Json = Document::Json;

namespace {
std::string lower(std::string s)
{
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

std::string stemOf(const std::string& origin)
{
    std::string s = origin.substr(origin.find_last_of("/:") + 1);
    return s.size() > 5 && s.substr(s.size() - 5) == ".json" ? s.substr(0, s.size() - 5) : s;
}

std::vector<StringPreset> readStrings(const Document& d)
{
    const Json& doc = d.root();
    const std::string instrument = d.text(doc, "instrument", "", false, stemOf(d.origin()));
    // A string's field falls back to the file's "defaults", and its length to the file's length_m.
    Json defaults = d.object(doc, "defaults", "", false);
    if (doc.contains("length_m")) defaults["length_m"] = doc["length_m"];
    const Json& list = d.array(doc, "strings");
    if (list.empty()) d.fail("field 'strings' must be a non-empty array");
    std::vector<StringPreset> out;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const Json& s = list[i];
        const std::string where = "strings[" + std::to_string(i) + "].";
        if (!s.is_object()) d.fail(where + " must be an object");
        auto number = [&](const char* key, bool required = true, double def = 0.0) {
            return d.number(s.contains(key) ? s : defaults, key, where, required, def);
        };
        StringPreset p;
        p.instrument = instrument;
        p.id = instrument + "-" + d.text(s, "name", where);
        p.note = d.text(s, "note", where, false, "");
        dsp::StringParams& q = p.params;
        q.name = p.id;
        const double f0 = number("frequency_hz");
        q.length = number("length_m");
        q.tension = number("tension_N");
        q.radius = number("radius_m");
        q.massPerLength = number("mass_per_length_kg_m", false, q.tension / std::pow(2.0 * q.length * f0, 2.0));
        q.torsionSpeedRatio = number("torsion_speed_ratio");
        q.torsionImpedanceRatio = number("torsion_impedance_ratio");
        q.qLow = number("q_low");
        q.qHigh = number("q_high");
        q.qHighFrequency = number("q_high_frequency_hz");
        q.qTorsion = number("q_torsion");
        q.inharmonicity = number("inharmonicity");
        if (const std::string problem = q.validate(); !problem.empty()) d.fail(where + problem);
        if (std::abs(q.fundamental() / f0 - 1.0) > 1e-3)
            d.fail(where + "mass_per_length_kg_m contradicts frequency_hz, length_m and tension_N");
        out.push_back(p);
    }
    return out;
}
} // namespace

std::vector<StringPreset> loadStrings(const Library& lib, const std::string& nameOrPath)
{
    return readStrings(lib.open("strings", nameOrPath, "rosin-strings/1"));
}

std::vector<StringPreset> allStrings(const Library& lib)
{
    std::vector<StringPreset> all;
    for (const auto& name : lib.list("strings")) {
        auto some = loadStrings(lib, name);
        all.insert(all.end(), some.begin(), some.end());
    }
    return all;
}

StringPreset findString(const Library& lib, const std::string& id)
{
    // "path/to/file.json:NAME" picks a string from an instrument file outside the presets.
    if (const auto colon = id.rfind(':'); colon != std::string::npos && id.find(".json") != std::string::npos) {
        const std::string file = id.substr(0, colon), name = lower(id.substr(colon + 1));
        for (const auto& p : loadStrings(lib, file))
            if (lower(p.id.substr(p.instrument.size() + 1)) == name) return p;
        throw PresetError(file + ": no string named '" + id.substr(colon + 1) + "'");
    }
    const auto all = allStrings(lib);
    for (const auto& p : all)
        if (lower(p.id) == lower(id)) return p;
    std::string known;
    for (const auto& p : all) known += (known.empty() ? "" : ", ") + p.id;
    throw PresetError("unknown string '" + id + "' (known: " + known + ")");
}

RosinPreset findRosin(const Library& lib, const std::string& nameOrPath)
{
    const bool path = nameOrPath.find(".json") != std::string::npos || nameOrPath.find('/') != std::string::npos;
    if (!path && !lib.has("rosin", lower(nameOrPath))) {
        std::string known;
        for (const auto& n : lib.list("rosin")) known += (known.empty() ? "" : ", ") + n;
        throw PresetError("unknown rosin '" + nameOrPath + "' (known: " + known + ")");
    }
    const Document d = lib.open("rosin", path ? nameOrPath : lower(nameOrPath), "rosin-rosin/1");
    RosinPreset r;
    r.name = d.text(d.root(), "name", "", false, stemOf(d.origin()));
    r.glassTransitionCelsius = d.number(d.root(), "glass_transition_C", "", true, 0.0, -50.0, 150.0);
    return r;
}

InstrumentPreset loadInstrument(const Library& lib, const std::string& nameOrPath)
{
    const Document d = lib.open("instruments", nameOrPath, "rosin-instrument/1");
    const Json& j = d.root();
    InstrumentPreset p;
    p.origin = d.origin();
    p.name = d.text(j, "name");
    p.tuningA4 = d.number(j, "tuning_a4_hz", "", false, 440.0, 380.0, 480.0);
    p.maxStopSemitones = d.number(j, "max_stop_semitones", "", false, 24.0, 0.0, 48.0);
    p.panSpread = d.number(j, "pan_spread", "", false, 0.5, 0.0, 1.0);

    // Strings: a path inside the preset set ("strings/cello.json"), an absolute file, or a name.
    const std::string stringsRef = d.text(j, "strings");
    std::vector<StringPreset> strings;
    try {
        const bool insideTheSet = stringsRef.find(".json") != std::string::npos && stringsRef.front() != '/';
        strings = insideTheSet ? readStrings(lib.openPath(stringsRef, "rosin-strings/1")) : loadStrings(lib, stringsRef);
    } catch (const PresetError& e) {
        d.fail(std::string("field 'strings': ") + e.what());
    }
    if (strings.size() > static_cast<std::size_t>(maxStrings))
        d.fail("field 'strings': " + stringsRef + " has " + std::to_string(strings.size()) + " strings; an instrument needs 1-" +
               std::to_string(maxStrings));
    std::sort(strings.begin(), strings.end(), [](const auto& a, const auto& b) { return a.params.fundamental() < b.params.fundamental(); });
    p.stringCount = static_cast<int>(strings.size());
    for (std::size_t i = 0; i < strings.size(); ++i) {
        p.strings[i] = strings[i].params;
        p.stringNames[i] = strings[i].id.substr(strings[i].instrument.size() + 1);
    }

    if (j.contains("bow")) {
        const Json& b = d.object(j, "bow");
        p.bowForce = d.number(b, "force_N", "bow: ", false, p.bowForce, 0.0, 5.0);
        p.bowSpeed = d.number(b, "speed_m_s", "bow: ", false, p.bowSpeed, 0.0, 1.0);
        p.bowPosition = d.number(b, "position", "bow: ", false, p.bowPosition, 0.02, 0.3);
        p.attackAccel = d.number(b, "attack_accel_m_s2", "bow: ", false, p.attackAccel, 0.1, 30.0);
        d.text(b, "note", "bow: ", false);
    }
    if (j.contains("rosin")) {
        try {
            p.rosinTg = findRosin(lib, d.text(j, "rosin")).glassTransitionCelsius;
        } catch (const PresetError& e) {
            d.fail(std::string("field 'rosin': ") + e.what());
        }
    }
    const Json& body = d.object(j, "body");
    p.body.direct = d.number(body, "direct", "body: ", false, 0.25, 0.0, 10.0);
    p.body.outputScale = d.number(body, "output_scale", "body: ", false, 1.0, 1e-6, 100.0);
    const Json& modes = d.array(body, "modes", "body: ");
    if (modes.size() > static_cast<std::size_t>(dsp::BodyParams::maxModes))
        d.fail("body: field 'modes' has " + std::to_string(modes.size()) + " entries; at most " + std::to_string(dsp::BodyParams::maxModes));
    p.body.count = static_cast<int>(modes.size());
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const std::string where = "body.modes[" + std::to_string(i) + "]: ";
        p.body.modes[i] = {d.number(modes[i], "f_hz", where, true, 0.0, 10.0, 20000.0), d.number(modes[i], "q", where, true, 0.0, 0.5, 1000.0),
                           d.number(modes[i], "gain", where, true, 0.0, 0.0, 100.0)};
    }
    return p;
}

ExciterPreset loadExciter(const Library& lib, const std::string& nameOrPath)
{
    const Document d = lib.open("exciters", nameOrPath, "rosin-exciter/1");
    const Json& j = d.root();
    ExciterPreset e;
    e.name = d.text(j, "name");
    const std::string model = d.text(j, "friction_model");
    if (model == "friction-curve") e.model = dsp::FrictionModel::FrictionCurve;
    else if (model == "thermal") e.model = dsp::FrictionModel::Thermal;
    else if (model == "enhanced") e.model = dsp::FrictionModel::Enhanced;
    else d.fail("field 'friction_model' is '" + model + "'; use friction-curve, thermal or enhanced");
    const std::string contact = d.text(j, "contact_law", "", false, "amontons");
    if (contact == "amontons") e.contact = dsp::ContactLaw::Amontons;
    else if (contact == "hertz") e.contact = dsp::ContactLaw::PowerLaw;
    else d.fail("field 'contact_law' is '" + contact + "'; use amontons or hertz");
    e.footprintRatio = d.number(j, "footprint_ratio", "", false, 1.0, 0.25, 2.0);
    e.ambient = d.number(j, "ambient_C", "", false, 20.0, 0.0, 40.0);
    return e;
}

MappingPreset loadMapping(const Library& lib, const std::string& nameOrPath)
{
    const Document d = lib.open("mappings", nameOrPath, "rosin-mapping/1");
    const Json& j = d.root();
    MappingPreset m;
    m.origin = d.origin();
    m.name = d.text(j, "name");
    m.mpeGiven = j.contains("mpe");
    m.mpe = d.flag(j, "mpe", "", false);
    m.articulation = lower(d.text(j, "articulation", "", false, ""));
    if (j.contains("articulation_by_channel")) m.articulationChannels = d.flag(j, "articulation_by_channel", "", false) ? 1 : 0;
    const Json& list = d.array(j, "mappings");
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string where = "mappings[" + std::to_string(i) + "]: ";
        MappingPreset::Entry e;
        e.cc = d.integer(list[i], "cc", where, true, 0, 0, 119);
        e.param = d.text(list[i], "param", where);
        e.hasMin = list[i].contains("min");
        e.hasMax = list[i].contains("max");
        e.min = d.number(list[i], "min", where, false, 0.0);
        e.max = d.number(list[i], "max", where, false, 1.0);
        e.invert = d.flag(list[i], "invert", where, false);
        m.entries.push_back(e);
    }
    return m;
}

} // namespace rosin::presets
