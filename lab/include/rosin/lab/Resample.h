// Band-limited resampling between any two rates (Kaiser-windowed sinc), and the causal
// anti-alias filter a recorder puts in front of its converter.
#pragma once
#include <vector>

namespace rosin::lab {

/// Resamples x from rate `from` to rate `to`. The sinc kernel's cutoff sits at 0.45 of the
/// lower rate, so nothing above the new Nyquist frequency folds back.
std::vector<double> resample(const std::vector<double>& x, double from, double to);

/// Second-order Butterworth low-pass run forwards then backwards: no phase shift, so event
/// times in the signal do not move.
void zeroPhaseLowPass(std::vector<double>& x, double cutoff, double rate);

/// Causal 4th-order Butterworth low-pass (two biquads), like a converter's analogue filter.
void antiAliasFilter(std::vector<double>& x, double cutoff, double rate);

} // namespace rosin::lab
