#include "rosin/presets/Document.h"

#include <cmath>

namespace rosin::presets {

Document Document::parse(const std::string& text, std::string origin)
{
    Json root;
    try {
        root = Json::parse(text);
    } catch (const Json::exception& e) { // parse errors, and numbers too large for a double (fuzzer)
        throw PresetError(origin + ": not valid JSON (" + e.what() + ")");
    }
    if (!root.is_object()) throw PresetError(origin + ": the top level must be an object");
    return Document(std::move(root), std::move(origin));
}

void Document::fail(const std::string& what) const { throw PresetError(origin_ + ": " + what); }

void Document::requireFormat(const std::string& format) const
{
    const std::string got = text(root_, "format", "", false, "");
    if (got != format) fail("field 'format' is '" + got + "', expected '" + format + "'");
}

double Document::number(const Json& obj, const std::string& key, const std::string& where, bool required, double def, double lo,
                        double hi) const
{
    if (!obj.is_object() || !obj.contains(key)) {
        if (required) fail(where + "field '" + key + "' is missing");
        return def;
    }
    const Json& v = obj[key];
    if (!v.is_number()) fail(where + "field '" + key + "' must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(where + "field '" + key + "' is not finite");
    if (x < lo || x > hi) fail(where + "field '" + key + "' = " + v.dump() + " is outside [" + Json(lo).dump() + ", " + Json(hi).dump() + "]");
    return x;
}

int Document::integer(const Json& obj, const std::string& key, const std::string& where, bool required, int def, int lo, int hi) const
{
    const double x = number(obj, key, where, required, def, lo, hi);
    if (x != std::floor(x)) fail(where + "field '" + key + "' must be a whole number");
    return static_cast<int>(x);
}

std::string Document::text(const Json& obj, const std::string& key, const std::string& where, bool required, const std::string& def) const
{
    if (!obj.is_object() || !obj.contains(key)) {
        if (required) fail(where + "field '" + key + "' is missing");
        return def;
    }
    if (!obj[key].is_string()) fail(where + "field '" + key + "' must be text");
    return obj[key].get<std::string>();
}

bool Document::flag(const Json& obj, const std::string& key, const std::string& where, bool def) const
{
    if (!obj.is_object() || !obj.contains(key)) return def;
    if (!obj[key].is_boolean()) fail(where + "field '" + key + "' must be true or false");
    return obj[key].get<bool>();
}

const Document::Json& Document::object(const Json& obj, const std::string& key, const std::string& where, bool required) const
{
    static const Json empty = Json::object();
    if (!obj.is_object() || !obj.contains(key)) {
        if (required) fail(where + "field '" + key + "' is missing");
        return empty;
    }
    if (!obj[key].is_object()) fail(where + "field '" + key + "' must be an object");
    return obj[key];
}

const Document::Json& Document::array(const Json& obj, const std::string& key, const std::string& where, bool required) const
{
    static const Json empty = Json::array();
    if (!obj.is_object() || !obj.contains(key)) {
        if (required) fail(where + "field '" + key + "' is missing");
        return empty;
    }
    if (!obj[key].is_array()) fail(where + "field '" + key + "' must be an array");
    return obj[key];
}

} // namespace rosin::presets
