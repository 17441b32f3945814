// Which string plays a note: where a cellist would play it (the lowest position, a free string
// first, as in a chord), or staying on one string, or a fixed one; and where a harmonic is found.
#pragma once
#include <array>

#include "rosin/engine/Presets.h"

namespace rosin::engine {

enum class StringPolicy { LowestPosition = 0, StayOnString = 1, FixedString = 2 };

class StringChooser {
public:
    /// [setup thread] The instrument's open strings and how far up a string can be stopped.
    void prepare(const InstrumentPreset& instrument) noexcept;

    int count() const noexcept { return count_; }
    double open(int s) const noexcept { return open_[static_cast<std::size_t>(s)]; }
    /// Open pitch (a quarter-tone flat still counts) up to the highest stop.
    bool reaches(int s, double frequency) const noexcept;
    /// Whether any string can play the note (the instrument's range).
    bool playable(double frequency) const noexcept;

    /// `controllerString` is a string a controller picked (-1 none); `preferred` the channel's
    /// last string (stay-on-string policy); `occupied` a mask of strings already sounding.
    /// `fixedString` counts from 1.
    int choose(double frequency, StringPolicy policy, int fixedString, int controllerString, int preferred,
               unsigned occupied) const noexcept;
    /// A natural harmonic (string s, n = 2-3, open string) or else an artificial one (stopped at
    /// f/n, touched above it, n = 4 to 2). Returns n and sets `string`.
    int harmonic(double frequency, int& string) const noexcept;

private:
    std::array<double, maxStrings> open_{};
    int count_ = 0;
    double maxStopSemitones_ = 24.0;
};

} // namespace rosin::engine
