#include "rosin/reference/Conduction.h"

#include <cmath>
#include <numbers>

namespace rosin::reference {

namespace {
const double kTwoOverSqrtPi = 2.0 / std::sqrt(std::numbers::pi);
// exp(-integral of kappa) is carried as exp(S - S_ref); S_ref moves on before it overflows.
constexpr double kRenormaliseAt = 300.0;
} // namespace

void ExactConduction::prepare(double step, double stringEffusivity, double rodEffusivity, int recentSteps)
{
    h_ = step;
    es_ = stringEffusivity;
    er_ = rodEffusivity;
    recent_ = recentSteps;
    reset();
}

void ExactConduction::reset()
{
    now_ = 0;
    theta_ = 0;
    renewal_ = renewalRef_ = 0;
    lastString_ = lastRod_ = 0;
    started_ = false;
    levels_.assign(1, {});
}

double ExactConduction::rootOf(long steps)
{
    while (static_cast<long>(roots_.size()) <= steps) roots_.push_back(std::sqrt(static_cast<double>(roots_.size())));
    return roots_[static_cast<std::size_t>(steps)];
}

void ExactConduction::compact()
{
    if (recent_ <= 0) return;
    const std::size_t cap = 2 * static_cast<std::size_t>(recent_);
    for (std::size_t l = 0; l < levels_.size(); ++l) {
        auto& level = levels_[l];
        if (level.size() <= cap) break;
        // The two oldest pieces of this level become one piece of the next, which is newer
        // than everything already there. Each level keeps at least `recent_` pieces, so a
        // piece is never longer than 1/recent_ of its age.
        const Piece a = level[0], b = level[1];
        level.erase(level.begin(), level.begin() + 2);
        if (l + 1 == levels_.size()) levels_.emplace_back();
        levels_[l + 1].push_back({a.start, b.end, a.stringHeat + b.stringHeat, a.rodHeat + b.rodHeat});
    }
}

double ExactConduction::step(double heatIn, double storage, double advection, double kappa)
{
    const long n = now_; // this step spans [n, n + 1) in steps
    if (!started_ && heatIn <= 0.0) {
        ++now_;
        return theta_; // nothing has entered yet: the contact is at ambient
    }
    started_ = true;
    kappa = std::max(0.0, kappa);
    const double renewalEnd = renewal_ + kappa * h_;
    const long end = n + 1;
    // History sums: each piece's mean flux times the kernel 1/sqrt(pi (t_end - t)) integrated
    // exactly over the piece.
    const double c0 = kTwoOverSqrtPi * std::sqrt(h_);
    rootOf(end);
    const double* root = roots_.data();
    double hs = 0.0, hr = 0.0;
    for (const auto& level : levels_)
        for (const Piece& p : level) {
            const double k = (root[end - p.start] - root[end - p.end]) / static_cast<double>(p.end - p.start);
            hs += p.stringHeat * k;
            hr += p.rodHeat * k;
        }
    hs *= c0;
    hr *= c0 * std::exp(renewalRef_ - renewalEnd);
    // This step's own kernel: the stationary side exactly, the renewed side with exp(-kappa s).
    const double c0r = kappa * h_ > 1e-12 ? std::erf(std::sqrt(kappa * h_)) / std::sqrt(kappa) : c0;
    const double theta = (heatIn + storage * theta_ / h_ + hs / c0 + hr / c0r) / (storage / h_ + advection + es_ / c0 + er_ / c0r);
    lastString_ = (es_ * theta - hs) / c0;
    lastRod_ = (er_ * theta - hr) / c0r;
    theta_ = theta;
    // Within the step the renewal decays the rod's flux by exp(-kappa s) before the step ends:
    // its mean factor (1 - e^-x)/x (x = kappa h) carries the piece to the end of the step.
    const double x = kappa * h_;
    const double within = x > 1e-9 ? -std::expm1(-x) / x : 1.0 - 0.5 * x;
    levels_[0].push_back({n, end, lastString_, lastRod_ * within * std::exp(renewalEnd - renewalRef_)});
    renewal_ = renewalEnd;
    if (renewal_ - renewalRef_ > kRenormaliseAt) {
        const double scale = std::exp(renewalRef_ - renewal_);
        for (auto& level : levels_)
            for (Piece& p : level) {
                p.rodHeat *= scale;
                if (std::abs(p.rodHeat) < 1e-250) p.rodHeat = 0.0; // long renewed: nothing left
            }
        renewalRef_ = renewal_;
    }
    compact();
    now_ = end;
    return theta_;
}

} // namespace rosin::reference
