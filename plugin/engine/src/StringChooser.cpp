#include "rosin/engine/StringChooser.h"
#include "rosin/engine/Synth.h"

#include <algorithm>
#include <cmath>

namespace rosin::engine {

void StringChooser::prepare(const InstrumentPreset& instrument) noexcept
{
    count_ = std::clamp(instrument.stringCount, 0, maxStrings);
    for (int s = 0; s < count_; ++s) open_[static_cast<std::size_t>(s)] = instrument.strings[static_cast<std::size_t>(s)].fundamental();
    maxStopSemitones_ = instrument.maxStopSemitones;
}

bool StringChooser::reaches(int s, double frequency) const noexcept
{
    if (s < 0 || s >= count_) return false;
    return frequency >= open(s) * std::exp2(-0.5 / 12.0) && frequency <= open(s) * std::exp2(maxStopSemitones_ / 12.0);
}

bool StringChooser::playable(double frequency) const noexcept
{
    for (int s = 0; s < count_; ++s)
        if (reaches(s, frequency)) return true;
    return false;
}

int StringChooser::choose(double frequency, StringPolicy policy, int fixedString, int controllerString, int preferred,
                          unsigned occupied) const noexcept
{
    const int n = count_;
    if (n <= 0) return 0;
    if (reaches(controllerString, frequency)) return controllerString; // the controller picked it
    if (policy == StringPolicy::StayOnString && reaches(preferred, frequency)) return preferred;
    if (policy == StringPolicy::FixedString) {
        const int fixed = std::clamp(fixedString - 1, 0, n - 1);
        if (reaches(fixed, frequency)) return fixed;
    }
    // Lowest position: the highest open string at or below the note, a free one first.
    for (int pass = 0; pass < 2; ++pass)
        for (int s = n - 1; s >= 0; --s)
            if (reaches(s, frequency) && (pass == 1 || !(occupied & (1u << s)))) return s;
    return frequency < open(0) ? 0 : n - 1; // outside the instrument: the lowest string tuned down, or the top one
}

int StringChooser::harmonic(double frequency, int& string) const noexcept
{
    // Natural harmonics an octave and a twelfth up (the ones that speak readily on an open
    // string); beyond that an artificial harmonic: a stopped note touched a fourth (n = 4), a
    // fifth (3) or an octave (2) above, on a string that is really stopped.
    for (int n = 2; n <= 3; ++n)
        for (int s = count_ - 1; s >= 0; --s)
            if (std::abs(1200.0 * std::log2(frequency / (n * open(s)))) < 30.0) {
                string = s;
                return n;
            }
    for (int n = 4; n >= 2; --n) {
        const int s = choose(frequency / n, StringPolicy::LowestPosition, 1, -1, -1, 0u);
        if (frequency / n > open(s) * std::exp2(1.0 / 12.0)) { // at least a semitone up: a finger stops it
            string = s;
            return n;
        }
    }
    string = 0;
    return 2;
}

// The instrument's strings as the model takes them (units, rosin, the parameters' friction
// choices), and the force scale that puts every string at the same Schelleng point.
dsp::BowedStringConfig stringConfig(const InstrumentPreset& instrument, int s, const ParamValues& params)
{
    const auto p = [&](Param q) { return sanitise(q, params[static_cast<std::size_t>(q)]); };
    dsp::BowedStringConfig c;
    c.string = instrument.strings[static_cast<std::size_t>(std::clamp(s, 0, std::max(0, instrument.stringCount - 1)))];
    c.waveguide.lowestPitchRatio = 0.5; // an octave of bend below the open string
    c.waveguide.dispersion = false;     // the allpass fit is not redone per stop
    c.friction.switchable = true;
    c.friction.model = static_cast<dsp::FrictionModel>(static_cast<int>(p(Param::FrictionModel)));
    c.friction.contactLaw = p(Param::ContactLaw) > 0.5f ? dsp::ContactLaw::PowerLaw : dsp::ContactLaw::Amontons;
    c.friction.thermal.glassTransitionCelsius = p(Param::RosinTg);
    c.friction.thermal.ambientCelsius = p(Param::Ambient);
    c.friction.thermal.footprintRatio = p(Param::Footprint);
    return c;
}

double stringForceScale(const InstrumentPreset& instrument, int s)
{
    if (s < 0 || s >= instrument.stringCount) return 1.0;
    const double zRef = instrument.strings[static_cast<std::size_t>(std::min(2, instrument.stringCount - 1))].impedance();
    return instrument.strings[static_cast<std::size_t>(s)].impedance() / zRef;
}

} // namespace rosin::engine
