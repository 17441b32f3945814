// The reference simulator: a bowed stiff string solved by finite differences, slow and
// accurate, independent of dsp/ (which solves a waveguide). Used to make data that the
// diagnosis must explain without the data living inside the diagnosis's own model space.
//
// Transverse displacement u(x, t), bridge at x = 0, nut at x = L (PHYSICS.md 1):
//   m u_tt = T u_xx - EI u_xxxx - 2 m sigma0 u_t + 2 m sigma1 u_txx + f delta(x - beta L)
// Tension explicit; stiffness and the frequency-dependent loss averaged over t(n+1), t(n-1),
// so the only stability limit is the Courant number c k / h <= 1 (taken as close to 1 as an
// integer number of cells allows: no numerical dispersion of the wave part at 1). Both ends
// are simply supported; the bridge end moves with the bridge's modes, driven by the string's
// end force T u_x - EI u_xxx. Torsion: the surface displacement obeys its own lossy wave
// equation with Z_t and c_t, and the bow drags the sum of both surface velocities.
// The bow force is spread linearly over the two grid points around the bow.
#pragma once
#include <vector>

#include "rosin/reference/Conduction.h"
#include "rosin/reference/Friction.h"
#include "rosin/reference/Rig.h"

namespace rosin::reference {

struct Sample {
    double bridgeForce = 0;   ///< N, force of the string on the bridge
    double farEndForce = 0;   ///< N, force of the string on the nut
    double velocity = 0;      ///< m/s, surface velocity at the bow (transverse + torsional)
    double friction = 0;      ///< N, bow on string
    double temperature = 0;   ///< K above ambient
    bool stick = true;
};

/// Numbers that say how the grid came out (for reports and tests).
struct GridInfo {
    int cells = 0, torsionCells = 0;
    double courant = 0, torsionCourant = 0;
    double sigma0 = 0, sigma1 = 0;             ///< transverse loss terms (1/s, m^2/s)
    double loadLineImpedance = 0;             ///< Z seen by the bow in one step (kg/s), ~ Z_eff
};

class Simulator {
public:
    /// Throws std::invalid_argument when the rig or the rate is unusable.
    Simulator(const Rig& rig, double beta, double sampleRate, int conductionRecentSteps = 64);

    void reset();
    /// One step with bow force (N) and bow speed (m/s).
    Sample step(double force, double bowSpeed);

    double sampleRate() const { return fs_; }
    const GridInfo& grid() const { return info_; }

private:
    struct Line { // one lossy 1-D wave equation on N cells with its implicit band matrix
        int cells = 0;
        double h = 0, lambda2 = 0, mu2 = 0, s0 = 0, s1 = 0, mass = 0; // mu2 = (kappa k / h^2)^2
        std::vector<double> now, prev, next, rhs;     // interior nodes 1..N-1 stored at 0..N-2
        std::vector<double> d0, d1, d2;               // LDL^T of the band matrix (diag, 1st, 2nd)
        std::vector<double> response;                 // A^-1 w for the bow weights
        std::size_t first = 2, last = 2;              // where the response is above rounding
        bool diagonal = false;                        // no stiffness, no sigma1: nothing to solve
        int bowNode = 1;
        double bowWeight = 1; // weight of bowNode; 1 - it on bowNode + 1
        void setUp(int n, double length, double waveSpeed, double k, double kappa2, double sigma0, double sigma1, double massPerLength, double beta);
        void factor();
        void solve(std::vector<double>& x) const;
        double bowValue(const std::vector<double>& u) const;
        /// next = the step without the bow's force (ends at bNow, bPrev, bNext in time).
        void freeStep(double bNow, double bPrev, double bNext);
    };

    Rig rig_;
    double fs_, k_, beta_;
    GridInfo info_;
    Line string_, torsion_;
    bool torsionOn_ = false;
    double ei_ = 0, tension_ = 0;
    struct Mode {
        double m, r, s, now = 0, prev = 0;
    };
    std::vector<Mode> bridge_;
    double bridgeNow_ = 0, bridgePrev_ = 0;
    TemperatureTable table_;
    ContactSolver contact_;
    ExactConduction heat_;
    double heatPrev_ = 0, slidePrev_ = 0, forcePrev_ = 0;
    double twoZ_ = 0;
};

} // namespace rosin::reference
