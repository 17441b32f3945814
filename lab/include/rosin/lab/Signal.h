// Reading a force signal from a file: WAV (any format libsndfile reads) or CSV.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace rosin::lab {

struct Signal {
    std::vector<double> samples;
    double sampleRate = 0;
};

/// WAV/FLAC/AIFF...: channel `channel` (0-based). CSV: the column named `column` (default
/// bridge_force_N) with the rate from a time_s column. Throws LabError naming file and field.
Signal readSignal(const std::filesystem::path& file, int channel = 0, const std::string& column = "bridge_force_N");

} // namespace rosin::lab
