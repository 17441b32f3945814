#include "rosin/engine/Controls.h"

#include <algorithm>
#include <cmath>

#include "rosin/dsp/Config.h"

namespace rosin::engine {

BowTarget mapBow(const ParamValues& params, double stringScale, float force01, float speed, float position01) noexcept
{
    auto nominal = [&](Param p) { return static_cast<double>(sanitise(p, params[static_cast<std::size_t>(p)])); };
    // A source at its middle (0.5) plays the nominal parameter; the range spans 0-2x (force and
    // speed) and a factor 2 either way (position, on a log scale: the bow moves in ratios).
    const double f = std::isfinite(force01) && force01 >= 0.0f ? std::min(1.0f, force01) : 0.5;
    const double v = std::isfinite(speed) ? std::clamp(static_cast<double>(speed), -1.0, 1.0) : 0.5;
    const double q = std::isfinite(position01) && position01 >= 0.0f ? std::min(1.0f, position01) : 0.5;
    const double scale = std::isfinite(stringScale) && stringScale > 0.0 ? stringScale : 1.0;
    BowTarget t;
    t.force = std::clamp(nominal(Param::BowForce) * 2.0 * f * scale, 0.0, dsp::config::maxBowForce);
    t.speed = std::clamp(nominal(Param::BowSpeed) * 2.0 * v, -dsp::config::maxBowSpeed, dsp::config::maxBowSpeed);
    t.beta = std::clamp(nominal(Param::BowPosition) * std::exp2(2.0 * (q - 0.5)), dsp::config::minBeta, dsp::config::maxBeta);
    return t;
}

} // namespace rosin::engine
