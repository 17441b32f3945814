// Where presets come from: the factory set compiled into every binary (so an installed plugin or
// a copied `rosin` needs no source tree), plus user folders that add to it and may replace a
// factory preset of the same kind and name. One lookup for the plugin, its editor, the headless
// host and the lab.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "rosin/presets/Document.h"

namespace rosin::presets {

class Library {
public:
    /// The factory presets only.
    Library() = default;
    /// Factory presets plus the user folders: every folder in $ROSIN_PRESETS (':'-separated),
    /// then $XDG_DATA_HOME/rosin/presets (default ~/.local/share/rosin/presets), where present.
    static Library standard();

    /// A folder laid out like presets/ (instruments/, strings/, ...): searched before every
    /// folder added earlier and before the factory set.
    void addFolder(const std::filesystem::path& folder);
    const std::vector<std::filesystem::path>& folders() const noexcept { return folders_; }

    /// The names (without .json) of one kind ("instruments", "strings", "controllers", ...),
    /// factory and user together, sorted, each once.
    std::vector<std::string> list(const std::string& kind) const;
    bool has(const std::string& kind, const std::string& name) const;

    /// The text of "kind/name.json" from the first folder that has it, else the factory set. A
    /// name ending in .json or holding a '/' is a file path. Throws PresetError listing what
    /// exists when nothing matches. An empty `format` leaves the check to the reader (a kind
    /// with several versions).
    Document open(const std::string& kind, const std::string& nameOrPath, const std::string& format) const;
    /// A preset that names another one by its path inside the set ("strings/cello.json").
    Document openPath(const std::string& relativePath, const std::string& format) const;

private:
    std::vector<std::filesystem::path> folders_; ///< most recently added first
};

/// The factory presets compiled into this binary: "kind/name.json" and its text.
struct FactoryEntry {
    const char* path;
    const char* text;
    unsigned long size;
};
const FactoryEntry* factoryEntries(unsigned long& count) noexcept;

} // namespace rosin::presets
