// Limits shared by every dsp unit. Buffers are sized from these in prepare(), never later.
#pragma once

namespace rosin::dsp::config {

/// Lowest bow position accepted (fraction of string length); below this the bridge-side
/// segment would be shorter than the minimum delay at audio rates.
inline constexpr double minBeta = 0.01;
/// Highest bow position accepted; beyond mid-string the two sides swap roles.
inline constexpr double maxBeta = 0.5;
/// Largest bow force (N) and speed (m/s) the model clamps to. Far beyond playing values,
/// but they keep a runaway controller from pushing the solver into overflow.
inline constexpr double maxBowForce = 20.0;
inline constexpr double maxBowSpeed = 10.0;
/// Smallest delay (samples) of any waveguide segment: below one sample the junction would
/// read its own output. Woodhouse's finite-width model used the same floor.
inline constexpr double minSegmentDelay = 1.0;
/// Number of entries of the temperature-law tables (mu(theta), y(theta)).
inline constexpr int temperatureTableSize = 2048;
/// Pole slots per side in the thermal conduction bank (unused slots carry zero weight). A
/// fixed count lets the per-sample loops vectorise; 1.5 poles per decade from 0.3/s to 10 fs
/// needs 12-14 of them at any rate from 44.1 kHz to 1 MHz.
inline constexpr int thermalPoleSlots = 16;

} // namespace rosin::dsp::config
