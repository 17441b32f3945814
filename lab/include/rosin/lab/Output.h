// Files the lab writes. Everything goes to a temporary name first and is renamed into place
// only when all outputs of a command are complete, so a failure leaves no half-written file.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

struct sf_private_tag; // libsndfile's SNDFILE, for withoutPeakChunk without its header

namespace rosin::lab {

class OutputSet {
public:
    OutputSet() = default;
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;
    ~OutputSet(); ///< removes any temporary files not committed

    /// Reserves `target`; returns the temporary path to write it to.
    std::filesystem::path add(const std::filesystem::path& target);
    /// Renames every temporary file onto its target.
    void commit();

private:
    std::vector<std::pair<std::filesystem::path, std::filesystem::path>> files_;
    bool committed_ = false;
};

enum class WavEncoding {
    Float32,        ///< raw values (newtons): exact data for analysis
    Pcm24Normalized ///< peak-normalised to -1 dBFS, for listening
};

/// Leaves out the PEAK chunk libsndfile adds to float WAVs: it holds the time of writing, so
/// the same samples written twice would differ. Call after sf_open, before any data.
void withoutPeakChunk(sf_private_tag* file);

/// Writes a mono WAV with libsndfile. Throws LabError naming the file.
void writeWav(const std::filesystem::path& file, const std::vector<double>& samples, double sampleRate, WavEncoding encoding);

/// A progress bar on stderr when it is a terminal; silent when piped or redirected.
class Progress {
public:
    Progress(std::string label, bool enabled = true);
    void update(double fraction);
    void finish();

private:
    std::string label_;
    bool active_;
    int lastShown_ = -1;
};

} // namespace rosin::lab
