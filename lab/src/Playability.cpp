#include "rosin/lab/Playability.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "rosin/lab/Error.h"

namespace rosin::lab {

const char* mapKindName(MapKind k) { return k == MapKind::Schelleng ? "schelleng" : "guettler"; }

namespace {

std::vector<double> logSpaced(double lo, double hi, int n)
{
    std::vector<double> v;
    for (int i = 0; i < n; ++i) v.push_back(n == 1 ? lo : lo * std::pow(hi / lo, static_cast<double>(i) / (n - 1)));
    return v;
}

/// The string stopped at `frequency`: same tension and mass per length, shorter.
dsp::BowedStringConfig stopped(const PlayabilitySpec& spec)
{
    dsp::BowedStringConfig c = spec.config;
    const double open = c.string.fundamental();
    if (spec.frequency > 0.0 && open > 0.0) c.string.length *= open / spec.frequency;
    c.friction.switchable = false;
    return c;
}

void check(const PlayabilitySpec& spec)
{
    if (spec.forces.empty() || spec.columns.empty()) throw LabError("playability: every axis needs at least one value");
    for (double f : spec.forces)
        if (!(f > 0 && f <= 20)) throw LabError("playability: forces must be within (0, 20] N");
    for (double c : spec.columns) {
        if (spec.kind == MapKind::Schelleng && !(c >= dsp::config::minBeta && c <= dsp::config::maxBeta))
            throw LabError("playability: beta must be within 0.01..0.5");
        if (spec.kind == MapKind::Guettler && !(c > 0 && c <= 100))
            throw LabError("playability: accelerations must be within (0, 100] m/s^2");
    }
    if (!(spec.sampleRate >= 8000 && spec.sampleRate <= 1e6)) throw LabError("playability: sample rate must be within 8 kHz..1 MHz");
    if (spec.kind == MapKind::Schelleng && !(std::abs(spec.speed) > 1e-4 && std::abs(spec.speed) <= 5))
        throw LabError("playability: the bow speed must be within 0.0001..5 m/s");
    if (spec.kind == MapKind::Guettler && !(spec.beta >= dsp::config::minBeta && spec.beta <= dsp::config::maxBeta))
        throw LabError("playability: beta must be within 0.01..0.5");
    if (!(spec.frequency >= 0 && spec.frequency < spec.sampleRate / 4)) throw LabError("playability: frequency out of range");
}

PlayabilityCell schellengCell(const PlayabilitySpec& spec, dsp::BowedString<double>& s, double beta, double force)
{
    // Steady bowing: the bow reaches its speed in 20 ms and holds it; after settling, count
    // slip onsets. Helmholtz motion slips once a period at regular intervals; below the
    // minimum force the string slips more often, above the maximum it goes raucous.
    s.reset();
    const double fs = spec.sampleRate, f0 = s.waveguide().fundamental(), period = fs / f0;
    const double ramp = 0.02;
    const auto settle = static_cast<long>(spec.settleSeconds * fs), judge = static_cast<long>(spec.judgeSeconds * fs);
    // Only slips longer than a third of Helmholtz's (beta P) count: the thermal law lets short
    // ripple slips break free inside the sticking phase without changing the motion.
    const long minSlip = std::max(2L, static_cast<long>(0.35 * beta * period));
    bool wasStick = true;
    long slipStart = -1, lastOnset = -1;
    std::vector<double> intervals;
    int onsets = 0;
    for (long n = 0; n < settle + judge; ++n) {
        const double t = static_cast<double>(n) / fs;
        const double v = spec.speed * std::min(1.0, t / ramp);
        dsp::BowFrame<double> fr;
        s.processSample(force, v, beta, &fr);
        if (wasStick && !fr.stick) slipStart = n;
        if (!wasStick && fr.stick && slipStart >= settle && n - slipStart >= minSlip) {
            ++onsets;
            if (lastOnset >= 0) intervals.push_back(static_cast<double>(slipStart - lastOnset));
            lastOnset = slipStart;
        }
        wasStick = fr.stick;
    }
    PlayabilityCell c;
    c.slipsPerPeriod = onsets / (static_cast<double>(judge) / period);
    if (onsets == 0) {
        c.regime = Regime::NoSlip;
        return c;
    }
    double mean = 0, var = 0;
    for (double x : intervals) mean += x;
    mean /= std::max<std::size_t>(1, intervals.size());
    for (double x : intervals) var += (x - mean) * (x - mean);
    const double cv = intervals.size() > 1 ? std::sqrt(var / intervals.size()) / mean : 1.0;
    if (c.slipsPerPeriod >= 0.9 && c.slipsPerPeriod <= 1.1 && cv < 0.1) c.regime = Regime::Helmholtz;
    else if (c.slipsPerPeriod > 1.1) c.regime = Regime::DoubleSlip;
    else c.regime = Regime::Irregular;
    c.success = c.regime == Regime::Helmholtz;
    return c;
}

PlayabilityCell guettlerCell(const PlayabilitySpec& spec, const dsp::BowedStringConfig& config, dsp::BowedString<double>& s,
                             double accel, double force, std::vector<double>& bridge, std::vector<std::uint8_t>& stick)
{
    // A constant-acceleration stroke from rest, classified as the lab's Guettler sweeps do.
    s.reset();
    const GuettlerStroke g = runGuettlerStroke(s, config, spec.sampleRate, accel, force, spec.beta, 32.0, 1.0, bridge, stick);
    PlayabilityCell c;
    c.regime = g.classification.regime;
    c.transientPeriods = g.classification.transientPeriods;
    c.success = c.transientPeriods >= 0;
    return c;
}

} // namespace

PlayabilitySpec PlayabilitySpec::around(MapKind kind, const dsp::BowedStringConfig& config, double nominalForce,
                                        double speed, double beta, double acceleration, double frequency, int columns,
                                        int rows)
{
    PlayabilitySpec s;
    s.kind = kind;
    s.config = config;
    s.frequency = frequency;
    s.speed = std::clamp(std::abs(speed), 0.01, 2.0);
    s.beta = std::clamp(beta, 0.02, 0.3);
    const double f = std::clamp(nominalForce, 0.02, 5.0);
    if (kind == MapKind::Schelleng) {
        s.forces = logSpaced(f / 20.0, std::min(20.0, f * 8.0), rows);
        s.columns = logSpaced(0.02, 0.3, columns);
    } else {
        s.forces = logSpaced(f / 10.0, std::min(20.0, f * 4.0), rows);
        s.columns.clear();
        const double top = 2.5 * std::clamp(acceleration, 0.1, 40.0);
        for (int i = 0; i < columns; ++i) s.columns.push_back(top * (i + 1) / columns);
    }
    return s;
}

GuettlerStroke runGuettlerStroke(dsp::BowedString<double>& s, const dsp::BowedStringConfig& config, double fs, double accel,
                                 double force, double beta, double periodsAfterSlip, double maxSeconds,
                                 std::vector<double>& bridge, std::vector<std::uint8_t>& stick,
                                 std::vector<dsp::BowFrame<double>>* trace)
{
    const double f0 = config.string.fundamental();
    const auto maxN = static_cast<std::size_t>(maxSeconds * fs), tail = static_cast<std::size_t>(periodsAfterSlip * fs / f0);
    bridge.clear();
    stick.clear();
    if (trace) trace->clear();
    GuettlerStroke g;
    std::size_t end = maxN;
    double previousFriction = 0.0;
    for (std::size_t n = 0; n < end; ++n) {
        dsp::BowFrame<double> fr;
        s.processSample(force, accel * (static_cast<double>(n) / fs), beta, &fr);
        bridge.push_back(fr.bridgeForce);
        stick.push_back(fr.stick ? 1 : 0);
        if (trace) trace->push_back(fr);
        g.peakTemperature = std::max(g.peakTemperature, fr.temperature);
        if (g.firstSlip < 0 && !fr.stick) {
            g.firstSlip = static_cast<long>(n);
            g.firstJump = previousFriction - fr.friction;
            end = std::min(maxN, n + tail);
        }
        previousFriction = fr.friction;
    }
    ClassifierInput in = guettlerStrokeInput(bridge, fs, f0, beta, config.string.impedance(), config.string.tension,
                                             config.string.length, accel);
    in.stick = stick;
    g.classification = classify(in);
    return g;
}

std::size_t PlayabilityMap::completed() const { return static_cast<std::size_t>(std::count(done.begin(), done.end(), true)); }

double schellengMaxForce(double z0, double speed, double beta, double muS, double muD)
{
    return 2.0 * z0 * std::abs(speed) / (beta * (muS - muD));
}

GuettlerBounds guettlerBounds(const dsp::StringParams& s, double beta, double muS, double muD)
{
    const double P0Z0 = s.impedance() / s.fundamental();
    const double k = beta * (1.0 - beta) / P0Z0;
    const double c1 = 3.0 * muS - muD - 2.0 * std::sqrt(2.0 * muS * muS - muS * muD);
    const double c2 = ((3.0 - 4.0 * beta) * muS - muD
                       - 2.0 * std::sqrt((1.0 - 2.0 * beta) * (2.0 * (1.0 - beta) * muS * muS - muS * muD)))
                      / (1.0 - 2.0 * beta);
    GuettlerBounds b;
    b.upperPerAccel = 1.0 / (k * c1);
    b.lowerPerAccel = 1.0 / (k * c2);
    return b;
}

PlayabilityCell playabilityCell(const PlayabilitySpec& spec, double column, double force)
{
    PlayabilitySpec one = spec;
    one.columns = {column};
    one.forces = {force};
    return computePlayability(one).cells.at(0);
}

PlayabilityMap computePlayability(const PlayabilitySpec& spec, const std::atomic<bool>* cancel,
                                  const std::function<void(const PlayabilityMap&)>& onRow)
{
    check(spec);
    const dsp::BowedStringConfig config = stopped(spec);
    auto string = std::make_unique<dsp::BowedString<double>>();
    string->prepare(spec.sampleRate, config);
    PlayabilityMap map;
    map.spec = spec;
    map.f0 = config.string.fundamental();
    map.z0 = config.string.impedance();
    map.cells.assign(spec.forces.size() * spec.columns.size(), {});
    map.done.assign(map.cells.size(), false);
    std::vector<double> bridge;
    std::vector<std::uint8_t> stick;
    for (std::size_t row = 0; row < spec.forces.size(); ++row) {
        for (std::size_t col = 0; col < spec.columns.size(); ++col) {
            if (cancel && cancel->load(std::memory_order_relaxed)) return map;
            const double F = spec.forces[row], x = spec.columns[col];
            map.cells[row * spec.columns.size() + col] = spec.kind == MapKind::Schelleng
                                                              ? schellengCell(spec, *string, x, F)
                                                              : guettlerCell(spec, config, *string, x, F, bridge, stick);
            map.done[row * spec.columns.size() + col] = true;
        }
        if (onRow) onRow(map);
    }
    return map;
}

} // namespace rosin::lab
