#include "rosin/lab/ViewFigures.h"

#include <fstream>
#include <nlohmann/json.hpp>

#include "rosin/lab/Error.h"
#include "rosin/lab/Plot.h"

namespace rosin::lab {

LiveHistory historyOf(const RenderResult& r, double f0, double seconds)
{
    LiveHistory h(r.sampleRate, seconds);
    h.ambientCelsius = r.ambientCelsius;
    const std::size_t n = r.frames.size();
    for (std::size_t i = 0; i < n; ++i) {
        const auto& f = r.frames[i];
        const auto& c = r.controls[std::min(i, r.controls.size() - 1)];
        LiveSample s;
        s.bridgeForce = static_cast<float>(f.bridgeForce);
        s.velocity = static_cast<float>(f.velocity);
        s.friction = static_cast<float>(f.friction);
        s.temperature = static_cast<float>(f.temperature);
        s.stick = f.stick;
        s.bowSpeed = static_cast<float>(c.speed);
        s.force = static_cast<float>(c.force);
        s.beta = static_cast<float>(c.beta);
        s.frequency = static_cast<float>(f0);
        s.noteStart = i == 0;
        h.push(s);
    }
    return h;
}

void writeLiveViews(const std::filesystem::path& png, const std::filesystem::path& json, const LiveHistory& h,
                    const PlayabilityMap* map, const std::string& title)
{
    const auto g = h.gesture();
    if (!png.empty()) {
        const int W = 1400, H = 900;
        Canvas canvas(W, H);
        CairoPainter p(canvas);
        const ViewTheme t = ViewTheme::light(15.0);
        p.fillRect({0, 0, W, H}, t.background);
        p.text({20, 8, W - 40.0, 34}, title, 18, t.text, Align::Left, true);
        const double top = 48, gap = 14, w = (W - 3 * gap) / 2, hgt = (H - top - 2 * gap) / 2;
        drawScope(p, {gap, top, w, hgt}, t, h);
        drawLoop(p, {2 * gap + w, top, w, hgt}, t, h);
        drawTemperature(p, {gap, top + hgt + gap, w, hgt}, t, h);
        drawPlayability(p, {2 * gap + w, top + hgt + gap, w, hgt}, t, map, g, "no map");
        canvas.save(png);
    }
    if (!json.empty()) {
        nlohmann::json j;
        const auto s = h.scope(3.0);
        j["scope"] = {{"time_s", s.time}, {"bridge_force_N", s.force}, {"stick", s.stick}, {"triggered", s.triggered}};
        const auto l = h.loop(2.0);
        j["loop"] = {{"sliding_speed_m_s", l.slide}, {"friction_over_force", l.mu}};
        const auto tr = h.temperature(2.0, 200);
        j["temperature"] = {{"time_s", tr.time}, {"low_C", tr.low}, {"high_C", tr.high}};
        j["gesture"] = {{"force_N", g.force}, {"speed_m_s", g.speed}, {"beta", g.beta}, {"attack_acceleration_m_s2", g.acceleration}};
        std::ofstream out(json);
        out << j.dump(1) << "\n";
        if (!out) throw LabError(json.string() + ": cannot write");
    }
}

void writePlayabilityPng(const std::filesystem::path& png, const PlayabilityMap& map, const LiveHistory::Gesture& g)
{
    Canvas canvas(900, 700);
    CairoPainter p(canvas);
    const ViewTheme t = ViewTheme::light(15.0);
    p.fillRect({0, 0, 900, 700}, t.background);
    drawPlayability(p, {10, 10, 880, 680}, t, &map, g);
    canvas.save(png);
}

void writePlayabilityCsv(const std::filesystem::path& csv, const PlayabilityMap& map)
{
    std::ofstream out(csv);
    const bool schelleng = map.spec.kind == MapKind::Schelleng;
    out << (schelleng ? "beta" : "acceleration_m_s2") << ",force_N,regime,success,transient_periods,slips_per_period\n";
    for (std::size_t row = 0; row < map.spec.forces.size(); ++row)
        for (std::size_t col = 0; col < map.spec.columns.size(); ++col) {
            const auto& c = map.at(col, row);
            out << map.spec.columns[col] << ',' << map.spec.forces[row] << ',' << regimeName(c.regime) << ','
                << (c.success ? 1 : 0) << ',' << c.transientPeriods << ',' << c.slipsPerPeriod << '\n';
        }
    if (!out) throw LabError(csv.string() + ": cannot write");
}

} // namespace rosin::lab
