// Transient classifier (PHYSICS.md 6.5): from a bridge-force signal, simulated or measured,
// find the first slip and the flybacks, label each period, and give the transient length and
// the regime. For recordings it first removes what rigs add: DC, mains hum, noise, an unknown
// gain and an unknown trigger time.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace rosin::lab {

enum class Regime { Helmholtz, SMotion, DoubleSlip, DoubleFlyback, Irregular, NoSlip };
const char* regimeName(Regime r);
bool isSuccess(Regime r); ///< Helmholtz or S-motion within the cap

enum class PeriodLabel : char { H = 'H', DoubleSlip = 'S', DoubleFlyback = 'F', Irregular = 'X' };

struct ClassifierSettings {
    double flybackFraction = 0.35;  ///< gamma: a flyback drops more than gamma * 2 Z0 vb / beta
    int capPeriods = 25;            ///< transients longer than this are failures [WG25; GW14]
    int settledRun = 5;             ///< H periods in a row that count as settled
    double periodTolerance = 0.10;  ///< H spacing within +-10 % of the period
    double sMotionRipple = 0.30;    ///< ripple / flyback above which an H period is S-motion
};

struct ClassifierInput {
    std::vector<double> bridgeForce; ///< N, or any unit when gain is unknown
    double sampleRate = 0;
    double f0 = 0;                   ///< nominal fundamental (Hz)
    double beta = 0;
    double z0 = 0;                   ///< transverse impedance (kg/s)
    double tension = 0, length = 0;  ///< string, for the quasi-static ramp (gain and trigger)
    std::function<double(double)> bowSpeed; ///< v_b(t) from the gesture start (m/s)
    std::vector<std::uint8_t> stick; ///< simulation only: ground-truth stick flags
    /// Recording mode: remove DC and hum, low-pass, and estimate gain and trigger time from
    /// the pre-slip ramp. Off for simulations, where the signal is exact and in newtons.
    bool measured = false;
};

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
    std::string labels;              ///< one character per period from the first slip
    int sMotionPeriods = 0;
};

Classification classify(const ClassifierInput& in, const ClassifierSettings& settings = {});

} // namespace rosin::lab
