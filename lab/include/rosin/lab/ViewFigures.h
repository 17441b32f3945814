// The editor's live views as PNG figures (light theme), with their data beside them: the same
// drawing code the plugin window runs, fed from an offline render instead of the audio thread.
#pragma once
#include <filesystem>

#include "rosin/lab/Playability.h"
#include "rosin/lab/Render.h"
#include "rosin/lab/Views.h"

namespace rosin::lab {

/// The recent past of a render of a string with fundamental f0, as the editor would hold it
/// at the render's end.
LiveHistory historyOf(const RenderResult& r, double f0, double seconds = 2.0);

/// Scope, temperature, friction loop and (when given) the playability map with the gesture as a
/// point, 2 x 2, to `png`; the plotted numbers to `json`. Either path may be empty.
void writeLiveViews(const std::filesystem::path& png, const std::filesystem::path& json, const LiveHistory& h,
                    const PlayabilityMap* map, const std::string& title);

/// A playability map alone: PNG, and a CSV with one row per cell.
void writePlayabilityPng(const std::filesystem::path& png, const PlayabilityMap& map, const LiveHistory::Gesture& g);
void writePlayabilityCsv(const std::filesystem::path& csv, const PlayabilityMap& map);

} // namespace rosin::lab
