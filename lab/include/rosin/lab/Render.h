// Offline simulation of one bow stroke and its research outputs (PHYSICS.md 6.9).
#pragma once
#include <filesystem>
#include <functional>
#include <vector>

#include "rosin/dsp.h"
#include "rosin/lab/Gesture.h"
#include "rosin/lab/Output.h"

namespace rosin::lab {

struct RenderSpec {
    dsp::BowedStringConfig config;
    Gesture gesture;
    double sampleRate = 192000.0;
    double duration = 0.5; ///< s
};

struct RenderResult {
    double sampleRate = 0.0;
    double ambientCelsius = 20.0;
    std::vector<Gesture::Controls> controls;
    std::vector<dsp::BowFrame<double>> frames;
};

/// Runs the simulation in double precision. `progress` (0..1) is called now and then.
RenderResult render(const RenderSpec& spec, const std::function<void(double)>& progress = {});

struct RenderSummary {
    double firstSlipTime = -1.0;       ///< s, -1 when the string never slipped
    double bridgeForceBeforeSlip = 0;  ///< f_br just before the first slip (N)
    double peakTemperatureRise = 0;    ///< K
    double peakBridgeForce = 0;        ///< N
    double slipFraction = 0;           ///< share of samples slipping
};
RenderSummary summarise(const RenderResult& r);

/// CSV columns: time_s, bridge_force_N, bow_point_velocity_m_s, friction_force_N,
/// contact_temperature_C, temperature_rise_K, stick, bow_force_N, bow_speed_m_s, beta.
void writeRenderCsv(const std::filesystem::path& file, const RenderResult& r);

} // namespace rosin::lab
