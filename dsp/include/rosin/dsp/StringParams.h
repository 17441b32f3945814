// Physical description of one string. Everything the waveguide needs, in SI units.
#pragma once
#include <cmath>
#include <string>

namespace rosin::dsp {

struct StringParams {
    std::string name = "cello-D";
    double length = 0.69;            ///< vibrating length L (m)
    double tension = 102.6;          ///< T (N)
    double massPerLength = 2.50e-3;  ///< m (kg/m)
    double radius = 0.44e-3;         ///< outer radius (m), for the Hertz contact
    double torsionSpeedRatio = 5.2;  ///< c_t / c
    double torsionImpedanceRatio = 2.0; ///< Z_t / Z_0
    double qLow = 500.0;             ///< transverse Q at f0
    double qHigh = 150.0;            ///< transverse Q at qHighFrequency
    double qHighFrequency = 5000.0;  ///< Hz
    double qTorsion = 30.0;          ///< torsional Q (taken flat in frequency)
    double inharmonicity = 1e-5;     ///< B in f_n = n f0 sqrt(1 + B n^2)

    double waveSpeed() const { return std::sqrt(tension / massPerLength); }
    double impedance() const { return std::sqrt(tension * massPerLength); }
    double fundamental() const { return waveSpeed() / (2.0 * length); }
    double torsionImpedance() const { return torsionImpedanceRatio * impedance(); }

    /// Tunes the string to `f0` as a player does, by its tension: the mass per length that
    /// sounds f0 at this length and tension (so a tension off the maker's figure moves it).
    void tuneTo(double f0) { massPerLength = tension / std::pow(2.0 * length * f0, 2.0); }

    /// The PHYSICS.md 1.6 reference: open cello D string of the Galluzzo rig comparisons.
    /// m is derived so that f0 = 146.83 Hz with L = 0.69 m and T = 102.6 N.
    static StringParams celloD()
    {
        StringParams p;
        p.tuneTo(146.83);
        return p;
    }

    /// Same string stopped so that it sounds at `frequency` (finger shortens L; T and m unchanged).
    StringParams stoppedAt(double frequency) const
    {
        StringParams p = *this;
        p.length = waveSpeed() / (2.0 * frequency);
        return p;
    }

    /// First thing wrong with the values, or empty when they are usable.
    std::string validate() const
    {
        auto bad = [](double x) { return !std::isfinite(x) || x <= 0.0; };
        if (bad(length)) return "length must be a positive number of metres";
        if (bad(tension)) return "tension must be a positive number of newtons";
        if (bad(massPerLength)) return "massPerLength must be a positive number of kg/m";
        if (bad(radius)) return "radius must be a positive number of metres";
        if (bad(torsionSpeedRatio)) return "torsionSpeedRatio must be positive";
        if (bad(torsionImpedanceRatio)) return "torsionImpedanceRatio must be positive";
        if (bad(qLow) || bad(qHigh) || bad(qTorsion)) return "Q values must be positive";
        if (bad(qHighFrequency)) return "qHighFrequency must be positive";
        if (!std::isfinite(inharmonicity) || inharmonicity < 0.0 || inharmonicity > 1e-2)
            return "inharmonicity must be in [0, 0.01]";
        const double f0 = fundamental();
        if (f0 < 20.0 || f0 > 5000.0) return "the string's fundamental must lie in 20-5000 Hz";
        return {};
    }
};

} // namespace rosin::dsp
