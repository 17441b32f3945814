#include "rosin/lab/Signal.h"

#include <sndfile.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "rosin/lab/Error.h"

namespace rosin::lab {

namespace {
Signal readCsv(const std::filesystem::path& file, const std::string& column)
{
    std::ifstream in(file);
    if (!in) throw LabError(file.string() + ": cannot open");
    std::string line;
    int lineNo = 0, timeCol = -1, valueCol = -1;
    std::vector<double> times;
    Signal s;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        if (timeCol < 0 && valueCol < 0) {
            for (std::size_t i = 0; i < cells.size(); ++i) {
                if (cells[i] == "time_s" || cells[i] == "time") timeCol = static_cast<int>(i);
                if (cells[i] == column) valueCol = static_cast<int>(i);
            }
            if (timeCol < 0) throw LabError(file.string() + ":" + std::to_string(lineNo) + ": no 'time_s' column in the header");
            if (valueCol < 0) throw LabError(file.string() + ":" + std::to_string(lineNo) + ": no '" + column + "' column in the header");
            continue;
        }
        auto value = [&](int col, const char* name) {
            if (col >= static_cast<int>(cells.size()))
                throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field '" + name + "' is missing");
            try {
                std::size_t used = 0;
                const double x = std::stod(cells[col], &used);
                if (std::isfinite(x)) return x;
            } catch (const std::exception&) {
            }
            throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field '" + name + "' is not a finite number");
        };
        times.push_back(value(timeCol, "time_s"));
        s.samples.push_back(value(valueCol, column.c_str()));
    }
    if (times.size() < 2) throw LabError(file.string() + ": fewer than two rows");
    const double dt = (times.back() - times.front()) / static_cast<double>(times.size() - 1);
    if (!(dt > 0)) throw LabError(file.string() + ": field 'time_s' does not increase");
    s.sampleRate = 1.0 / dt;
    return s;
}
} // namespace

Signal readSignal(const std::filesystem::path& file, int channel, const std::string& column)
{
    if (file.extension() == ".csv") return readCsv(file, column);
    SF_INFO info{};
    SNDFILE* sf = sf_open(file.c_str(), SFM_READ, &info);
    if (!sf) throw LabError(file.string() + ": cannot read as audio (" + sf_strerror(nullptr) + ")");
    if (channel < 0 || channel >= info.channels) {
        sf_close(sf);
        throw LabError(file.string() + ": channel " + std::to_string(channel) + " does not exist (" + std::to_string(info.channels) + " channels)");
    }
    std::vector<double> all(static_cast<std::size_t>(info.frames) * static_cast<std::size_t>(info.channels));
    const sf_count_t got = sf_readf_double(sf, all.data(), info.frames);
    sf_close(sf);
    if (got != info.frames) throw LabError(file.string() + ": truncated audio data");
    Signal s;
    s.sampleRate = info.samplerate;
    s.samples.resize(static_cast<std::size_t>(info.frames));
    for (sf_count_t i = 0; i < info.frames; ++i) {
        s.samples[i] = all[static_cast<std::size_t>(i) * static_cast<std::size_t>(info.channels) + static_cast<std::size_t>(channel)];
        if (!std::isfinite(s.samples[i])) throw LabError(file.string() + ": sample " + std::to_string(i) + " is not finite");
    }
    return s;
}

} // namespace rosin::lab
