// Build-time fix for Debian's JUCE 7.0.5 LV2 description (run after juce_lv2_helper writes
// dsp.ttl): an enumerated parameter's scale points are written at normalised values (0, 1/3,
// 2/3, 1) while its range and default are the plain index (0..3, default 2), so LV2 hosts label
// every choice wrongly (a fresh plugin showed "double-bass" for the cello default). JUCE's port
// values for these parameters are plain: the k-th scale point of each list gets the value k.
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>

int main(int argc, char** argv)
{
    if (argc != 2) {
        std::cerr << "usage: fix_lv2_scale_points dsp.ttl\n";
        return 2;
    }
    std::ifstream in(argv[1]);
    if (!in) {
        std::cerr << argv[1] << ": cannot open\n";
        return 1;
    }
    const std::regex value(R"(^(\s*rdf:value )[-+0-9.eE]+(\s*;.*)$)");
    std::ostringstream out;
    std::string line;
    int point = -1, fixed = 0;
    while (std::getline(in, line)) {
        if (line.find("lv2:scalePoint") != std::string::npos) point = 0;
        std::smatch m;
        if (point >= 0 && std::regex_match(line, m, value)) {
            line = m[1].str() + std::to_string(point++) + m[2].str();
            ++fixed;
        }
        if (point >= 0 && line.find("] .") != std::string::npos) point = -1;
        out << line << "\n";
    }
    in.close();
    std::ofstream(argv[1]) << out.str();
    std::cout << "fix_lv2_scale_points: " << fixed << " scale points in " << argv[1] << "\n";
    return 0;
}
