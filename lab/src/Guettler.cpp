#include "rosin/lab/Guettler.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>

#include "rosin/lab/Distributed.h"
#include "rosin/lab/Error.h"

namespace rosin::lab {

std::vector<double> SweepSpec::grid(double lo, double hi, int n)
{
    std::vector<double> g;
    for (int i = 0; i < n; ++i) g.push_back(n == 1 ? lo : lo + (hi - lo) * i / (n - 1));
    return g;
}

int SweepResult::successCount() const
{
    return static_cast<int>(std::count_if(cells.begin(), cells.end(), [](const CellResult& c) { return c.transientPeriods >= 0; }));
}

namespace {

/// Deterministic per-(seed, cell, variant) stream, independent of thread and rank.
std::uint64_t mix(std::uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

struct Perturbed {
    double accel, force, beta, ambient, noise;
    std::uint64_t noiseSeed;
};

/// PHYSICS.md 6.7: the datum plus runs with beta +-0.5 %, ambient +-1 K, force and
/// acceleration jittered by +-1 %, and 0.1 % friction noise during slip with its own seed.
Perturbed perturb(const SweepSpec& spec, double a, double F, double beta, std::uint64_t cell, int variant)
{
    Perturbed p{a, F, beta, spec.config.friction.thermal.ambientCelsius, 0.0, 0};
    if (variant == 0) return p;
    std::mt19937_64 rng(mix(spec.seed ^ mix(cell * 1000003ull + static_cast<std::uint64_t>(variant))));
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double sign = u(rng) < 0 ? -1.0 : 1.0;
    switch ((variant - 1) % 4) {
    case 0: p.beta *= 1.0 + 0.005 * sign; break;
    case 1: p.ambient += 1.0 * sign; break;
    case 2: p.force *= 1.0 + 0.01 * u(rng); p.accel *= 1.0 + 0.01 * u(rng); break;
    case 3: p.noise = 1e-3; p.noiseSeed = rng(); break;
    }
    return p;
}

struct Worker {
    std::unique_ptr<dsp::BowedString<double>> string;
    std::vector<double> bridge;
    std::vector<std::uint8_t> stick;
};

CellResult runStroke(const SweepSpec& spec, Worker& w, double a, double F, double beta, int variant, std::uint64_t cell,
                     std::vector<dsp::BowFrame<double>>* trace, long long* samples)
{
    const Perturbed p = perturb(spec, a, F, beta, cell, variant);
    auto& s = *w.string;
    s.reset();
    s.junction().setAmbient(p.ambient);
    s.junction().setSlipNoise(p.noise, p.noiseSeed);
    CellResult r;
    r.acceleration = a;
    r.force = F;
    r.beta = beta;
    r.variant = variant;
    const GuettlerStroke g = runGuettlerStroke(s, spec.config, spec.sampleRate, p.accel, p.force, p.beta, spec.periodsAfterSlip,
                                               spec.maxSeconds, w.bridge, w.stick, trace);
    if (samples) *samples += static_cast<long long>(w.bridge.size());
    r.regime = g.classification.regime;
    r.transientPeriods = g.classification.transientPeriods;
    r.peakTemperature = g.peakTemperature;
    if (g.firstSlip >= 0) {
        r.firstSlipTime = static_cast<double>(g.firstSlip) / spec.sampleRate;
        r.forceBeforeSlip = g.firstSlip > 0 ? w.bridge[static_cast<std::size_t>(g.firstSlip) - 1] : 0.0;
        r.firstJump = g.firstJump;
    }
    return r;
}

Worker makeWorker(const SweepSpec& spec)
{
    Worker w;
    w.string = std::make_unique<dsp::BowedString<double>>();
    w.string->prepare(spec.sampleRate, spec.config);
    const auto cap = static_cast<std::size_t>(spec.maxSeconds * spec.sampleRate) + 1;
    w.bridge.reserve(cap);
    w.stick.reserve(cap);
    return w;
}

void checkModel(const SweepSpec& spec)
{
    if (spec.variants < 1 || spec.variants > 64) throw LabError("sweep: variants must be within 1..64");
    if (!(spec.sampleRate >= 8000 && spec.sampleRate <= 1e6)) throw LabError("sweep: sample rate must be within 8 kHz..1 MHz");
    if (!(spec.maxSeconds > 0 && spec.maxSeconds <= 60)) throw LabError("sweep: the longest stroke must be within 0..60 s");
    if (!(spec.periodsAfterSlip >= 1 && spec.periodsAfterSlip <= 1000)) throw LabError("sweep: periods after the first slip must be within 1..1000");
}

void checkSpec(const SweepSpec& spec)
{
    checkModel(spec);
    if (spec.accelerations.empty() || spec.forces.empty() || spec.betas.empty())
        throw LabError("sweep: every axis needs at least one value");
    for (double a : spec.accelerations)
        if (!(a > 0 && a <= 100)) throw LabError("sweep: accelerations must be within (0, 100] m/s^2");
    for (double f : spec.forces)
        if (!(f > 0 && f <= 20)) throw LabError("sweep: forces must be within (0, 20] N");
    for (double b : spec.betas)
        if (!(b >= dsp::config::minBeta && b <= dsp::config::maxBeta)) throw LabError("sweep: beta must be within 0.01..0.5");
}

bool better(const CellResult& a, const CellResult& b)
{
    // Shorter transient wins; any success beats any failure; ties keep the lower variant.
    if (a.transientPeriods >= 0 && b.transientPeriods >= 0) return a.transientPeriods < b.transientPeriods;
    return a.transientPeriods >= 0 && b.transientPeriods < 0;
}

} // namespace

CellResult simulateCell(const SweepSpec& spec, double accel, double force, double beta, int variant,
                        std::vector<dsp::BowFrame<double>>* trace, std::uint64_t cellIndex)
{
    checkModel(spec);
    Worker w = makeWorker(spec);
    return runStroke(spec, w, accel, force, beta, variant, cellIndex, trace, nullptr);
}

SweepResult runSweep(const SweepSpec& spec, const std::function<void(double)>& progress)
{
    checkSpec(spec);
    const auto start = std::chrono::steady_clock::now();
    const std::size_t nA = spec.accelerations.size(), nF = spec.forces.size(), nB = spec.betas.size();
    const std::size_t cells = nA * nF * nB, tasks = cells * static_cast<std::size_t>(spec.variants);
    const Distributed& dist = Distributed::instance();

    std::vector<CellResult> all(tasks);
    std::atomic<std::size_t> done{0};
    std::atomic<long long> samples{0};
    std::mutex progressLock;
    tbb::enumerable_thread_specific<Worker> workers([&] { return makeWorker(spec); });
    // Tasks are dealt round-robin to MPI ranks; within a rank, to cores.
    std::vector<std::size_t> mine;
    for (std::size_t t = static_cast<std::size_t>(dist.rank()); t < tasks; t += static_cast<std::size_t>(dist.size()))
        mine.push_back(t);
    tbb::parallel_for(std::size_t(0), mine.size(), [&](std::size_t k) {
        const std::size_t t = mine[k];
        const std::size_t cell = t / static_cast<std::size_t>(spec.variants);
        const int variant = static_cast<int>(t % static_cast<std::size_t>(spec.variants));
        const std::size_t ia = cell % nA, iF = (cell / nA) % nF, ib = cell / (nA * nF);
        long long local = 0;
        all[t] = runStroke(spec, workers.local(), spec.accelerations[ia], spec.forces[iF], spec.betas[ib], variant, cell,
                           nullptr, &local);
        samples += local;
        const std::size_t finished = ++done;
        if (progress && progressLock.try_lock()) {
            progress(static_cast<double>(finished) / static_cast<double>(mine.size()));
            progressLock.unlock();
        }
    });
    dist.combine(all, samples);

    SweepResult result;
    result.spec = spec;
    result.cells.resize(cells);
    for (std::size_t c = 0; c < cells; ++c) {
        CellResult best = all[c * static_cast<std::size_t>(spec.variants)];
        for (int v = 1; v < spec.variants; ++v) {
            const CellResult& cand = all[c * static_cast<std::size_t>(spec.variants) + static_cast<std::size_t>(v)];
            if (better(cand, best)) best = cand;
        }
        // The table reports the datum's own first-slip data, the minimum's N_T and regime.
        const CellResult& datum = all[c * static_cast<std::size_t>(spec.variants)];
        best.acceleration = datum.acceleration;
        best.force = datum.force;
        best.beta = datum.beta;
        best.firstSlipTime = datum.firstSlipTime;
        best.forceBeforeSlip = datum.forceBeforeSlip;
        best.firstJump = datum.firstJump;
        for (int v = 0; v < spec.variants; ++v)
            best.peakTemperature = std::max(best.peakTemperature, all[c * static_cast<std::size_t>(spec.variants) + static_cast<std::size_t>(v)].peakTemperature);
        result.cells[c] = best;
    }
    result.simulatedSamples = samples.load();
    result.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

void writeSweepCsv(const std::filesystem::path& file, const SweepResult& r)
{
    std::unique_ptr<FILE, int (*)(FILE*)> out(std::fopen(file.c_str(), "w"), &std::fclose);
    if (!out) throw LabError(file.string() + ": cannot write CSV");
    std::fprintf(out.get(), "beta,accel_m_s2,force_N,first_slip_s,bridge_force_before_slip_N,first_jump_N,"
                            "transient_periods,regime,peak_temperature_K,variant\n");
    for (const auto& c : r.cells)
        std::fprintf(out.get(), "%.6g,%.6g,%.6g,%.9g,%.9g,%.9g,%d,%s,%.6g,%d\n", c.beta, c.acceleration, c.force,
                     c.firstSlipTime, c.forceBeforeSlip, c.firstJump, c.transientPeriods, regimeName(c.regime),
                     c.peakTemperature, c.variant);
    if (std::ferror(out.get())) throw LabError(file.string() + ": write error");
}

void writeSweepJson(const std::filesystem::path& file, const SweepResult& r)
{
    using nlohmann::json;
    const auto& s = r.spec;
    json spec{{"model", s.label},
              {"string", s.config.string.name},
              {"string_params", {{"length_m", s.config.string.length}, {"tension_N", s.config.string.tension},
                                 {"mass_per_length_kg_m", s.config.string.massPerLength},
                                 {"f0_hz", s.config.string.fundamental()}, {"z0_kg_s", s.config.string.impedance()}}},
              {"sample_rate_hz", s.sampleRate},
              {"accelerations_m_s2", s.accelerations},
              {"forces_N", s.forces},
              {"betas", s.betas},
              {"variants", s.variants},
              {"seed", s.seed},
              {"periods_after_slip", s.periodsAfterSlip},
              {"max_seconds", s.maxSeconds},
              {"torsion", s.config.waveguide.torsion},
              {"contact_exponent", s.config.friction.contactLaw == dsp::ContactLaw::Amontons ? 1.0 : s.config.friction.contactExponent},
              {"ambient_C", s.config.friction.thermal.ambientCelsius},
              {"footprint_ratio", s.config.friction.thermal.footprintRatio},
              {"glass_transition_C", s.config.friction.thermal.glassTransitionCelsius}};
    json cells = json::array();
    for (const auto& c : r.cells)
        cells.push_back({{"beta", c.beta}, {"accel_m_s2", c.acceleration}, {"force_N", c.force},
                         {"first_slip_s", c.firstSlipTime}, {"bridge_force_before_slip_N", c.forceBeforeSlip},
                         {"first_jump_N", c.firstJump}, {"transient_periods", c.transientPeriods},
                         {"regime", regimeName(c.regime)}, {"peak_temperature_K", c.peakTemperature}, {"variant", c.variant}});
    const json doc{{"format", "rosin-guettler/1"}, {"spec", spec}, {"success_cells", r.successCount()}, {"cells", cells}};
    std::unique_ptr<FILE, int (*)(FILE*)> out(std::fopen(file.c_str(), "w"), &std::fclose);
    if (!out) throw LabError(file.string() + ": cannot write JSON");
    const std::string text = doc.dump(1);
    std::fwrite(text.data(), 1, text.size(), out.get());
    if (std::ferror(out.get())) throw LabError(file.string() + ": write error");
}

BoundaryFit fitLowerBoundary(const SweepResult& r, std::size_t ib)
{
    BoundaryFit fit;
    const auto& A = r.spec.accelerations;
    const auto& F = r.spec.forces;
    // Per acceleration column: the lowest force of a successful pair of neighbouring cells
    // (one isolated success is a speckle, not the region); the boundary sits halfway down to
    // the failing cell below. A column whose lowest cell succeeds is censored (boundary below
    // the grid) and left out, as is one with no success at all.
    for (std::size_t ia = 0; ia < A.size(); ++ia) {
        for (std::size_t iF = 1; iF + 1 < F.size(); ++iF) {
            const bool here = r.at(ia, iF, ib).transientPeriods >= 0, above = r.at(ia, iF + 1, ib).transientPeriods >= 0;
            const bool below = r.at(ia, iF - 1, ib).transientPeriods >= 0;
            if (here && above) {
                if (!below) {
                    fit.accelerations.push_back(A[ia]);
                    fit.forces.push_back(0.5 * (F[iF] + F[iF - 1]));
                }
                break;
            }
        }
    }
    const std::size_t n = fit.accelerations.size();
    if (n < 4) return fit;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double x = std::log(fit.accelerations[i]), y = std::log(fit.forces[i]);
        sx += x; sy += y; sxx += x * x; sxy += x * y;
    }
    const double dn = static_cast<double>(n);
    const double den = dn * sxx - sx * sx;
    if (den <= 0) return fit;
    fit.p = (dn * sxy - sx * sy) / den;
    const double logC = (sy - fit.p * sx) / dn;
    fit.c = std::exp(logC);
    double rss = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double e = std::log(fit.forces[i]) - (logC + fit.p * std::log(fit.accelerations[i]));
        rss += e * e;
    }
    const double se = std::sqrt(rss / (dn - 2.0) / (sxx - sx * sx / dn));
    // Two-sided 95 % Student t for n - 2 degrees of freedom (table up to 30, normal beyond).
    static const double t95[] = {12.71, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
                                 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
    const std::size_t dof = n - 2;
    const double t = dof >= 1 && dof <= 30 ? t95[dof - 1] : 1.96;
    fit.pLow = fit.p - t * se;
    fit.pHigh = fit.p + t * se;
    fit.valid = true;
    return fit;
}

} // namespace rosin::lab
