// The plugin's saved state: what it holds, its version, and the way every earlier version is
// brought up to the current one. The XML is the parameter tree (APVTS) plus the MIDI-learn map
// and the HID maps; the version is the `format` attribute "rosin-state/N".
#pragma once
#include <juce_core/juce_core.h>

namespace rosin::plugin::state {

/// The version a saved state declares (1 for "rosin-state/1"), 0 when it declares none.
int version(const juce::XmlElement& xml);

/// Brings a state of any earlier version up to `current` in place. Returns "" on success, or
/// the reason it cannot be read (a version newer than this build knows). Migrations:
/// 0 and 1 -> 2: every parameter the state does not hold gets its default (older builds had no
/// such parameter, so they played as its default does); HID maps in rosin-hid/1 are converted
/// when they are read (HidMapping::fromJson).
juce::String migrate(juce::XmlElement& xml, int current);

} // namespace rosin::plugin::state
