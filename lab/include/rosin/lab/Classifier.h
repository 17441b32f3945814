// Transient classifier (PHYSICS.md 6.5): from a bridge-force signal, simulated or measured,
// find the first slip and the flybacks, label each period, and give the transient length and
// the regime. For recordings it first removes what rigs add: DC, mains hum, noise, an unknown
// gain and an unknown trigger time.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace rosin::lab {

enum class Regime { Helmholtz, SMotion, DoubleSlip, DoubleFlyback, Irregular, NoSlip };
const char* regimeName(Regime r);
bool isSuccess(Regime r); ///< Helmholtz or S-motion within the cap

/// Samples in the 0.1 ms a first slip must drop the force within (at least 2).
inline int slipDropWindow(double sampleRate) { return std::max(2, static_cast<int>(std::lround(1e-4 * sampleRate))); }

/// Standard deviation of zero-mean Gaussian values from the median of their magnitudes
/// (1.4826 x median |x|): flybacks and slips, a minority, leave it alone.
inline double robustSigma(std::vector<double> x)
{
    if (x.empty()) return 0.0;
    for (double& v : x) v = std::abs(v);
    const auto mid = x.begin() + static_cast<long>(x.size() / 2);
    std::nth_element(x.begin(), mid, x.end());
    return 1.4826 * *mid;
}

struct ClassifierSettings {
    double flybackFraction = 0.35;  ///< gamma: a flyback drops more than gamma * 2 Z0 vb / beta
    int capPeriods = 25;            ///< transients longer than this are failures [WG25; GW14]
    int settledRun = 5;             ///< H periods in a row that count as settled
    double periodTolerance = 0.10;  ///< H spacing within +-10 % of the period
    double sMotionRipple = 0.30;    ///< ripple / flyback above which an H period is S-motion
    double slipFloor = 1e-9;        ///< a first slip must drop the force by at least this (N)
    double minSlipForce = 0.0;      ///< a first slip comes only after the force has reached this (N)
};

struct ClassifierInput {
    std::vector<double> bridgeForce; ///< N, or any unit when gain is unknown
    double sampleRate = 0;
    double f0 = 0;                   ///< nominal fundamental (Hz)
    double beta = 0;
    double z0 = 0;                   ///< transverse impedance (kg/s)
    double tension = 0, length = 0;  ///< string, for the quasi-static ramp (gain and trigger)
    std::function<double(double)> bowSpeed; ///< v_b(t) from the gesture start (m/s)
    /// Recording mode, gestures that slide from the start (a rising force at constant speed):
    /// the pre-slip bridge force is this shape of time from the gesture start times an unknown
    /// factor, which carries the friction level and so is not the gain. Empty: the string
    /// sticks to the bow and the pre-slip force is T x_b / (beta L) times the gain.
    std::function<double(double)> rampShape;
    std::vector<std::uint8_t> stick; ///< simulation only: ground-truth stick flags
    /// Recording mode: remove DC and hum, low-pass, and estimate gain and trigger time from
    /// the pre-slip ramp. Off for simulations, where the signal is exact and in newtons.
    bool measured = false;
    /// Recording mode: signal units per newton when already known (e.g. one gain for a whole
    /// set); then only trigger, DC and hum are fitted. 0 = unknown, fitted per recording.
    double knownGain = 0.0;
    /// Mains hum to take out of a recording: -1 = decide from this recording (BIC between no
    /// hum, 50 Hz and 60 Hz), 0 = none, 50 or 60 = that frequency and its harmonics.
    double hum = -1.0;
};

/// Input for a constant-acceleration (Guettler) stroke, v_b = accel * t.
ClassifierInput guettlerStrokeInput(std::vector<double> signal, double sampleRate, double f0, double beta, double z0,
                                    double tension, double length, double accel);

struct Classification {
    Regime regime = Regime::NoSlip;
    int transientPeriods = -1;       ///< N_T, -1 for a failure
    bool success = false;
    double firstSlipTime = -1;       ///< s from the gesture start
    double forceBeforeSlip = 0;      ///< bridge force just before the first slip (N after gain)
    double firstDrop = 0;            ///< drop of the bridge force over 0.1 ms at the first slip (N)
    double gain = 1;                 ///< signal units per newton (1 for simulations)
    double triggerTime = 0;          ///< s into the record where the gesture starts
    double humFrequency = 0;         ///< 50 or 60 Hz when hum was removed, else 0
    std::vector<double> flybacks;    ///< s from the gesture start
    std::string labels;              ///< per period from the first slip: H Helmholtz, S double slip, F double flyback, X irregular
    int sMotionPeriods = 0;
};

Classification classify(const ClassifierInput& in, const ClassifierSettings& settings = {});

/// The recording clean-up on its own: low-pass at 10 kHz, then DC, mains hum, gain and trigger
/// fitted to the pre-slip ramp. `force` is the whole record in newtons (same sample times as
/// the input; the gesture starts at `trigger`); `firstSlip` is its index, -1 if none.
struct Calibration {
    std::vector<double> force;
    double gain = 1, dc = 0, trigger = 0, hum = 0;
    int firstSlip = -1;
    bool rampFitted = false; ///< gain and trigger come from a fitted ramp (else gain 1, trigger 0)
};
Calibration calibrateRecording(const ClassifierInput& in);

} // namespace rosin::lab
