#include "StateFormat.h"

#include <algorithm>
#include <cmath>

#include "rosin/engine/ControllerMap.h"
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
    // 0 and 1 -> 2, and any state missing parameters (cut short, edited by hand): what it does
    // not hold plays as its default, as older builds without that parameter did.
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
    xml.setAttribute("format", "rosin-state/" + juce::String(current));
    return {};
}

LoadedState read(const void* data, int sizeInBytes, const juce::String& treeType, int current)
{
    LoadedState out;
    // JUCE's copyXmlToBinary: 0x21324356 (little-endian), the text's length, the text.
    constexpr juce::uint32 magic = 0x21324356;
    if (data == nullptr || sizeInBytes <= 8 || juce::ByteOrder::littleEndianInt(data) != magic) {
        out.problem = "the state is not a Rosin state: the current settings are kept";
        return out;
    }
    const auto* bytes = static_cast<const char*>(data);
    const auto length = static_cast<int>(juce::jmin<juce::uint32>(juce::ByteOrder::littleEndianInt(bytes + 4), static_cast<juce::uint32>(sizeInBytes - 8)));
    // The text ends at its terminating zero; it must be UTF-8 (juce::String reads past the end
    // of invalid UTF-8: found by the fuzzer under AddressSanitizer).
    const int textLength = static_cast<int>(std::find(bytes + 8, bytes + 8 + length, '\0') - (bytes + 8));
    if (!juce::CharPointer_UTF8::isValidString(bytes + 8, textLength)) {
        out.problem = "the state is malformed (its text is not UTF-8): the current settings are kept";
        return out;
    }
    const juce::String text = juce::String::fromUTF8(bytes + 8, textLength);
    // Rosin writes an XML declaration and elements, nothing else. A processing instruction inside
    // an element ("<?x?>text" unclosed) sends JUCE 7's parser into an endless loop (found by the
    // fuzzer), and DOCTYPEs or entities have no business here: such a state is refused unread.
    const juce::String body = text.trimStart().startsWith("<?xml") ? text.fromFirstOccurrenceOf("?>", false, false) : text;
    if (body.contains("<?") || body.contains("<!")) {
        out.problem = "the state is malformed (processing instructions or declarations inside it): the current settings are kept";
        return out;
    }
    std::unique_ptr<juce::XmlElement> xml = juce::parseXML(text);
    if (xml == nullptr || !xml->hasTagName(treeType)) {
        out.problem = "the state is not a Rosin state: the current settings are kept";
        return out;
    }
    if (const juce::String problem = migrate(*xml, current); problem.isNotEmpty()) {
        out.problem = problem;
        return out;
    }
    while (auto* maps = xml->getChildByName("Mappings")) { // one in every state Rosin writes
        for (auto* m : maps->getChildIterator()) {
            engine::MappingEntry e;
            e.cc = m->getIntAttribute("cc", -1);
            e.param = engine::paramIndex(m->getStringAttribute("param").toStdString());
            e.min = static_cast<float>(m->getDoubleAttribute("min"));
            e.max = static_cast<float>(m->getDoubleAttribute("max"));
            e.invert = m->getBoolAttribute("invert");
            if (e.cc >= 0 && e.cc < engine::ControllerMap::numControllers && e.param >= 0 && std::isfinite(e.min) && std::isfinite(e.max)) out.mappings.push_back(e);
        }
        xml->removeChildElement(maps, true);
    }
    while (auto* hidXml = xml->getChildByName("Hid")) {
        for (auto* m : hidXml->getChildIterator()) {
            try {
                out.hidMappings.push_back(hid::HidMapping::fromJson(m->getAllSubText().toStdString(), "saved state"));
            } catch (const std::exception& e) {
                out.problem += juce::String(e.what()) + "; ";
            }
        }
        xml->removeChildElement(hidXml, true);
    }
    xml->removeAttribute("format");
    out.tree = std::move(xml);
    return out;
}

} // namespace rosin::plugin::state
