// `rosin figures`: the story of Euphonics 9.6 regenerated from scratch as PNG + data.
#pragma once
#include <filesystem>
#include <functional>
#include <string>

namespace rosin::lab {

struct FigureSetOptions {
    double sweepRate = 48000.0;      ///< Guettler sweeps (justified by the convergence table)
    double transientRate = 192000.0; ///< single transients and loops, research quality
    int grid = 20;                   ///< cells per axis
    int variants = 5;                ///< for the min-over-N maps
    std::uint64_t seed = 1;
    bool quiet = false;
};

/// Writes every figure and its data into `dir` (created if missing). Returns a one-line
/// summary per figure for the terminal.
std::string writeFigureSet(const std::filesystem::path& dir, const FigureSetOptions& options);

} // namespace rosin::lab
