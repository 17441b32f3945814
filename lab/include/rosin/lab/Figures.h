// Figures of the lab: Guettler diagrams (PHYSICS.md 6.6 convention), panels of them, and the
// Euphonics 9.6 figure set. Every PNG is written beside the data it shows.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "rosin/lab/Guettler.h"
#include "rosin/lab/Plot.h"
#include "rosin/lab/Views.h" // transientColor, regimeColor

namespace rosin::lab {

struct DiagramOptions {
    std::string title;
    bool bounds = true;   ///< Guettler's lossless-string bounds (PHYSICS.md 6.3)
    bool fit = true;      ///< fitted lower boundary F = c a^p
    double muS = 1.2, muD = 0.35; ///< friction coefficients for the bounds
    std::string xLabel = "bow acceleration (m/s\u00b2)"; ///< the other gestures' maps have their own drive
};


/// One diagram in the given pixel box (axes, cells, overlays).
void drawGuettler(Canvas& canvas, double left, double top, double width, double height, const SweepResult& r,
                  std::size_t betaIndex, const DiagramOptions& options);
/// Colour key: N_T 0..25 and the failure colours.
void drawColorKey(Canvas& canvas, double left, double top, double height);

/// One PNG per sweep (several betas side by side).
void writeGuettlerPng(const std::filesystem::path& file, const SweepResult& r, const DiagramOptions& options);
/// Several sweeps laid out in rows of `columns` (Euphonics Fig. 19 style).
void writePanelPng(const std::filesystem::path& file, const std::vector<SweepResult>& sweeps,
                   const std::vector<std::string>& titles, int columns, const DiagramOptions& options);

/// Reads a table written by writeSweepJson (for panels of earlier sweeps).
SweepResult readSweepJson(const std::filesystem::path& file);

} // namespace rosin::lab
