// hid-recorder text files (hid-tools): the descriptor, device identity and timed input reports.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rosin::hid {

struct RecordedReport {
    double seconds = 0.0;
    std::vector<std::uint8_t> bytes; ///< as hidraw delivers it (report ID first when numbered)
};

struct Recording {
    std::string name, phys;
    int bus = 0;
    std::uint16_t vendor = 0, product = 0;
    std::vector<std::uint8_t> descriptor;
    std::vector<RecordedReport> reports;
};

/// Reads the first device of a recording. Throws std::runtime_error naming file and line.
Recording readRecording(const std::filesystem::path& file);
/// Reads a raw descriptor file (*.rdesc.bin).
std::vector<std::uint8_t> readBinary(const std::filesystem::path& file);

} // namespace rosin::hid
