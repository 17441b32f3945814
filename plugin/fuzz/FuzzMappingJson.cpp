// libFuzzer target: HidMapping::fromJson, which reads saved sessions and controller files. Any
// text either gives a mapping or throws presets::PresetError (never another exception, a crash,
// or a mapping with non-finite numbers); a mapping read back from its own JSON is the same.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "rosin/hid/Mapping.h"
#include "rosin/presets/Document.h"

namespace {
bool finite(const rosin::hid::Curve& c)
{
    return std::isfinite(c.inMin) && std::isfinite(c.inMax) && std::isfinite(c.outMin) && std::isfinite(c.outMax) && std::isfinite(c.exponent) &&
           std::isfinite(c.deadzone);
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rosin::hid;
    const std::string text(reinterpret_cast<const char*>(data), size);
    HidMapping m;
    try {
        m = HidMapping::fromJson(text, "fuzz");
    } catch (const rosin::presets::PresetError&) {
        return 0; // a clear error naming the field is the right answer
    }
    if (!finite(m.forceCurve) || !finite(m.speedCurve) || !finite(m.positionCurve) || !finite(m.stringCurve) || !std::isfinite(m.speedScale))
        __builtin_trap();
    const HidMapping again = HidMapping::fromJson(m.toJson(), "round trip");
    if (again.toJson() != m.toJson()) __builtin_trap();
    // The mapper survives whatever the file said.
    BowMapper mapper(m);
    DeviceState s;
    std::vector<Event> events;
    for (int i = 0; i < 8; ++i) {
        s.tip = (i & 1) != 0;
        s.pressure = i / 7.0;
        s.x = (i * 37 % 11) / 10.0;
        s.buttons = static_cast<std::uint64_t>(i * 0x35);
        mapper.update(s, 0.01 * i, events);
    }
    mapper.release(0.1, events);
    for (const Event& e : events)
        if (!(e.force >= 0.0f && e.force <= 1.0f) || !(e.speed >= -1.0f && e.speed <= 1.0f) || !(e.position >= 0.0f && e.position <= 1.0f))
            __builtin_trap();
    if (mapper.heldNotes() != 0) __builtin_trap();
    return 0;
}
