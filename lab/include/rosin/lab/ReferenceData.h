// `rosin synth-data --generator reference`: measurement sets made by the reference simulator
// (lab/reference, which shares no code with dsp/) on a rig drawn per set. Besides the hidden
// effects, the rig draws what a lab never knows exactly: tension and bow position off the
// manifest, static friction and the steady-sliding curve off the standard fit, thermal
// constants within their literature ranges, string stiffness and losses, a bridge with two
// resonances, a force sensor with its own transfer function, mains hum, DC, noise from clean to
// poor, sometimes clipping. The manifest carries only what a lab would write down; the truth
// file records everything.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rosin/lab/SynthData.h"

namespace rosin::lab {

/// One drawn rig value: uniform (or log-uniform) between lo and hi unless fixed by the user.
struct RigPrior {
    std::string key;
    double lo, hi;
    bool logScale;
    std::string meaning;
};

/// Every rig value the reference generator draws, in the order it draws them.
const std::vector<RigPrior>& referenceRigPriors();

/// NAME=VALUE strings (`--rig-param`) to fixed rig values, each name one of referenceRigPriors()
/// and each value finite: a clear error otherwise, before anything is simulated.
std::map<std::string, double> parseRigValues(const std::vector<std::string>& nameEqualsValue);

/// Priors of the hidden effects' parameters in reference sets. They reach weak effects close
/// to none: shifts from 1 K, load exponents up to 0.95, Z_t/Z_0 up to 8.
const std::map<std::string, std::pair<double, double>>& referenceEffectPriors();

/// NAME=LO:HI strings (`--param-range`) to narrowed draws of hidden parameters: each name one of
/// referenceEffectPriors(), LO < HI, both finite and inside that prior; a clear error otherwise.
/// For shift_k the range is of its size |shift|; the sign is drawn as before.
std::map<std::string, std::pair<double, double>> parseParamRanges(const std::vector<std::string>& nameEqualsRange);

/// NAME=U strings (`--stated-uncertainty`) for a lab that measured its rig: names tension and
/// beta, U a fraction either way from 0.001 (what a manifest accepts) to the generator's own
/// spread of that error (0.04, 0.03). The rig's error is then drawn within +-U and the manifest
/// states U (rig.string.tension_uncertainty, rig.beta_uncertainty); a clear error otherwise.
std::map<std::string, double> parseStatedUncertainties(const std::vector<std::string>& nameEqualsFraction);

/// A set on a rig drawn from spec.seed. `--generator reference` plays it on the reference simulator;
/// `model-on-rig` takes the very same draws and plays them on modelOnRig(), the diagnosis's ceiling.
MeasurementSet synthesizeReference(const SynthSpec& spec, SynthTruth& truth, const std::function<void(double)>& progress = {});

} // namespace rosin::lab
