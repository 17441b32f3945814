// One bowed string: waveguide + bow junction, driven by physical controls every sample.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "BowJunction.h"
#include "StringWaveguide.h"

// The voice loop is also compiled for AVX2 and AVX-512 machines, picked at load time (GNU
// ifunc). Results stay bit-identical to the baseline build because the project compiles with
// -ffp-contract=off (no fused multiply-add): wider and more registers, the same arithmetic.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && !defined(ROSIN_NO_CLONES)
#define ROSIN_VOICE_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4"), flatten))
#else
#define ROSIN_VOICE_CLONES
#endif

namespace rosin::dsp {

struct BowedStringConfig {
    StringParams string = StringParams::celloD();
    WaveguideOptions waveguide;
    FrictionParams friction;
};

/// Everything the research outputs need about one sample (PHYSICS.md 6.9).
template <typename T>
struct BowFrame {
    T bridgeForce = T(0);   ///< f_br (N)
    T velocity = T(0);      ///< string surface velocity at the bow v (m/s)
    T friction = T(0);      ///< friction force on the string f (N)
    T temperature = T(0);   ///< contact rise theta (K)
    T history = T(0);       ///< v_h (m/s)
    bool stick = true;
};

template <typename T>
class BowedString {
public:
    /// [setup thread] Allocates; call again when the string, model or rate changes.
    void prepare(double sampleRate, const BowedStringConfig& config)
    {
        config_ = config;
        waveguide_.prepare(sampleRate, config.string, config.waveguide);
        junction_.prepare(sampleRate, config.friction);
        zEff_ = waveguide_.effectiveImpedance();
        reset();
    }

    void reset() noexcept
    {
        waveguide_.reset();
        junction_.reset();
    }

    /// [audio thread] One sample. force (N), speed (m/s, signed), beta (bow position / L).
    /// Returns the bridge force; fills `frame` when given.
    T processSample(T force, T speed, T beta, BowFrame<T>* frame = nullptr) noexcept
    {
        followBow(beta);
        const T vh = waveguide_.beginSample();
        const JunctionResult<T> r = junction_.solve(vh, speed, force, zEff_);
        waveguide_.endSample(r.force);
        const T out = waveguide_.bridgeForce();
        if (frame) *frame = {out, r.velocity, r.force, r.temperature, vh, r.stick};
        return out;
    }

    /// [audio thread] n samples; each control is an array (per-sample trajectories), so a
    /// block split anywhere gives the same output. `stick`, when given, receives 1 for each
    /// sample the contact sticks (the instrument listens for slip onsets).
    void processBlock(const T* force, const T* speed, const T* beta, T* out, int n,
                      BowFrame<T>* frames = nullptr, std::uint8_t* stick = nullptr) noexcept
    {
        // A playing voice (plain string, thermal model, no research frames) gets a loop with its
        // switches fixed at compile time: the same calls as processSample, so the same output.
        if (!frames && waveguide_.packed() && junction_.params().model == FrictionModel::Thermal) {
            const bool torsion = waveguide_.options().torsion;
            if (stick) {
                if (torsion) processPlainThermal<true, true>(force, speed, beta, out, stick, n);
                else processPlainThermal<false, true>(force, speed, beta, out, stick, n);
            } else {
                if (torsion) processPlainThermal<true, false>(force, speed, beta, out, stick, n);
                else processPlainThermal<false, false>(force, speed, beta, out, stick, n);
            }
            return;
        }
        BowFrame<T> frame;
        for (int i = 0; i < n; ++i) {
            BowFrame<T>* f = frames ? frames + i : (stick ? &frame : nullptr);
            out[i] = processSample(force[i], speed[i], beta[i], f);
            if (stick) stick[i] = f->stick ? 1 : 0;
        }
    }

    /// [audio thread] Drive the string with a prescribed force instead of the bow (the pulse
    /// tests and plucks). Returns the history velocity before the force acted.
    T processForce(T f) noexcept
    {
        const T vh = waveguide_.beginSample();
        waveguide_.endSample(f);
        return vh;
    }

    const StringWaveguide<T>& waveguide() const noexcept { return waveguide_; }
    StringWaveguide<T>& waveguide() noexcept { return waveguide_; }
    const BowJunction<T>& junction() const noexcept { return junction_; }
    BowJunction<T>& junction() noexcept { return junction_; }
    double effectiveImpedance() const noexcept { return zEff_; }
    const BowedStringConfig& config() const noexcept { return config_; }

private:
    /// The bow rarely moves along the string: skip the call (setBeta clamps, so an out-of-range
    /// beta still goes through and is ignored there).
    void followBow(T beta) noexcept
    {
        if (static_cast<double>(beta) != waveguide_.beta()) waveguide_.setBeta(static_cast<double>(beta));
    }

    template <bool Torsion, bool Stick>
    ROSIN_VOICE_CLONES void processPlainThermal(const T* force, const T* speed, const T* beta, T* out, std::uint8_t* stick,
                                                int n) noexcept
    {
        // The controls are made safe a chunk at a time in one vectorised pass, not per sample.
        constexpr int kChunk = 64;
        T forceClean[kChunk], speedClean[kChunk];
        for (int start = 0; start < n; start += kChunk) {
            const int m = std::min(kChunk, n - start);
            BowJunction<T>::cleanControls(force + start, speed + start, forceClean, speedClean, m);
            for (int j = 0; j < m; ++j) {
                followBow(beta[start + j]);
                const T vh = waveguide_.template beginSamplePacked<Torsion>();
                const JunctionResult<T> r = junction_.solveThermalCleanControls(vh, speedClean[j], forceClean[j], zEff_);
                waveguide_.template endSampleWith<Torsion>(r.force);
                out[start + j] = waveguide_.bridgeForce();
                if constexpr (Stick) stick[start + j] = r.stick ? 1 : 0;
            }
        }
    }

    BowedStringConfig config_;
    StringWaveguide<T> waveguide_;
    BowJunction<T> junction_;
    double zEff_ = 0.5;
};

} // namespace rosin::dsp
