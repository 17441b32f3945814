// libFuzzer target: the plugin's state reader (what a host hands setStateInformation). Input:
// a first byte choosing raw bytes (0) or XML text to be wrapped as JUCE's binary XML (else), so
// that the fuzzer reaches the XML, the migration, the learn map and the HID maps quickly. Either
// the state is refused with a reason, or it reads with every learned entry in range.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "StateFormat.h"
#include "rosin/engine/ControllerMap.h"
#include "rosin/engine/Parameters.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace rosin::plugin;
    if (size < 1 || size > (1u << 20)) return 0;
    std::vector<std::uint8_t> bytes;
    if (data[0] == 0) {
        bytes.assign(data + 1, data + size);
    } else {
        const auto n = static_cast<std::uint32_t>(size - 1);
        bytes = {0x56, 0x43, 0x32, 0x21, static_cast<std::uint8_t>(n), static_cast<std::uint8_t>(n >> 8), static_cast<std::uint8_t>(n >> 16),
                 static_cast<std::uint8_t>(n >> 24)};
        bytes.insert(bytes.end(), data + 1, data + size);
    }
    const state::LoadedState s = state::read(bytes.data(), static_cast<int>(bytes.size()), "RosinState", 2);
    if (s.tree == nullptr) {
        if (s.problem.isEmpty()) __builtin_trap(); // a refusal says why
        return 0;
    }
    if (!s.tree->hasTagName("RosinState") || s.tree->getChildByName("Mappings") != nullptr || s.tree->getChildByName("Hid") != nullptr)
        __builtin_trap();
    for (const auto& e : s.mappings)
        if (e.cc < 0 || e.cc >= rosin::engine::ControllerMap::numControllers || e.param < 0 || e.param >= rosin::engine::paramCount || !std::isfinite(e.min) || !std::isfinite(e.max))
            __builtin_trap();
    // Migrated: every parameter is present.
    int params = 0;
    for (auto* p : s.tree->getChildWithTagNameIterator("PARAM")) params += p != nullptr;
    if (params < rosin::engine::paramCount) __builtin_trap();
    return 0;
}
