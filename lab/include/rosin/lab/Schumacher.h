// Schumacher's reconstruction (PHYSICS.md 7.2): from the forces at both ends of a string,
// the velocity of the string at the bow and the friction force, without a sensor at the bow.
#pragma once
#include <vector>

namespace rosin::lab {

struct Reconstruction {
    std::vector<double> velocity; ///< m/s, string at the bow
    std::vector<double> friction; ///< N, bow on string
    std::size_t first = 0;        ///< index of the first reconstructed sample in the input
};

/// Ideal-end version (A): f1 the bridge force, f2 the far-end force (both positive when the
/// string pulls its support in the +v direction), fs the rate, tauBridge = beta L / c and
/// tauFar = (1 - beta) L / c the one-way travel times. The two estimates of each quantity
/// are averaged; fractional delays are interpolated linearly.
Reconstruction reconstruct(const std::vector<double>& f1, const std::vector<double>& f2, double fs, double tauBridge,
                           double tauFar, double z0);

/// Signed area of the (v, f) trajectory over [from, to): positive = anticlockwise (PHYSICS.md 7.3).
double loopArea(const std::vector<double>& v, const std::vector<double>& f, std::size_t from, std::size_t to);

} // namespace rosin::lab
