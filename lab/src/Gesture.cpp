#include "rosin/lab/Gesture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "rosin/lab/Error.h"

namespace rosin::lab {

Gesture::Controls Gesture::at(double t) const noexcept
{
    switch (kind) {
    case GestureKind::Guettler: return {force, acceleration * t, beta};
    case GestureKind::Constant: return {force, speed, beta};
    case GestureKind::ExpSpeed: return {force, speed * (1.0 - std::exp(-t / timeConstant)), beta};
    case GestureKind::ExpForce: return {force * (1.0 - std::exp(-t / timeConstant)), speed, beta};
    case GestureKind::File: break;
    }
    if (rows.empty()) return {0.0, 0.0, beta};
    if (t <= rows.front().time) return {rows.front().force, rows.front().speed, rows.front().beta};
    if (t >= rows.back().time) return {rows.back().force, rows.back().speed, rows.back().beta};
    const auto it = std::upper_bound(rows.begin(), rows.end(), t, [](double x, const GestureRow& r) { return x < r.time; });
    const GestureRow& b = *it;
    const GestureRow& a = *(it - 1);
    const double s = (t - a.time) / (b.time - a.time);
    return {a.force + s * (b.force - a.force), a.speed + s * (b.speed - a.speed), a.beta + s * (b.beta - a.beta)};
}

double Gesture::drive() const noexcept
{
    switch (kind) {
    case GestureKind::Guettler: return acceleration;
    case GestureKind::ExpSpeed: return speed / timeConstant;
    case GestureKind::Constant:
    case GestureKind::ExpForce: return speed;
    case GestureKind::File: break;
    }
    return 0.0;
}

GestureKind parseGestureKind(const std::string& name)
{
    if (name == "guettler") return GestureKind::Guettler;
    if (name == "constant") return GestureKind::Constant;
    if (name == "exp-speed") return GestureKind::ExpSpeed;
    if (name == "exp-force") return GestureKind::ExpForce;
    if (name == "file") return GestureKind::File;
    throw LabError("--gesture: unknown gesture '" + name + "' (guettler, constant, exp-speed, exp-force, file)");
}

std::vector<GestureRow> loadGestureFile(const std::filesystem::path& file)
{
    std::ifstream in(file);
    if (!in) throw LabError(file.string() + ": cannot open gesture file");
    const std::array<std::string, 4> names{"time", "force", "speed", "beta"};
    std::array<int, 4> column{-1, -1, -1, -1};
    std::vector<GestureRow> rows;
    std::string line;
    int lineNo = 0;
    bool haveHeader = false;
    auto fail = [&](const std::string& what) { throw LabError(file.string() + ":" + std::to_string(lineNo) + ": " + what); };
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const auto first = line.find_first_not_of(" \t");
        if (first == std::string::npos || line[first] == '#') continue;
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string cell; std::getline(ss, cell, ',');) {
            const auto a = cell.find_first_not_of(" \t"), b = cell.find_last_not_of(" \t");
            cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
        }
        if (!haveHeader) {
            for (std::size_t c = 0; c < cells.size(); ++c)
                for (std::size_t k = 0; k < names.size(); ++k)
                    if (cells[c] == names[k]) column[k] = static_cast<int>(c);
            for (std::size_t k = 0; k < names.size(); ++k)
                if (column[k] < 0) fail("header must name the column '" + names[k] + "' (time,force,speed,beta)");
            haveHeader = true;
            continue;
        }
        std::array<double, 4> v{};
        for (std::size_t k = 0; k < names.size(); ++k) {
            if (column[k] >= static_cast<int>(cells.size())) fail("field '" + names[k] + "' is missing");
            const std::string& cell = cells[column[k]];
            const std::optional<double> number = wholeNumber(cell);
            if (!number || !std::isfinite(*number))
                fail("field '" + names[k] + "' is not a finite number: '" + cell + "'");
            v[k] = *number;
        }
        GestureRow r{v[0], v[1], v[2], v[3]};
        if (r.time < 0) fail("field 'time' must not be negative");
        if (!rows.empty() && r.time <= rows.back().time) fail("field 'time' must increase from row to row");
        if (r.force < 0 || r.force > 20) fail("field 'force' must be within 0..20 N");
        if (std::abs(r.speed) > 10) fail("field 'speed' must be within -10..10 m/s");
        if (r.beta < 0.01 || r.beta > 0.5) fail("field 'beta' must be within 0.01..0.5");
        rows.push_back(r);
    }
    if (!haveHeader) throw LabError(file.string() + ": empty gesture file (needs a header time,force,speed,beta)");
    if (rows.size() < 2) throw LabError(file.string() + ": a gesture needs at least two rows");
    return rows;
}

} // namespace rosin::lab
