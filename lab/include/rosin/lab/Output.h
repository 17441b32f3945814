// Files the lab writes. Everything goes to a temporary name first and is renamed into place
// only when all outputs of a command are complete, so a failure leaves no half-written file.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

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

/// Writes a WAV of `channels` interleaved channels with libsndfile, `sampleFormat` one of
/// SF_FORMAT_FLOAT, SF_FORMAT_PCM_24, ... Without libsndfile's PEAK chunk, which holds the time
/// of writing: the same samples written twice give the same bytes. Throws LabError naming the file.
void writeWavFrames(const std::filesystem::path& file, const std::vector<double>& interleaved, int channels, double sampleRate,
                    int sampleFormat);

/// Writes a mono WAV. Throws LabError naming the file.
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
