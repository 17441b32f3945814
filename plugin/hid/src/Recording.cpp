#include "rosin/hid/Recording.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rosin::hid {

namespace {
std::vector<std::uint8_t> hexBytes(std::istringstream& s, std::size_t expected, const std::string& where)
{
    std::vector<std::uint8_t> out;
    std::string tok;
    while (s >> tok) {
        std::size_t used = 0;
        unsigned long v = 0;
        try { v = std::stoul(tok, &used, 16); } catch (...) { used = 0; }
        if (used != tok.size() || v > 255) throw std::runtime_error(where + ": '" + tok + "' is not a hex byte");
        out.push_back(static_cast<std::uint8_t>(v));
    }
    if (out.size() != expected)
        throw std::runtime_error(where + ": length says " + std::to_string(expected) + " bytes, found " + std::to_string(out.size()));
    return out;
}
} // namespace

Recording readRecording(const std::filesystem::path& file)
{
    std::ifstream in(file);
    if (!in) throw std::runtime_error(file.string() + ": cannot open recording");
    Recording r;
    std::string line;
    int number = 0, device = 0;
    while (std::getline(in, line)) {
        ++number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        const std::string where = file.string() + ":" + std::to_string(number);
        if (line.size() < 2 || line[1] != ':') throw std::runtime_error(where + ": expected 'X: ...'");
        std::istringstream s(line.substr(2));
        switch (line[0]) {
        case 'D': s >> device; break;
        case 'R': {
            if (device != 0) break;
            std::size_t len = 0;
            if (!(s >> len) || len > 4096) throw std::runtime_error(where + ": bad descriptor length");
            r.descriptor = hexBytes(s, len, where);
            break;
        }
        case 'N': if (device == 0) r.name = line.size() > 3 ? line.substr(3) : ""; break;
        case 'P': if (device == 0) r.phys = line.size() > 3 ? line.substr(3) : ""; break;
        case 'I': {
            std::string bus, vid, pid;
            if (!(s >> bus >> vid >> pid)) throw std::runtime_error(where + ": expected 'I: bus vid pid'");
            try {
                r.bus = static_cast<int>(std::stoul(bus, nullptr, 16));
                r.vendor = static_cast<std::uint16_t>(std::stoul(vid, nullptr, 16));
                r.product = static_cast<std::uint16_t>(std::stoul(pid, nullptr, 16));
            } catch (...) {
                throw std::runtime_error(where + ": bus, vendor and product must be hex");
            }
            break;
        }
        case 'E': {
            if (device != 0) break;
            RecordedReport e;
            std::size_t len = 0;
            if (!(s >> e.seconds >> len) || len > 4096) throw std::runtime_error(where + ": expected 'E: seconds length bytes...'");
            e.bytes = hexBytes(s, len, where);
            r.reports.push_back(std::move(e));
            break;
        }
        default: break; // other record kinds (S:, F:) carry nothing we replay
        }
    }
    if (r.descriptor.empty()) throw std::runtime_error(file.string() + ": no 'R:' descriptor line");
    return r;
}

std::vector<std::uint8_t> readBinary(const std::filesystem::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) throw std::runtime_error(file.string() + ": cannot open");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

} // namespace rosin::hid
