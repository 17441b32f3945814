#include "rosin/presets/Library.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace rosin::presets {
namespace fs = std::filesystem;

namespace {
std::string readFile(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) throw PresetError(file.string() + ": cannot open file");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

const FactoryEntry* factoryFind(const std::string& path)
{
    unsigned long n = 0;
    const FactoryEntry* e = factoryEntries(n);
    for (unsigned long i = 0; i < n; ++i)
        if (path == e[i].path) return &e[i];
    return nullptr;
}
} // namespace

Library Library::standard()
{
    Library lib;
    std::error_code ec;
    // Added lowest priority first: the XDG folder, then $ROSIN_PRESETS from last to first.
    fs::path data;
    if (const char* x = std::getenv("XDG_DATA_HOME"); x && *x) data = fs::path(x);
    else if (const char* h = std::getenv("HOME"); h && *h) data = fs::path(h) / ".local" / "share";
    if (!data.empty() && fs::is_directory(data / "rosin" / "presets", ec)) lib.addFolder(data / "rosin" / "presets");
    if (const char* env = std::getenv("ROSIN_PRESETS"); env && *env) {
        std::vector<fs::path> dirs;
        std::string list(env);
        for (std::size_t start = 0; start <= list.size();) {
            const std::size_t colon = std::min(list.find(':', start), list.size());
            if (colon > start) dirs.emplace_back(list.substr(start, colon - start));
            start = colon + 1;
        }
        for (auto it = dirs.rbegin(); it != dirs.rend(); ++it) lib.addFolder(*it);
    }
    return lib;
}

void Library::addFolder(const fs::path& folder) { folders_.insert(folders_.begin(), folder); }

std::vector<std::string> Library::list(const std::string& kind) const
{
    std::vector<std::string> names;
    unsigned long n = 0;
    const FactoryEntry* e = factoryEntries(n);
    const std::string prefix = kind + "/";
    for (unsigned long i = 0; i < n; ++i) {
        const std::string p = e[i].path;
        if (p.rfind(prefix, 0) == 0 && p.size() > prefix.size() + 5 && p.substr(p.size() - 5) == ".json")
            names.push_back(p.substr(prefix.size(), p.size() - prefix.size() - 5));
    }
    std::error_code ec;
    for (const auto& folder : folders_)
        for (const auto& entry : fs::directory_iterator(folder / kind, ec))
            if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    return names;
}

bool Library::has(const std::string& kind, const std::string& name) const
{
    const auto all = list(kind);
    return std::find(all.begin(), all.end(), name) != all.end();
}

Document Library::openPath(const std::string& relativePath, const std::string& format) const
{
    std::error_code ec;
    for (const auto& folder : folders_)
        if (fs::is_regular_file(folder / relativePath, ec)) {
            Document d = Document::parse(readFile(folder / relativePath), (folder / relativePath).string());
            if (!format.empty()) d.requireFormat(format);
            return d;
        }
    if (const FactoryEntry* e = factoryFind(relativePath)) {
        Document d = Document::parse(std::string(e->text, e->size), "factory:" + relativePath);
        if (!format.empty()) d.requireFormat(format);
        return d;
    }
    throw PresetError("no preset '" + relativePath + "' (neither in the factory set nor in a user folder)");
}

Document Library::open(const std::string& kind, const std::string& nameOrPath, const std::string& format) const
{
    const fs::path asPath(nameOrPath);
    if (asPath.extension() == ".json" || nameOrPath.find('/') != std::string::npos) {
        Document d = Document::parse(readFile(asPath), asPath.string());
        if (!format.empty()) d.requireFormat(format);
        return d;
    }
    if (!has(kind, nameOrPath)) {
        std::string known;
        for (const auto& n : list(kind)) known += (known.empty() ? "" : ", ") + n;
        throw PresetError("no " + kind + " preset '" + nameOrPath + "' (known: " + known + ")");
    }
    return openPath(kind + "/" + nameOrPath + ".json", format);
}

} // namespace rosin::presets
