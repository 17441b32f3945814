#include "rosin/lab/Classifier.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "rosin/lab/Error.h"
#include "rosin/lab/Resample.h"

namespace rosin::lab {

const char* regimeName(Regime r)
{
    switch (r) {
    case Regime::Helmholtz: return "Helmholtz";
    case Regime::SMotion: return "SMotion";
    case Regime::DoubleSlip: return "DoubleSlip";
    case Regime::DoubleFlyback: return "DoubleFlyback";
    case Regime::Irregular: return "Irregular";
    case Regime::NoSlip: return "NoSlip";
    }
    return "?";
}

bool isSuccess(Regime r) { return r == Regime::Helmholtz || r == Regime::SMotion; }

namespace {

/// Solves the augmented normal equations [A^T A | A^T y] (m rows, m + 1 columns) by Gaussian elimination.
std::vector<double> solveNormal(std::vector<std::vector<double>> a)
{
    const std::size_t m = a.size();
    for (std::size_t i = 0; i < m; ++i) {
        std::size_t pivot = i;
        for (std::size_t r = i + 1; r < m; ++r)
            if (std::abs(a[r][i]) > std::abs(a[pivot][i])) pivot = r;
        std::swap(a[i], a[pivot]);
        if (std::abs(a[i][i]) < 1e-300) continue;
        for (std::size_t r = 0; r < m; ++r) {
            if (r == i) continue;
            const double f = a[r][i] / a[i][i];
            for (std::size_t c = i; c <= m; ++c) a[r][c] -= f * a[i][c];
        }
    }
    std::vector<double> c(m, 0.0);
    for (std::size_t i = 0; i < m; ++i) c[i] = std::abs(a[i][i]) < 1e-300 ? 0.0 : a[i][m] / a[i][i];
    return c;
}

double dot(const std::vector<double>& x, const std::vector<double>& y, std::size_t n)
{
    double s = 0.0;
    for (std::size_t k = 0; k < n; ++k) s += x[k] * y[k];
    return s;
}

/// Least squares of y on the columns cols, where the products among the columns that do not
/// change from call to call (all but `varying`, which may be cols.size() for none) are given
/// in `fixed` (m x m, entries touching `varying` ignored): the trigger search refits the same
/// DC and hum columns against a ramp that moves with each trial start.
std::vector<double> leastSquares(const std::vector<std::vector<double>>& cols, const std::vector<double>& y,
                                 const std::vector<std::vector<double>>& fixed, std::size_t varying)
{
    const std::size_t m = cols.size();
    std::vector<std::vector<double>> a(m, std::vector<double>(m + 1, 0.0));
    for (std::size_t i = 0; i < m; ++i) {
        for (std::size_t j = 0; j < m; ++j) a[i][j] = (i == varying || j == varying) ? dot(cols[i], cols[j], y.size()) : fixed[i][j];
        a[i][m] = dot(cols[i], y, y.size());
    }
    return solveNormal(std::move(a));
}

/// The products of every pair of columns over the first n samples.
std::vector<std::vector<double>> gram(const std::vector<std::vector<double>>& cols, std::size_t n)
{
    std::vector<std::vector<double>> g(cols.size(), std::vector<double>(cols.size(), 0.0));
    for (std::size_t i = 0; i < cols.size(); ++i)
        for (std::size_t j = 0; j < cols.size(); ++j) g[i][j] = dot(cols[i], cols[j], n);
    return g;
}

/// First sample where the signal falls by more than 5 % of its level (above `base`) within
/// `window` samples, and by more than `floor` in absolute terms. -1 if none.
int firstRelativeDrop(const std::vector<double>& f, double base, int window, double floor, int from = 0)
{
    const int n = static_cast<int>(f.size());
    for (int i = std::max(from, 1); i + window < n; ++i) {
        const double level = f[i] - base;
        if (level <= floor) continue;
        double lowest = f[i];
        for (int j = 1; j <= window; ++j) lowest = std::min(lowest, f[i + j]);
        if (f[i] - lowest > std::max(0.05 * level, floor)) {
            // The slip starts at the steepest fall inside the window: the first sample after it.
            int at = i;
            for (int j = i; j < i + window; ++j)
                if (f[j] - f[j + 1] > f[at] - f[at + 1]) at = j;
            return at + 1;
        }
    }
    return -1;
}

/// Bow displacement x_b(t) = integral of v_b from the gesture start, sampled on the record.
std::vector<double> bowDisplacement(const std::function<double(double)>& speed, double fs, int n, double t0)
{
    std::vector<double> x(static_cast<std::size_t>(n), 0.0);
    double acc = 0.0;
    for (int i = 0; i < n; ++i) {
        const double t = i / fs - t0;
        if (t > 0) acc += speed(t) / fs;
        x[i] = acc;
    }
    return x;
}

struct RampFit {
    double gain = 1, dc = 0, trigger = 0, hum = 0;
    std::vector<double> humWave;
};

/// Recording clean-up: fits DC + gain * (quasi-static bridge force of the gesture started at
/// t0) + mains hum (50 or 60 Hz and three harmonics) to the pre-slip ramp. The quasi-static
/// bridge force is T x_b / (beta L) (PHYSICS.md 6.4); its fitted factor is the gain.
RampFit calibrate(const std::vector<double>& f, const ClassifierInput& in, int roughSlip)
{
    RampFit best;
    const double fs = in.sampleRate;
    const int n = static_cast<int>(f.size());
    int end = std::max(16, roughSlip - static_cast<int>(0.2e-3 * fs));
    // Only the quasi-static part of the ramp: with thermal friction the contact creeps well
    // before the first abrupt drop, so stop where the force passes 60 % of its pre-slip peak.
    {
        const double base = f.front();
        double peak = 0.0;
        for (int i = 0; i < end; ++i) peak = std::max(peak, f[i] - base);
        for (int i = 0; i < end; ++i)
            if (f[i] - base > 0.6 * peak) {
                end = std::max(16, i);
                break;
            }
    }
    double bestResidual = 1e300;
    const double stiffness = in.tension / (in.beta * in.length);
    // Hum is taken out only where the recording shows it: each candidate (none, 50, 60 Hz)
    // pays for its parameters (BIC), so a clean ramp is not bent by a fitted hum and a DC.
    std::vector<double> hums{0.0, 50.0, 60.0};
    if (in.hum >= 0.0) hums = {in.hum};
    // A hum is fitted only over at least one of its periods: over a shorter window its sines
    // and their harmonics stand in for the ramp and come out huge and cancelling, and taking
    // them out of the whole record writes a false 50 Hz wave into it.
    std::erase_if(hums, [&](double hum) { return hum > 0.0 && end < fs / hum; });
    if (hums.empty()) hums = {0.0};
    std::vector<double> bestCoefficients;
    int bestHarmonics = 0;
    for (double hum : hums) {
        const int harmonics = hum > 0.0 ? 4 : 0;
        // Column 1 is the ramp, which moves with the trial start; the DC and the hum's sines
        // do not, nor do their products with each other.
        std::vector<std::vector<double>> cols(2 + 2 * harmonics, std::vector<double>(static_cast<std::size_t>(end)));
        for (int i = 0; i < end; ++i) {
            cols[0][i] = 1.0;
            for (int h = 1; h <= harmonics; ++h) {
                cols[2 * h][i] = std::sin(2 * std::numbers::pi * hum * h * i / fs);
                cols[2 * h + 1][i] = std::cos(2 * std::numbers::pi * hum * h * i / fs);
            }
        }
        const std::vector<std::vector<double>> fixedAll = gram(cols, static_cast<std::size_t>(end));
        // With the gain known the ramp is subtracted and only these fixed columns are fitted.
        std::vector<std::vector<double>> rest(cols), fixedRest = fixedAll; // without the ramp's row and column
        rest.erase(rest.begin() + 1);
        fixedRest.erase(fixedRest.begin() + 1);
        for (auto& row : fixedRest) row.erase(row.begin() + 1);
        // Trigger search: coarse grid over the pre-slip time, then refined around the best.
        double lo = 0.0, hi = end / fs, bestT0 = 0.0;
        for (int pass = 0; pass < 3; ++pass) {
            const int steps = 40;
            double passBest = 1e300, passT0 = lo;
            for (int s = 0; s <= steps; ++s) {
                const double t0 = lo + (hi - lo) * s / steps;
                const auto xb = bowDisplacement(in.bowSpeed, fs, end, t0);
                for (int i = 0; i < end; ++i)
                    cols[1][i] = in.rampShape ? (i / fs > t0 ? in.rampShape(i / fs - t0) : 0.0) : stiffness * xb[i];
                std::vector<double> y(f.begin(), f.begin() + end);
                std::vector<double> c;
                if (in.knownGain > 0.0 && !in.rampShape) {
                    // Gain known: subtract the ramp, fit only DC and hum.
                    for (int i = 0; i < end; ++i) y[i] -= in.knownGain * cols[1][i];
                    c = leastSquares(rest, y, fixedRest, rest.size());
                    c.insert(c.begin() + 1, in.knownGain);
                    for (int i = 0; i < end; ++i) y[i] += in.knownGain * cols[1][i];
                } else {
                    c = leastSquares(cols, y, fixedAll, 1);
                }
                double r = 0.0;
                for (int i = 0; i < end; ++i) {
                    double model = 0.0;
                    for (std::size_t k = 0; k < cols.size(); ++k) model += c[k] * cols[k][i];
                    r += (y[i] - model) * (y[i] - model);
                }
                const double bic = end * std::log(std::max(r, 1e-300) / end) + static_cast<double>(cols.size()) * std::log(static_cast<double>(end));
                if (r < passBest) { passBest = r; passT0 = t0; }
                if (bic < bestResidual && c[1] > 0.0) {
                    bestResidual = bic;
                    // A shape's factor is not the gain: the gain is the known one, or stays 1.
                    best.gain = in.rampShape ? (in.knownGain > 0.0 ? in.knownGain : 1.0) : c[1];
                    best.dc = c[0];
                    best.trigger = t0;
                    best.hum = hum;
                    bestCoefficients = c;
                    bestHarmonics = harmonics;
                }
            }
            bestT0 = passT0;
            const double span = (hi - lo) / steps;
            lo = std::max(0.0, bestT0 - span);
            hi = bestT0 + span;
        }
    }
    // The hum over the whole record, once, from the best fit's coefficients.
    if (!bestCoefficients.empty()) {
        best.humWave.assign(static_cast<std::size_t>(n), 0.0);
        for (int i = 0; i < n; ++i)
            for (int h = 1; h <= bestHarmonics; ++h)
                best.humWave[i] += bestCoefficients[2 * h] * std::sin(2 * std::numbers::pi * best.hum * h * i / fs)
                                   + bestCoefficients[2 * h + 1] * std::cos(2 * std::numbers::pi * best.hum * h * i / fs);
    }
    // The sensor's offset is what it reads while the string rests before the gesture. Where the
    // recording holds a millisecond of that rest, the offset comes from it, and the ramp's gain is
    // refitted with it fixed: the ramp's intercept alone took a false DC out of clean data
    // (the quasi-static ramp is not the string's exact start).
    const int rest = static_cast<int>(best.trigger * fs) - static_cast<int>(0.2e-3 * fs);
    if (!best.humWave.empty() && rest >= static_cast<int>(1e-3 * fs)) {
        std::vector<double> still(static_cast<std::size_t>(rest));
        for (int i = 0; i < rest; ++i) still[static_cast<std::size_t>(i)] = f[static_cast<std::size_t>(i)] - best.humWave[static_cast<std::size_t>(i)];
        std::nth_element(still.begin(), still.begin() + rest / 2, still.end());
        best.dc = still[static_cast<std::size_t>(rest / 2)];
        if (in.knownGain <= 0.0 && !in.rampShape) {
            const auto xb = bowDisplacement(in.bowSpeed, fs, end, best.trigger);
            double num = 0.0, den = 0.0;
            for (int i = 0; i < end; ++i) {
                const double ramp = stiffness * xb[static_cast<std::size_t>(i)];
                num += ramp * (f[static_cast<std::size_t>(i)] - best.dc - best.humWave[static_cast<std::size_t>(i)]);
                den += ramp * ramp;
            }
            if (den > 0.0 && num > 0.0) best.gain = num / den;
        }
    }
    return best;
}

} // namespace

ClassifierInput guettlerStrokeInput(std::vector<double> signal, double sampleRate, double f0, double beta, double z0,
                                    double tension, double length, double accel)
{
    ClassifierInput in;
    in.bridgeForce = std::move(signal);
    in.sampleRate = sampleRate;
    in.f0 = f0;
    in.beta = beta;
    in.z0 = z0;
    in.tension = tension;
    in.length = length;
    in.bowSpeed = [accel](double t) { return accel * t; };
    return in;
}

Calibration calibrateRecording(const ClassifierInput& in)
{
    if (!(in.sampleRate > 0 && in.beta > 0 && in.tension > 0 && in.length > 0) || !in.bowSpeed)
        throw LabError("calibration: sample rate, beta, tension, length and the bow speed are all needed");
    const double fs = in.sampleRate;
    std::vector<double> f = in.bridgeForce;
    const int n = static_cast<int>(f.size());
    if (n < 16) throw LabError("calibration: the signal is too short");
    for (double x : f)
        if (!std::isfinite(x)) throw LabError("calibration: the signal contains NaN or infinite samples");
    const int window01 = slipDropWindow(fs);
    zeroPhaseLowPass(f, std::min(10000.0, 0.4 * fs), fs);
    // Noise floor from sample-to-sample differences.
    std::vector<double> d;
    for (int i = 1; i < n; ++i) d.push_back(f[i] - f[i - 1]);
    const double noise = robustSigma(std::move(d));
    std::vector<double> head(f.begin(), f.begin() + std::min(n, static_cast<int>(2e-3 * fs) + 1));
    std::nth_element(head.begin(), head.begin() + head.size() / 2, head.end());
    Calibration out;
    const int rough = firstRelativeDrop(f, head[head.size() / 2], window01, 8.0 * noise);
    if (rough < 0) {
        out.dc = head[head.size() / 2];
        out.force.resize(f.size());
        for (int i = 0; i < n; ++i) out.force[i] = f[i] - out.dc;
        return out;
    }
    const RampFit fit = calibrate(f, in, rough);
    if (fit.humWave.empty()) {
        // No ramp with a positive gain fits before the first drop (it came too early): keep
        // the signal's own scale, take out only its starting level, and say so.
        out.dc = head[head.size() / 2];
        out.force.resize(f.size());
        for (int i = 0; i < n; ++i) out.force[i] = f[i] - out.dc;
        out.firstSlip = rough;
        out.rampFitted = false;
        return out;
    }
    out.rampFitted = true;
    out.gain = fit.gain;
    out.dc = fit.dc;
    out.trigger = fit.trigger;
    out.hum = fit.hum;
    out.force.resize(f.size());
    for (int i = 0; i < n; ++i) out.force[i] = (f[i] - fit.dc - fit.humWave[i]) / fit.gain;
    out.firstSlip = firstRelativeDrop(out.force, 0.0, window01, 8.0 * noise / fit.gain, std::max(1, rough - window01 * 10));
    return out;
}

Classification classify(const ClassifierInput& in, const ClassifierSettings& st)
{
    if (!(in.sampleRate > 0 && in.f0 > 0 && in.beta > 0 && in.z0 > 0) || !in.bowSpeed)
        throw LabError("classifier: sample rate, f0, beta, Z0 and the bow speed are all needed");
    Classification out;
    const double fs = in.sampleRate, P0 = 1.0 / in.f0, beta = in.beta;
    std::vector<double> f = in.bridgeForce;
    const int n = static_cast<int>(f.size());
    if (n < 16) throw LabError("classifier: the signal is too short");
    for (double x : f)
        if (!std::isfinite(x)) throw LabError("classifier: the signal contains NaN or infinite samples");
    const int window01 = slipDropWindow(fs);

    int slip = -1;
    if (in.measured) {
        const Calibration cal = calibrateRecording(in);
        if (cal.firstSlip < 0) {
            out.regime = Regime::NoSlip;
            return out;
        }
        out.gain = cal.gain;
        out.triggerTime = cal.trigger;
        out.humFrequency = cal.hum;
        f = cal.force;
        slip = cal.firstSlip;
    } else if (!in.stick.empty()) {
        for (int i = 0; i < n && i < static_cast<int>(in.stick.size()); ++i)
            if (!in.stick[i]) { slip = i; break; }
    } else {
        int from = 0;
        while (from < n && f[from] < st.minSlipForce) ++from;
        slip = from < n ? firstRelativeDrop(f, 0.0, window01, st.slipFloor, from) : -1;
    }
    if (slip < 1) {
        out.regime = Regime::NoSlip;
        return out;
    }
    const double t0 = out.triggerTime;
    auto vb = [&](int i) { return in.bowSpeed(i / fs - t0); };
    out.firstSlipTime = slip / fs - t0;
    out.forceBeforeSlip = f[slip - 1];
    {
        double lowest = f[slip];
        for (int j = 0; j <= window01 && slip + j < n; ++j) lowest = std::min(lowest, f[slip + j]);
        out.firstDrop = f[slip - 1] - lowest;
    }

    // Flybacks: drops within W larger than gamma times the ideal Helmholtz flyback at the
    // current bow speed; the sign of the bow speed tells which way the sawtooth runs.
    const int W = std::max(3, static_cast<int>(std::lround(0.15 * beta * P0 * fs)));
    const int merge = std::max(1, static_cast<int>(0.5 * beta * P0 * fs));
    std::vector<int> events;
    {
        int i = std::max(1, slip - W);
        while (i + W < n) {
            const double v = vb(i), s = v >= 0 ? 1.0 : -1.0;
            const double threshold = st.flybackFraction * 2.0 * in.z0 * std::abs(v) / beta;
            double lowest = s * f[i];
            for (int j = 1; j <= W; ++j) lowest = std::min(lowest, s * f[i + j]);
            if (threshold > 0 && s * f[i] - lowest > threshold) {
                // Event at the steepest fall within the window.
                int at = i;
                double steepest = -1e300;
                for (int j = 0; j < W; ++j) {
                    const double fall = s * (f[i + j] - f[i + j + 1]);
                    if (fall > steepest) { steepest = fall; at = i + j; }
                }
                if (!events.empty() && at - events.back() < merge) {
                    // too close to the previous one: the same flyback seen twice
                } else {
                    events.push_back(at);
                }
                i = at + 1;
                continue;
            }
            ++i;
        }
    }
    for (int e : events) out.flybacks.push_back(e / fs - t0);

    // Periods from the first slip. Each window runs from a quarter period before the expected
    // main flyback to three quarters after it, and the next is anchored on this window's first
    // flyback: a second flyback half a period later (double slip) then falls inside, not on a
    // window edge.
    const int maxPeriods = st.capPeriods + st.settledRun;
    double period = P0 * fs;
    double anchor = slip;
    std::size_t next = 0;
    int previousEvent = -1;
    std::string labels;
    std::vector<std::pair<int, int>> hSpans; // flyback pairs of H periods, for S-motion
    while (static_cast<int>(labels.size()) < maxPeriods && anchor + 0.75 * period <= n) {
        const double start = anchor - 0.25 * period, end = anchor + 0.75 * period;
        std::vector<int> inside;
        while (next < events.size() && events[next] < end) {
            if (events[next] >= start) inside.push_back(events[next]);
            ++next;
        }
        char label = 'X';
        if (inside.size() == 1) {
            const bool first = previousEvent < 0;
            const double spacing = first ? P0 * fs : inside[0] - previousEvent;
            if (std::abs(spacing / (P0 * fs) - 1.0) <= st.periodTolerance) {
                label = 'H';
                if (!first) {
                    hSpans.emplace_back(previousEvent, inside[0]);
                    period = spacing; // running period
                }
            }
        } else if (inside.size() == 2) {
            const double d = inside[1] - inside[0];
            if (d < 2.0 * beta * P0 * fs) label = 'F';
            else if (std::abs(d / (P0 * fs) - 0.5) < 0.25) label = 'S';
        }
        labels.push_back(label);
        if (!inside.empty()) {
            previousEvent = inside.back();
            anchor = inside.front() + period;
        } else {
            anchor += period;
        }
    }
    out.labels = labels;

    // S-motion: strong ripple on the sticking ramp between two flybacks of an H period.
    for (auto [a, b] : hSpans) {
        const int from = a + 2 * W, to = b - W;
        if (to - from < 8) continue;
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        const int m = to - from;
        for (int i = from; i < to; ++i) { sx += i; sy += f[i]; sxx += double(i) * i; sxy += double(i) * f[i]; }
        const double slope = (m * sxy - sx * sy) / (m * sxx - sx * sx), icpt = (sy - slope * sx) / m;
        double lo = 1e300, hi = -1e300;
        for (int i = from; i < to; ++i) {
            const double r = f[i] - (icpt + slope * i);
            lo = std::min(lo, r);
            hi = std::max(hi, r);
        }
        const double flyback = 2.0 * in.z0 * std::abs(vb(b)) / beta;
        if (hi - lo > st.sMotionRipple * flyback) ++out.sMotionPeriods;
    }

    // Transient length: first period that starts a run of settled H periods lasting to the
    // end of the analysed window.
    const int K = static_cast<int>(labels.size());
    for (int k = 0; k <= std::min(st.capPeriods, K - st.settledRun); ++k) {
        if (labels.find_first_not_of('H', static_cast<std::size_t>(k)) == std::string::npos) {
            out.transientPeriods = k;
            break;
        }
    }
    if (out.transientPeriods >= 0) {
        out.success = true;
        const int settled = K - out.transientPeriods;
        out.regime = out.sMotionPeriods * 2 >= settled ? Regime::SMotion : Regime::Helmholtz;
        return out;
    }
    int counts[3] = {0, 0, 0};
    for (int k = std::min(5, K); k < std::min(st.capPeriods, K); ++k) {
        if (labels[k] == 'S') ++counts[0];
        if (labels[k] == 'F') ++counts[1];
        if (labels[k] == 'X') ++counts[2];
    }
    if (counts[0] >= counts[1] && counts[0] >= counts[2] && counts[0] > 0) out.regime = Regime::DoubleSlip;
    else if (counts[1] >= counts[2] && counts[1] > 0) out.regime = Regime::DoubleFlyback;
    else out.regime = Regime::Irregular;
    return out;
}

} // namespace rosin::lab
