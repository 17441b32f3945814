// The reference simulator's friction laws: the temperature law by inverting steady sliding
// (PHYSICS.md 3.5, 4.2) and the contact solve with the stick/slip jump rule (2.2-2.3).
#pragma once
#include <functional>
#include <vector>

#include "rosin/reference/Rig.h"

namespace rosin::reference {

/// Steady temperature rise of the steady-sliding test at speed v (PHYSICS.md 3.3).
double steadyRise(double speed, const Friction& f);

/// mu(theta) (thermal) or y(theta) (enhanced): each table point is found by solving
/// theta_ss(v) = theta for v by bisection, then reading mu_ss(v) (or mu_ss(v) / h(v)).
/// Beyond the first maximum of theta_ss the law is flat (PHYSICS.md 3.5 step 3).
class TemperatureTable {
public:
    void build(const Friction& f, int points = 8192);
    double at(double theta) const; ///< linear between points, clamped at both ends
    double maxRise() const { return thetaMax_; }

private:
    std::vector<double> values_;
    double thetaMax_ = 0.0, step_ = 1.0;
};

enum class ContactState { Stick, SlipForward, SlipBackward };

/// Solves the load line v = vFree + f / (2 Z) against the friction law. `limit(x)` is the
/// largest friction force at sliding speed x >= 0 (falling and convex in x, or flat).
class ContactSolver {
public:
    struct Result {
        double force = 0, velocity = 0;
        bool stick = true;
    };
    void reset() { state_ = ContactState::Stick; }
    /// flat = true when limit does not depend on x (thermal law): one closed-form slip.
    Result solve(double vFree, double bowSpeed, double twoZ, const std::function<double(double)>& limit, bool flat);
    ContactState state() const { return state_; }

private:
    ContactState state_ = ContactState::Stick;
};

} // namespace rosin::reference
