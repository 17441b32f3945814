#include "rosin/reference/Simulator.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rosin::reference {

namespace {
constexpr double kPi = std::numbers::pi;

/// Cells for a line of Courant limit `most` cells: the bow's one-step admittance depends on
/// where it falls between two nodes (split evenly, it halves), so take the count within 10 %
/// below the limit that puts the bow closest to a node (Courant number 0.9-1).
int alignedCells(int most, double beta)
{
    int best = most;
    double bestOff = 1.0;
    for (int n = most; n >= std::max(8, most - most / 10); --n) {
        const double off = std::abs(beta * n - std::round(beta * n));
        if (off < bestOff - 1e-12) { best = n; bestOff = off; }
    }
    return best;
}

/// Squared wavenumber of a stiff string's travelling wave at angular frequency w:
/// w^2 = c^2 xi + kappa^2 xi^2.
double wavenumber2(double w, double c, double kappa2)
{
    if (kappa2 <= 0.0) return w * w / (c * c);
    return (-c * c + std::sqrt(c * c * c * c + 4.0 * kappa2 * w * w)) / (2.0 * kappa2);
}

/// sigma0, sigma1 such that a wave decays at sigma0 + sigma1 xi with Q(w) = w / (2 sigma(w))
/// equal to q1 at w1 and q2 at w2 (both kept >= 0: a Q that rises with frequency is flattened).
std::pair<double, double> lossTerms(double w1, double q1, double w2, double q2, double c, double kappa2)
{
    const double s1 = w1 / (2.0 * q1), s2 = w2 / (2.0 * q2);
    const double x1 = wavenumber2(w1, c, kappa2), x2 = wavenumber2(w2, c, kappa2);
    double b = (s2 - s1) / (x2 - x1);
    b = std::max(0.0, b);
    const double a = std::max(0.0, s1 - b * x1);
    return {a, b};
}
} // namespace

std::string Rig::validate() const
{
    auto bad = [](double x) { return !std::isfinite(x) || x <= 0.0; };
    const StringModel& s = string;
    if (bad(s.length) || bad(s.tension) || bad(s.massPerLength)) return "string: length, tension and mass per length must be positive";
    if (!std::isfinite(s.inharmonicity) || s.inharmonicity < 0.0 || s.inharmonicity > 0.05) return "string: inharmonicity must be in [0, 0.05]";
    if (s.losses && (bad(s.qLow) || bad(s.qHigh) || bad(s.fHigh))) return "string: Q values must be positive";
    if (s.torsion && (bad(s.torsionSpeedRatio) || bad(s.torsionImpedanceRatio) || bad(s.qTorsion))) return "string: torsion constants must be positive";
    for (const auto& m : bridge)
        if (bad(m.frequency) || bad(m.q) || bad(m.peakAdmittance)) return "bridge: every mode needs a positive frequency, Q and admittance";
    const Friction& f = friction;
    if (bad(f.footprintRatio) || bad(f.loadExponent) || !std::isfinite(f.temperatureShiftK)) return "friction: r_A and the load exponent must be positive";
    if (bad(f.steady.level)) return "friction: steady-sliding level must be positive";
    const ContactConstants& k = f.contact;
    if (bad(k.radiusAtReference) || bad(k.referenceLoad) || bad(k.layerThickness) || bad(k.rosinVolumetricHeat) ||
        bad(k.stringEffusivity) || bad(k.rodEffusivity) || bad(k.advectionWidthFactor))
        return "contact: every thermal constant must be positive";
    if (f.law == FrictionLaw::Enhanced && (bad(f.speed.h0) || bad(f.speed.v0) || !(f.speed.p >= 0.0)))
        return "friction: the speed function needs h0 > 0, v0 > 0, p >= 0";
    return {};
}

double StringModel::waveSpeed() const { return std::sqrt(tension / massPerLength); }
double StringModel::impedance() const { return std::sqrt(tension * massPerLength); }
double StringModel::flexuralRigidity() const { return inharmonicity * tension * length * length / (kPi * kPi); }

