// Heat in the bow-string contact by direct convolution with the exact conduction kernels
// (PHYSICS.md 3.3), not by a bank of poles.
//
// Per unit area, the surface temperature of a half-space is its past flux convolved with
// 1/(e sqrt(pi t)). The string side is stationary. The rod/bow side moves through the
// contact and is renewed at rate kappa(t) = 3|dv|/(8a): T_t = D T_zz - kappa T in the rod,
// whose Green's function is the same kernel times exp(-integral of kappa) since the flux
// entered. Flux is taken constant over each step and the kernel is integrated exactly over
// the step. The layer's storage and the advected heat close the balance, solved implicitly
// for the new temperature each step.
//
// History older than `recentSteps` is kept in pieces that grow with their age (each at most
// 1/recentSteps of it): the kernel is still integrated exactly over each piece, only the flux
// inside a piece is averaged. recentSteps = 0 keeps every step (O(n^2), for the tests).
#pragma once
#include <cstddef>
#include <vector>

namespace rosin::reference {

class ExactConduction {
public:
    struct Side {
        double effusivity = 0.0;
    };

    void prepare(double step, double stringEffusivity, double rodEffusivity, int recentSteps = 64);
    void reset();

    /// One step of length h. heatIn: W/m^2 generated in the layer over the step; storage:
    /// J m^-2 K^-1; advection: W m^-2 K^-1 (heat carried out per kelvin); kappa: 1/s.
    /// Returns the temperature rise at the end of the step.
    double step(double heatIn, double storage, double advection, double kappa);
    double temperature() const { return theta_; }

    /// Flux densities into each side over the last step (W/m^2), for the balance tests.
    double lastStringFlux() const { return lastString_; }
    double lastRodFlux() const { return lastRod_; }

private:
    struct Piece {
        long start, end;       ///< steps: the piece spans [start, end)
        double stringHeat;     ///< integral of flux over the piece (J/m^2)
        double rodHeat;        ///< same, weighted by exp(S(mid) - S_ref)
    };
    double rootOf(long steps); ///< sqrt(steps), tabulated (ages are whole steps)
    void compact();

    double h_ = 0, es_ = 0, er_ = 0, theta_ = 0, renewal_ = 0, renewalRef_ = 0;
    long now_ = 0;
    std::vector<double> roots_;
    double lastString_ = 0, lastRod_ = 0;
    int recent_ = 64;
    bool started_ = false;
    std::vector<std::vector<Piece>> levels_; ///< level l holds pieces of 2^l steps, newest last
};

} // namespace rosin::reference
