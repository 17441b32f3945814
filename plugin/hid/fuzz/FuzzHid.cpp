// libFuzzer target: the descriptor parser, then the report decoder and the bow mapper on
// whatever reports follow. Input: 2 bytes of descriptor length (little-endian), the
// descriptor, then reports of 1 length byte + data. Build and run: scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rosin/hid/Descriptor.h"
#include "rosin/hid/Mapping.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rosin::hid;
    if (size < 2) return 0;
    const std::size_t len = std::min<std::size_t>(data[0] | (data[1] << 8), size - 2);
    Descriptor d;
    try {
        d = parseDescriptor(data + 2, len);
    } catch (const DescriptorError&) {
        return 0; // a clear error is the right answer to garbage
    }
    for (const auto& f : d.fields) {
        if (f.bitSize < 0 || f.bitSize > 64 || f.bitOffset < 0) __builtin_trap();
        (void)physicalValue(f, f.logicalMax);
        (void)normalisedValue(f, f.logicalMin);
    }
    DeviceDecoder decoder(d, quirksFor(0x046D, 0xC626));
    BowMapper mapper(HidMapping::defaultFor(decoder.kind()));
    DeviceState state;
    std::size_t at = 2 + len;
    double t = 0.0;
    std::vector<Event> events;
    while (at < size) {
        const std::size_t n = std::min<std::size_t>(data[at], size - at - 1);
        decoder.apply(data + at + 1, n, state);
        events.clear();
        mapper.update(state, t += 0.001, events);
        for (const Event& c : events) // normalised controls, whatever the report held
            if (!(c.force >= 0.0f && c.force <= 1.0f) || !(c.position >= 0.0f && c.position <= 1.0f) || !(c.speed >= -1.0f && c.speed <= 1.0f))
                __builtin_trap();
        at += 1 + n;
    }
    events.clear();
    mapper.release(t, events);
    if (mapper.heldNotes() != 0 || events.empty() || events.back().kind != Event::Kind::Released) __builtin_trap();
    return 0;
}
