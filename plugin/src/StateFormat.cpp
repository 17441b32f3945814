#include "StateFormat.h"

#include "rosin/engine/Parameters.h"

namespace rosin::plugin::state {

int version(const juce::XmlElement& xml)
{
    const juce::String format = xml.getStringAttribute("format");
    if (!format.startsWith("rosin-state/")) return 0;
    return format.fromFirstOccurrenceOf("/", false, false).getIntValue();
}

juce::String migrate(juce::XmlElement& xml, int current)
{
    const int v = version(xml);
    if (v > current)
        return "this state was saved by a newer Rosin (state version " + juce::String(v) + "; this build reads up to " +
               juce::String(current) + "): the current settings are kept";
    if (v < 2) {
        for (int i = 0; i < engine::paramCount; ++i) {
            const auto& info = engine::paramInfo(i);
            const juce::String id(info.id.data(), info.id.size());
            bool present = false;
            for (auto* p : xml.getChildWithTagNameIterator("PARAM")) present = present || p->getStringAttribute("id") == id;
            if (present) continue;
            auto* p = xml.createNewChildElement("PARAM");
            p->setAttribute("id", id);
            p->setAttribute("value", static_cast<double>(info.steps > 0 ? info.def - info.min : info.def));
        }
    }
    xml.setAttribute("format", "rosin-state/" + juce::String(current));
    return {};
}

} // namespace rosin::plugin::state
