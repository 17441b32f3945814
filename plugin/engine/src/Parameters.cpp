#include "rosin/engine/Parameters.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace rosin::engine {
namespace {
// Ranges: force and speed cover playing on every instrument from violin to bass (Schelleng
// diagrams in Euphonics ch. 9 span about 0.01-5 N and 0.01-1 m/s); beta 0.02-0.3 spans sul
// ponticello to sul tasto. Temperatures cover rooms and rosins (violin Tg 49 C, bass 16 C).
constexpr std::array<ParamInfo, paramCount> table{{
    {"bow_force", "Bow force", "N", 0.0f, 5.0f, 1.1f, 0.8f, 0, ""},
    {"bow_speed", "Bow speed", "m/s", 0.0f, 1.0f, 0.15f, 0.2f, 0, ""},
    {"bow_position", "Bow position (beta)", "", 0.02f, 0.3f, 0.0899f, 0.1f, 0, ""},
    {"friction_model", "Friction model", "", 0.0f, 2.0f, 1.0f, 1.0f, 8, "Friction curve|Thermal|Enhanced thermal"},
    {"contact_law", "Contact law", "", 0.0f, 1.0f, 0.0f, 0.5f, 4, "Amontons|Hertz"},
    {"rosin_tg", "Rosin glass transition", "C", 0.0f, 80.0f, 49.0f, 40.0f, 0, ""},
    {"ambient", "Ambient temperature", "C", 0.0f, 40.0f, 20.0f, 20.0f, 0, ""},
    {"footprint_ratio", "Footprint ratio r_A", "", 0.25f, 2.0f, 1.0f, 1.0f, 0, ""},
    {"attack_accel", "Attack acceleration", "m/s^2", 0.1f, 30.0f, 1.27f, 4.0f, 0, ""},
    {"attack_force", "Attack force boost", "", 0.0f, 2.0f, 0.0f, 0.5f, 0, ""},
    {"release_time", "Bow lift time", "s", 0.005f, 2.0f, 0.08f, 0.2f, 0, ""},
    {"portamento", "Portamento", "s", 0.0f, 1.0f, 0.06f, 0.1f, 0, ""},
    {"legato", "Legato", "", 0.0f, 1.0f, 0.0f, 0.5f, 2, "Off|On"},
    {"string_policy", "String choice", "", 0.0f, 2.0f, 0.0f, 1.0f, 4, "Lowest position|Stay on string|Fixed string"},
    {"fixed_string", "Fixed string", "", 1.0f, 5.0f, 1.0f, 3.0f, 8, "1|2|3|4|5"},
    {"bend_range", "Pitch-bend range", "st", 0.0f, 48.0f, 2.0f, 12.0f, 0, ""},
    {"vibrato_rate", "Vibrato rate", "Hz", 0.5f, 10.0f, 5.5f, 5.0f, 0, ""},
    {"vibrato_depth", "Vibrato depth", "cents", 0.0f, 100.0f, 25.0f, 25.0f, 0, ""},
    {"body_mix", "Body", "", 0.0f, 1.0f, 1.0f, 0.5f, 0, ""},
    {"width", "Stereo width", "", 0.0f, 1.0f, 0.6f, 0.5f, 0, ""},
    {"gain", "Output gain", "dB", -60.0f, 12.0f, 0.0f, -12.0f, 0, ""},
    {"mpe", "MPE", "", 0.0f, 1.0f, 0.0f, 0.5f, 2, "Off|On"},
    {"intonation", "Intonation by ear", "", 0.0f, 1.0f, 1.0f, 0.5f, 0, ""},
    {"articulation", "Articulation", "", 0.0f, 6.0f, 0.0f, 3.0f, 16, "Detache|Martele|Spiccato|Tremolo|Col legno|Pizzicato|Harmonic"},
    {"tremolo_rate", "Tremolo rate", "strokes/s", 2.0f, 20.0f, 8.0f, 8.0f, 0, ""},
    {"spiccato_rate", "Spiccato rate", "bounces/s", 2.0f, 15.0f, 7.0f, 7.0f, 0, ""},
    {"bow_length", "Bow length", "m", 0.2f, 0.75f, 0.65f, 0.5f, 0, ""},
    {"vibrato_auto", "Automatic vibrato", "", 0.0f, 1.0f, 0.0f, 0.5f, 0, ""},
    {"vibrato_delay", "Vibrato onset delay", "s", 0.0f, 2.0f, 0.3f, 0.5f, 0, ""},
    {"mute", "Mute (sordino)", "", 0.0f, 1.0f, 0.0f, 0.5f, 2, "Off|On"},
    {"articulation_channels", "Articulation per MIDI channel", "", 0.0f, 1.0f, 0.0f, 0.5f, 2, "Off|On"},
}};
} // namespace

const ParamInfo& paramInfo(Param p) noexcept
{
    return table[static_cast<std::size_t>(std::clamp(static_cast<int>(p), 0, paramCount - 1))];
}

int paramIndex(std::string_view id) noexcept
{
    for (int i = 0; i < paramCount; ++i)
        if (table[static_cast<std::size_t>(i)].id == id) return i;
    return -1;
}

std::vector<std::string> choiceNames(Param p)
{
    std::vector<std::string> names;
    const std::string_view all = paramInfo(p).choices;
    for (std::size_t start = 0; start < all.size();) {
        const std::size_t bar = std::min(all.find('|', start), all.size());
        names.emplace_back(all.substr(start, bar - start));
        start = bar + 1;
    }
    return names;
}

int choiceIndex(Param p, std::string_view name)
{
    auto lower = [](std::string s) {
        for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        return s;
    };
    const auto names = choiceNames(p);
    for (std::size_t i = 0; i < names.size(); ++i)
        if (lower(names[i]) == lower(std::string(name))) return static_cast<int>(i);
    return -1;
}

float sanitise(Param p, float value) noexcept
{
    const ParamInfo& info = paramInfo(p);
    if (!std::isfinite(value)) return info.def;
    value = std::clamp(value, info.min, info.max);
    if (info.steps > 0) value = std::round(value);
    return value;
}

ParamValues defaultParams() noexcept
{
    ParamValues v{};
    for (int i = 0; i < paramCount; ++i) v[static_cast<std::size_t>(i)] = table[static_cast<std::size_t>(i)].def;
    return v;
}

} // namespace rosin::engine
