// libFuzzer target: the descriptor parser, then the report decoder and the bow mapper on
// whatever reports follow, with every quirk set the device table holds. Input: 1 byte choosing
// the device (its quirks and its kind), 2 bytes of descriptor length (little-endian), the
// descriptor, then reports of 1 length byte + data. Build and run: scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rosin/hid/Descriptor.h"
#include "rosin/hid/Devices.h"
#include "rosin/hid/Mapping.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rosin::hid;
    if (size < 3) return 0;
    // 0: no device known (the descriptor decides); 1..N: the table's devices, each with its
    // quirks and kind; N+1: 3Dconnexion's vendor-wide quirk.
    const auto devices = supportedDevices();
    const std::size_t choice = data[0] % (devices.size() + 2);
    Quirks quirks{};
    DeviceKind kind = DeviceKind::Other;
    if (choice >= 1 && choice <= devices.size()) {
        quirks = devices[choice - 1].quirks;
        kind = devices[choice - 1].kind;
    } else if (choice == devices.size() + 1) {
        quirks = quirksFor(0x256F, 0xFFFF);
    }
    ++data;
    --size;
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
    DeviceDecoder decoder(d, quirks, kind);
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
