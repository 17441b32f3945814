#include "rosin/lab/Render.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include "rosin/lab/Error.h"

namespace rosin::lab {

RenderResult render(const RenderSpec& spec, const std::function<void(double)>& progress)
{
    if (!(spec.sampleRate >= 8000.0 && spec.sampleRate <= 1.0e6)) throw LabError("--sample-rate must be within 8000..1000000 Hz");
    if (!(spec.duration > 0.0 && spec.duration <= 600.0)) throw LabError("--duration must be within 0..600 s");
    auto string = std::make_unique<dsp::BowedString<double>>();
    string->prepare(spec.sampleRate, spec.config);
    const auto n = static_cast<std::size_t>(std::llround(spec.duration * spec.sampleRate));
    RenderResult r;
    r.sampleRate = spec.sampleRate;
    r.ambientCelsius = spec.config.friction.thermal.ambientCelsius;
    r.controls.resize(n);
    r.frames.resize(n);
    const std::size_t chunk = std::max<std::size_t>(1, n / 100);
    for (std::size_t i = 0; i < n; ++i) {
        const auto c = spec.gesture.at(static_cast<double>(i) / spec.sampleRate);
        r.controls[i] = c;
        string->processSample(c.force, c.speed, c.beta, &r.frames[i]);
        if (progress && i % chunk == 0) progress(static_cast<double>(i) / static_cast<double>(n));
    }
    if (progress) progress(1.0);
    return r;
}

RenderSummary summarise(const RenderResult& r)
{
    RenderSummary s;
    std::size_t slipping = 0;
    for (std::size_t i = 0; i < r.frames.size(); ++i) {
        const auto& f = r.frames[i];
        if (!f.stick) {
            ++slipping;
            // The first slip under a pressing bow: a string with no bow on it also "slips".
            if (s.firstSlipTime < 0 && r.controls[i].force > 0) {
                s.firstSlipTime = static_cast<double>(i) / r.sampleRate;
                s.bridgeForceBeforeSlip = i > 0 ? r.frames[i - 1].bridgeForce : 0.0;
            }
        }
        s.peakTemperatureRise = std::max(s.peakTemperatureRise, double(f.temperature));
        s.peakBridgeForce = std::max(s.peakBridgeForce, std::abs(double(f.bridgeForce)));
    }
    s.slipFraction = r.frames.empty() ? 0.0 : double(slipping) / double(r.frames.size());
    return s;
}

void writeRenderCsv(const std::filesystem::path& file, const RenderResult& r)
{
    std::unique_ptr<FILE, int (*)(FILE*)> out(std::fopen(file.c_str(), "w"), &std::fclose);
    if (!out) throw LabError(file.string() + ": cannot write CSV");
    std::fprintf(out.get(), "time_s,bridge_force_N,bow_point_velocity_m_s,friction_force_N,contact_temperature_C,"
                            "temperature_rise_K,stick,bow_force_N,bow_speed_m_s,beta\n");
    for (std::size_t i = 0; i < r.frames.size(); ++i) {
        const auto& f = r.frames[i];
        const auto& c = r.controls[i];
        std::fprintf(out.get(), "%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%d,%.6g,%.6g,%.6g\n", static_cast<double>(i) / r.sampleRate,
                     f.bridgeForce, f.velocity, f.friction, r.ambientCelsius + f.temperature, f.temperature,
                     f.stick ? 1 : 0, c.force, c.speed, c.beta);
    }
    if (std::ferror(out.get())) throw LabError(file.string() + ": write error");
}

} // namespace rosin::lab