void Simulator::Line::setUp(int n, double length, double waveSpeed, double k, double kappa2, double sigma0, double sigma1,
                            double massPerLength, double beta)
{
    cells = n;
    h = length / n;
    lambda2 = std::pow(waveSpeed * k / h, 2.0);
    mu2 = kappa2 * k * k / (h * h * h * h);
    s0 = sigma0 * k;
    s1 = sigma1 * k / (h * h);
    mass = massPerLength;
    now.assign(static_cast<std::size_t>(n + 3), 0.0);
    prev = next = rhs = now;
    const double p = std::clamp(beta * n, 1.0, n - 1.0);
    bowNode = std::min(static_cast<int>(std::floor(p)), n - 2);
    bowWeight = 1.0 - (p - bowNode);
    factor();
    std::vector<double> w(static_cast<std::size_t>(n + 3), 0.0);
    w[static_cast<std::size_t>(bowNode + 1)] = bowWeight;
    w[static_cast<std::size_t>(bowNode + 2)] = 1.0 - bowWeight;
    solve(w);
    response = w;
    // The response falls off fast away from the bow (stiffness and loss spread it over a few
    // cells): the force is applied only where it is above rounding.
    double peak = 0.0;
    for (double x : response) peak = std::max(peak, std::abs(x));
    first = 2;
    last = static_cast<std::size_t>(n);
    while (first < last && std::abs(response[first]) < 1e-17 * peak) ++first;
    while (last > first && std::abs(response[last]) < 1e-17 * peak) --last;
}

void Simulator::Line::factor()
{
    // (1 + s0) I + (mu2/2) D4 - s1 D2 on the interior nodes 1..N-1; the simply supported ends'
    // ghost points turn D4's first and last diagonal entries from 6 into 5.
    const int m = cells - 1;
    d0.assign(static_cast<std::size_t>(m), 0.0);
    d1 = d2 = d0;
    const double off1 = -s1 - 2.0 * mu2, off2 = 0.5 * mu2;
    std::vector<double> dd(static_cast<std::size_t>(m)), l1(static_cast<std::size_t>(m), 0.0), l2(static_cast<std::size_t>(m), 0.0);
    for (int i = 0; i < m; ++i) {
        const double a = 1.0 + s0 + 2.0 * s1 + 0.5 * mu2 * ((i == 0 || i == m - 1) ? 5.0 : 6.0);
        double x2 = 0.0, x1 = 0.0;
        if (i >= 2) x2 = off2 / dd[static_cast<std::size_t>(i - 2)];
        if (i >= 1) x1 = (off1 - (i >= 2 ? x2 * l1[static_cast<std::size_t>(i - 1)] * dd[static_cast<std::size_t>(i - 2)] : 0.0)) / dd[static_cast<std::size_t>(i - 1)];
        l1[static_cast<std::size_t>(i)] = x1;
        l2[static_cast<std::size_t>(i)] = x2;
        dd[static_cast<std::size_t>(i)] = a - x1 * x1 * (i >= 1 ? dd[static_cast<std::size_t>(i - 1)] : 0.0) -
                                          x2 * x2 * (i >= 2 ? dd[static_cast<std::size_t>(i - 2)] : 0.0);
    }
    diagonal = s1 == 0.0 && mu2 == 0.0;
    for (int i = 0; i < m; ++i) {
        d0[static_cast<std::size_t>(i)] = 1.0 / dd[static_cast<std::size_t>(i)];
        d1[static_cast<std::size_t>(i)] = l1[static_cast<std::size_t>(i)];
        d2[static_cast<std::size_t>(i)] = l2[static_cast<std::size_t>(i)];
    }
}

