#include "rosin/engine/Presets.h"

#include <algorithm>
#include <cctype>

#include "rosin/engine/Parameters.h"

namespace rosin::engine {

MappingPreset resolveMapping(const presets::MappingPreset& w)
{
    auto fail = [&](const std::string& what) { throw presets::PresetError(w.origin + ": " + what); };
    MappingPreset m;
    m.name = w.name;
    m.mpe = w.mpe;
    m.mpeGiven = w.mpeGiven;
    m.articulationChannels = w.articulationChannels;
    if (!w.articulation.empty()) {
        m.articulation = choiceIndex(Param::Articulation, w.articulation);
        if (m.articulation < 0) {
            std::string known;
            for (const auto& name : choiceNames(Param::Articulation)) known += (known.empty() ? "" : ", ") + name;
            fail("field 'articulation' is '" + w.articulation + "'; use one of: " + known);
        }
    }
    for (std::size_t i = 0; i < w.entries.size(); ++i) {
        const auto& e = w.entries[i];
        const std::string where = "mappings[" + std::to_string(i) + "]: ";
        MappingEntry r;
        r.cc = e.cc;
        r.param = paramIndex(e.param);
        if (r.param < 0) fail(where + "field 'param' = '" + e.param + "' is not a parameter ID");
        const ParamInfo& info = paramInfo(r.param);
        r.min = e.hasMin ? static_cast<float>(e.min) : info.min;
        r.max = e.hasMax ? static_cast<float>(e.max) : info.max;
        for (const float x : {r.min, r.max})
            if (x < info.min || x > info.max)
                fail(where + "min and max must lie within " + std::to_string(info.min) + ".." + std::to_string(info.max));
        r.invert = e.invert;
        m.entries.push_back(r);
    }
    return m;
}

} // namespace rosin::engine
