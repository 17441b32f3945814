#include "rosin/lab/Output.h"

#include <sndfile.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "rosin/lab/Error.h"

namespace rosin::lab {
namespace fs = std::filesystem;

OutputSet::~OutputSet()
{
    if (committed_) return;
    for (const auto& [tmp, target] : files_) {
        std::error_code ec;
        fs::remove(tmp, ec);
    }
}

fs::path OutputSet::add(const fs::path& target)
{
    const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    if (!fs::is_directory(dir)) throw LabError(target.string() + ": the directory " + dir.string() + " does not exist");
    std::random_device rd;
    std::string name = ".";
    name += target.filename().string();
    name += ".tmp";
    name += std::to_string(rd() % 1000000);
    const fs::path tmp = dir / name;
    files_.emplace_back(tmp, target);
    return tmp;
}

void OutputSet::commit()
{
    for (const auto& [tmp, target] : files_) {
        std::error_code ec;
        fs::rename(tmp, target, ec);
        if (ec) throw LabError(target.string() + ": cannot move the finished file into place (" + ec.message() + ")");
    }
    committed_ = true;
}

void writeWavFrames(const fs::path& file, const std::vector<double>& interleaved, int channels, double sampleRate, int sampleFormat)
{
    SF_INFO info{};
    info.samplerate = static_cast<int>(std::lround(sampleRate));
    info.channels = channels;
    info.format = SF_FORMAT_WAV | sampleFormat;
    SNDFILE* sf = sf_open(file.c_str(), SFM_WRITE, &info);
    if (!sf) throw LabError(file.string() + ": cannot write WAV (" + sf_strerror(nullptr) + ")");
    sf_command(sf, SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);
    const auto frames = static_cast<sf_count_t>(interleaved.size() / static_cast<std::size_t>(channels));
    const sf_count_t written = sf_writef_double(sf, interleaved.data(), frames);
    sf_close(sf);
    if (written != frames) throw LabError(file.string() + ": short write (disk full?)");
}

void writeWav(const fs::path& file, const std::vector<double>& samples, double sampleRate, WavEncoding encoding)
{
    if (encoding == WavEncoding::Float32) {
        writeWavFrames(file, samples, 1, sampleRate, SF_FORMAT_FLOAT);
        return;
    }
    double peak = 0.0;
    for (double x : samples) peak = std::max(peak, std::abs(x));
    const double gain = peak > 0.0 ? std::pow(10.0, -1.0 / 20.0) / peak : 0.0;
    std::vector<double> data = samples;
    for (double& x : data) x *= gain;
    writeWavFrames(file, data, 1, sampleRate, SF_FORMAT_PCM_24);
}

Progress::Progress(std::string label, bool enabled) : label_(std::move(label)), active_(enabled && isatty(2)) {}

void Progress::update(double fraction)
{
    if (!active_) return;
    const int pct = std::clamp(static_cast<int>(fraction * 100.0), 0, 100);
    if (pct == lastShown_) return;
    lastShown_ = pct;
    const int width = 30, filled = pct * width / 100;
    std::fprintf(stderr, "\r%s [%s%s] %3d%%", label_.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), pct);
    std::fflush(stderr);
}

void Progress::finish()
{
    if (!active_) return;
    update(1.0);
    std::fprintf(stderr, "\n");
    active_ = false;
}

} // namespace rosin::lab