void Simulator::Line::solve(std::vector<double>& x) const
{
    // x holds the right-hand side at padded indices 2..N (nodes 1..N-1); solved in place.
    // A hand-written band LDL^T: a generic sparse solver costs several times more per step here.
    const int m = cells - 1;
    double* __restrict y = x.data() + 2;
    const double* __restrict l1 = d1.data();
    const double* __restrict l2 = d2.data();
    const double* __restrict inv = d0.data();
    if (diagonal) {
        for (int i = 0; i < m; ++i) y[i] *= inv[i];
        return;
    }
    y[1] -= l1[1] * y[0];
    for (int i = 2; i < m; ++i) y[i] -= l1[i] * y[i - 1] + l2[i] * y[i - 2];
    for (int i = 0; i < m; ++i) y[i] *= inv[i];
    y[m - 2] -= l1[m - 1] * y[m - 1];
    for (int i = m - 3; i >= 0; --i) y[i] -= l1[i + 1] * y[i + 1] + l2[i + 2] * y[i + 2];
}

double Simulator::Line::bowValue(const std::vector<double>& u) const
{
    return bowWeight * u[static_cast<std::size_t>(bowNode + 1)] + (1.0 - bowWeight) * u[static_cast<std::size_t>(bowNode + 2)];
}

void Simulator::Line::freeStep(double bNow, double bPrev, double bNext)
{
    const int n = cells;
    auto setGhosts = [n](std::vector<double>& u, double b) {
        u[1] = b;                                       // node 0
        u[0] = 2.0 * b - u[2];                          // node -1: zero curvature at the end
        u[static_cast<std::size_t>(n + 1)] = 0.0;       // node N
        u[static_cast<std::size_t>(n + 2)] = -u[static_cast<std::size_t>(n)]; // node N+1
    };
    setGhosts(now, bNow);
    setGhosts(prev, bPrev);
    const double* __restrict u1 = now.data() + 1; // u1[l] = node l
    const double* __restrict u0 = prev.data() + 1;
    double* __restrict r = rhs.data() + 1;
    for (int l = 1; l < n; ++l) {
        const double d2now = u1[l + 1] - 2.0 * u1[l] + u1[l - 1];
        const double d2prev = u0[l + 1] - 2.0 * u0[l] + u0[l - 1];
        const double d4prev = u0[l + 2] - 4.0 * u0[l + 1] + 6.0 * u0[l] - 4.0 * u0[l - 1] + u0[l - 2];
        r[l] = 2.0 * u1[l] + lambda2 * d2now - (1.0 - s0) * u0[l] - 0.5 * mu2 * d4prev - s1 * d2prev;
    }
    // The new boundary value enters the implicit operator's first two rows.
    r[1] += (mu2 + s1) * bNext;
    if (n > 2) r[2] -= 0.5 * mu2 * bNext;
    solve(rhs);
    next.swap(rhs);
    next[1] = bNext;
    next[static_cast<std::size_t>(n + 1)] = 0.0;
}

