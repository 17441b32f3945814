// The one JSON reader of the project's presets and saved maps: every field read through it gets
// the same checks (type, finite, range) and the same error, naming where the text came from and
// the field at fault. Allocates and throws: never on the audio thread.
#pragma once
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace rosin::presets {

/// A preset (or a saved map) that cannot be used: "origin: field 'x' ...".
class PresetError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class Document {
public:
    using Json = nlohmann::json;

    /// Parses `text`; `origin` names it in errors (a file path, "factory:instruments/cello.json",
    /// "saved state"). The top level must be an object.
    static Document parse(const std::string& text, std::string origin);

    const Json& root() const noexcept { return root_; }
    const std::string& origin() const noexcept { return origin_; }
    /// Throws unless the document's "format" field is `format`.
    void requireFormat(const std::string& format) const;

    [[noreturn]] void fail(const std::string& what) const;

    /// `where` prefixes the field ("body.modes[2]: "). Missing optional fields give `def`.
    double number(const Json& obj, const std::string& key, const std::string& where = {}, bool required = true, double def = 0.0,
                  double lo = -std::numeric_limits<double>::max(), double hi = std::numeric_limits<double>::max()) const;
    int integer(const Json& obj, const std::string& key, const std::string& where, bool required, int def, int lo, int hi) const;
    std::string text(const Json& obj, const std::string& key, const std::string& where = {}, bool required = true,
                     const std::string& def = {}) const;
    bool flag(const Json& obj, const std::string& key, const std::string& where, bool def) const;
    /// An object-valued field (an empty object when it is absent and not required).
    const Json& object(const Json& obj, const std::string& key, const std::string& where = {}, bool required = true) const;
    const Json& array(const Json& obj, const std::string& key, const std::string& where = {}, bool required = true) const;

private:
    Document(Json root, std::string origin) : root_(std::move(root)), origin_(std::move(origin)) {}
    Json root_;
    std::string origin_;
};

} // namespace rosin::presets
