// The plugin's saved state: what it holds, its version, and the way every earlier version is
// brought up to the current one. The XML is the parameter tree (APVTS) plus the MIDI-learn map
// and the HID maps; the version is the `format` attribute "rosin-state/N".
#pragma once
#include <juce_core/juce_core.h>

#include <memory>
#include <vector>

#include "rosin/engine/Presets.h"
#include "rosin/hid/Mapping.h"

namespace rosin::plugin::state {

/// The version a saved state declares (1 for "rosin-state/1"), 0 when it declares none.
int version(const juce::XmlElement& xml);

/// Brings a state of any earlier version up to `current` in place. Returns "" on success, or
/// the reason it cannot be read (a version newer than this build knows). Migrations:
/// 0 and 1 -> 2: every parameter the state does not hold gets its default (older builds had no
/// such parameter, so they played as its default does; a state of any version cut short is
/// completed the same way); HID maps in rosin-hid/1 are converted
/// when they are read (HidMapping::fromJson).
juce::String migrate(juce::XmlElement& xml, int current);

/// A saved state taken apart, ready to apply. Reading never throws and never half-applies: when
/// `tree` is null the state is not ours or cannot be read (`problem` says why) and the caller
/// keeps its settings; otherwise `problem` lists the parts that were skipped (a broken HID map
/// keeps that device's current one).
struct LoadedState {
    std::unique_ptr<juce::XmlElement> tree; ///< the parameter tree, migrated, without Mappings and Hid
    std::vector<engine::MappingEntry> mappings;
    std::vector<hid::HidMapping> hidMappings;
    juce::String problem;
};

/// Reads what getStateInformation wrote (JUCE's binary XML: magic, length, UTF-8 text) whose
/// root is `treeType`, brought up to `current`. The fuzz target feeds it arbitrary bytes.
LoadedState read(const void* data, int sizeInBytes, const juce::String& treeType, int current);

} // namespace rosin::plugin::state