Simulator::Simulator(const Rig& rig, double beta, double sampleRate, int conductionRecentSteps)
    : rig_(rig), fs_(sampleRate), k_(1.0 / sampleRate), beta_(beta)
{
    if (const std::string why = rig.validate(); !why.empty()) throw std::invalid_argument("reference rig: " + why);
    if (!(sampleRate >= 8000.0 && sampleRate <= 1e7)) throw std::invalid_argument("reference: sample rate must be within 8 kHz..10 MHz");
    if (!(beta > 0.0 && beta < 0.5)) throw std::invalid_argument("reference: beta must be within (0, 0.5)");
    const StringModel& s = rig.string;
    const double c = s.waveSpeed(), ei = s.flexuralRigidity(), kappa2 = ei / s.massPerLength;
    tension_ = s.tension;
    ei_ = ei;
    const int cells = alignedCells(static_cast<int>(std::floor(s.length / (c * k_) + 1e-9)), beta);
    if (cells < 8) throw std::invalid_argument("reference: the sample rate gives fewer than 8 cells along the string");
    double sigma0 = 0, sigma1 = 0;
    if (s.losses) {
        const double w1 = 2.0 * kPi * c / (2.0 * s.length) * std::sqrt(1.0 + s.inharmonicity);
        std::tie(sigma0, sigma1) = lossTerms(w1, s.qLow, 2.0 * kPi * s.fHigh, s.qHigh, c, kappa2);
    }
    string_.setUp(cells, s.length, c, k_, kappa2, sigma0, sigma1, s.massPerLength, beta);
    info_.cells = cells;
    info_.courant = c * k_ / string_.h;
    info_.sigma0 = sigma0;
    info_.sigma1 = sigma1;
    double admittance = k_ / (2.0 * s.massPerLength * string_.h) * string_.bowValue(string_.response);
    torsionOn_ = s.torsion;
    if (torsionOn_) {
        const double ct = s.torsionSpeedRatio * c, zt = s.torsionImpedanceRatio * s.impedance(), mt = zt / ct;
        const int tc = alignedCells(static_cast<int>(std::floor(s.length / (ct * k_) + 1e-9)), beta);
        if (tc < 4) throw std::invalid_argument("reference: the sample rate gives fewer than 4 torsional cells");
        const double w1 = 2.0 * kPi * ct / (2.0 * s.length);
        // Torsional Q is about flat in frequency: matched at the first and fourth mode.
        const auto [t0, t1] = lossTerms(w1, s.qTorsion, 4.0 * w1, s.qTorsion, ct, 0.0);
        torsion_.setUp(tc, s.length, ct, k_, 0.0, t0, t1, mt, beta);
        info_.torsionCells = tc;
        info_.torsionCourant = ct * k_ / torsion_.h;
        admittance += k_ / (2.0 * mt * torsion_.h) * torsion_.bowValue(torsion_.response);
    }
    twoZ_ = 1.0 / admittance;
    info_.loadLineImpedance = 0.5 * twoZ_;
    for (const auto& m : rig.bridge) {
        const double w = 2.0 * kPi * m.frequency, r = 1.0 / m.peakAdmittance, mass = m.q * r / w;
        bridge_.push_back({mass, r, mass * w * w});
    }
    if (rig.friction.law != FrictionLaw::Curve) table_.build(rig.friction);
    heat_.prepare(k_, rig.friction.contact.stringEffusivity, rig.friction.contact.rodEffusivity, conductionRecentSteps);
    reset();
}

void Simulator::reset()
{
    for (Line* l : {&string_, &torsion_}) {
        std::fill(l->now.begin(), l->now.end(), 0.0);
        std::fill(l->prev.begin(), l->prev.end(), 0.0);
        std::fill(l->next.begin(), l->next.end(), 0.0);
    }
    for (auto& m : bridge_) m.now = m.prev = 0.0;
    bridgeNow_ = bridgePrev_ = 0.0;
    contact_.reset();
    heat_.reset();
    heatPrev_ = slidePrev_ = forcePrev_ = 0.0;
}

