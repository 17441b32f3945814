#include "rosin/lab/Schumacher.h"

#include <algorithm>
#include <cmath>

#include "rosin/lab/Error.h"

namespace rosin::lab {

namespace {
double at(const std::vector<double>& x, double i)
{
    const auto k = static_cast<std::size_t>(std::floor(i));
    const double s = i - static_cast<double>(k);
    return x[k] + s * (x[k + 1] - x[k]);
}
} // namespace

Reconstruction reconstruct(const std::vector<double>& f1, const std::vector<double>& f2, double fs, double tauBridge, double tauFar,
                           double z0)
{
    if (f1.size() != f2.size()) throw LabError("reconstruction: the two end forces differ in length");
    const double db = tauBridge * fs, dn = tauFar * fs, reach = std::max(db, dn) + 2.0;
    Reconstruction r;
    if (static_cast<double>(f1.size()) < 2.0 * reach + 4.0) return r;
    r.first = static_cast<std::size_t>(std::ceil(reach));
    const std::size_t last = f1.size() - r.first - 1;
    for (std::size_t n = r.first; n < last; ++n) {
        const double t = static_cast<double>(n);
        // v = [f1(t + tb) - f1(t - tb)] / 2Z0 = [f2(t + tn) - f2(t - tn)] / 2Z0
        const double v1 = (at(f1, t + db) - at(f1, t - db)) / (2.0 * z0);
        const double v2 = (at(f2, t + dn) - at(f2, t - dn)) / (2.0 * z0);
        // f = f1(t + tb) + f2(t - tn) = f2(t + tn) + f1(t - tb)
        const double fa = at(f1, t + db) + at(f2, t - dn);
        const double fb = at(f2, t + dn) + at(f1, t - db);
        r.velocity.push_back(0.5 * (v1 + v2));
        r.friction.push_back(0.5 * (fa + fb));
    }
    return r;
}

double loopArea(const std::vector<double>& v, const std::vector<double>& f, std::size_t from, std::size_t to)
{
    double a = 0.0;
    to = std::min({to, v.size(), f.size()});
    for (std::size_t i = from; i + 1 < to; ++i) a += v[i] * f[i + 1] - v[i + 1] * f[i];
    return 0.5 * a;
}

} // namespace rosin::lab