Sample Simulator::step(double force, double bowSpeed)
{
    Sample out;
    const Friction& fr = rig_.friction;
    const double h = string_.h;
    const std::vector<double>& u = string_.now; // padded: node l at l + 1
    // Forces of the string on its ends (T u_x - EI u_xxx, second-order with the odd ghosts).
    out.bridgeForce = tension_ * (u[2] - u[1]) / h - ei_ * (u[3] - 2.0 * u[2] + u[1]) / (h * h * h);
    const auto N = static_cast<std::size_t>(string_.cells);
    out.farEndForce = tension_ * (u[N] - u[N + 1]) / h - ei_ * (u[N - 1] - 2.0 * u[N] + u[N + 1]) / (h * h * h);
    // The bridge's modes, driven by that force (central differences; their mass is far above
    // a cell's, so the explicit step is stable).
    double bridgeNext = 0.0;
    for (auto& m : bridge_) {
        const double a = m.m * fs_ * fs_, b = 0.5 * m.r * fs_;
        const double y = (out.bridgeForce + (2.0 * a - m.s) * m.now - (a - b) * m.prev) / (a + b);
        m.prev = m.now;
        m.now = y;
        bridgeNext += y;
    }
    string_.freeStep(bridgeNow_, bridgePrev_, bridgeNext);
    double vFree = (string_.bowValue(string_.next) - string_.bowValue(string_.prev)) * 0.5 * fs_;
    if (torsionOn_) {
        torsion_.freeStep(0.0, 0.0, 0.0);
        vFree += (torsion_.bowValue(torsion_.next) - torsion_.bowValue(torsion_.prev)) * 0.5 * fs_;
    }
    // Contact: footprint from the load law, temperature from the heat of the last step.
    force = std::max(0.0, force);
    const ContactConstants& kc = fr.contact;
    auto loadOf = [&](double f) { return f > 0.0 ? kc.referenceLoad * std::pow(f / kc.referenceLoad, fr.loadExponent) : 0.0; };
    const double load = loadOf(force);
    double theta = 0.0;
    if (fr.law != FrictionLaw::Curve) {
        // The heat of the last step spreads over the last step's footprint, which follows the same
        // load law as the friction (a Hertzian footprint grows as F^n, not as F).
        const double area = fr.footprintRatio * kPi * kc.radiusAtReference * kc.radiusAtReference * loadOf(forcePrev_) / kc.referenceLoad;
        double heat = 0.0, advection = 0.0, kappa = 0.0;
        if (area > 0.0) {
            const double a = std::sqrt(area / kPi);
            heat = heatPrev_ / area;
            advection = kc.rosinVolumetricHeat * kc.layerThickness * kc.advectionWidthFactor * a * slidePrev_ / area;
            kappa = 3.0 * slidePrev_ / (8.0 * a);
        }
        theta = heat_.step(heat, kc.rosinVolumetricHeat * kc.layerThickness, advection, kappa);
    }
    const double rA = fr.footprintRatio;
    ContactSolver::Result r;
    switch (fr.law) {
    case FrictionLaw::Curve:
        r = contact_.solve(vFree, bowSpeed, twoZ_, [&](double x) { return load * fr.steady.mu(x); }, false);
        break;
    case FrictionLaw::Thermal: {
        const double limit = rA * load * table_.at(theta + fr.temperatureShiftK);
        r = contact_.solve(vFree, bowSpeed, twoZ_, [limit](double) { return limit; }, true);
        break;
    }
    case FrictionLaw::Enhanced: {
        const double y = rA * load * table_.at(theta + fr.temperatureShiftK);
        r = contact_.solve(vFree, bowSpeed, twoZ_, [&](double x) { return y * fr.speed.at(x); }, false);
        break;
    }
    }
    // Apply the friction force to both lines and move time on.
    const double gain = k_ * k_ / (rig_.string.massPerLength * h) * r.force;
    for (std::size_t i = string_.first; i <= string_.last; ++i) string_.next[i] += gain * string_.response[i];
    std::swap(string_.prev, string_.now);
    std::swap(string_.now, string_.next);
    bridgePrev_ = bridgeNow_;
    bridgeNow_ = bridgeNext;
    if (torsionOn_) {
        const double gt = k_ * k_ / (torsion_.mass * torsion_.h) * r.force;
        for (std::size_t i = torsion_.first; i <= torsion_.last; ++i) torsion_.next[i] += gt * torsion_.response[i];
        std::swap(torsion_.prev, torsion_.now);
        std::swap(torsion_.now, torsion_.next);
    }
    const double slide = std::abs(r.velocity - bowSpeed);
    heatPrev_ = std::abs(r.force) * slide;
    slidePrev_ = slide;
    forcePrev_ = force;
    out.velocity = r.velocity;
    out.friction = r.force;
    out.temperature = theta;
    out.stick = r.stick;
    return out;
}

} // namespace rosin::reference
