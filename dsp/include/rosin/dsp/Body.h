// Instrument body as a bank of resonant modes driven by the bridge force (a modal bridge
// admittance, PHYSICS.md 1.1 "body filter"): what turns a bare string into a violin or a cello.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace rosin::dsp {

struct BodyMode {
    double frequency = 300.0; ///< Hz
    double q = 30.0;          ///< quality factor (damping ratio 1/2Q)
    double gain = 1.0;        ///< peak response relative to the direct path
};

struct BodyParams {
    static constexpr int maxModes = 24;
    std::array<BodyMode, maxModes> modes{};
    int count = 0;
    double direct = 0.2; ///< the bridge force passed straight through (high-frequency radiation)
    double outputScale = 1.0; ///< N -> output units, so instruments of different size sit at similar levels
};

/// Parallel second-order resonators in topology-preserving (trapezoidal) state-variable form:
/// stable for any coefficient, and their band-pass output peaks at exactly `gain`.
template <typename T>
class ModalBody {
public:
    /// [setup thread] No allocation: the mode array is fixed.
    void prepare(double sampleRate, const BodyParams& params) noexcept
    {
        fs_ = sampleRate;
        params_ = params;
        count_ = std::clamp(params.count, 0, BodyParams::maxModes);
        active_ = 0;
        for (int i = 0; i < count_; ++i) {
            const BodyMode& m = params.modes[static_cast<std::size_t>(i)];
            if (!(m.frequency > 0.0) || m.frequency >= 0.49 * sampleRate || !(m.q > 0.0)) continue;
            Section& s = sections_[static_cast<std::size_t>(active_++)];
            const double g = std::tan(std::numbers::pi * m.frequency / sampleRate);
            const double k = 1.0 / m.q;
            s.g = static_cast<T>(g);
            s.k = static_cast<T>(k);
            s.a1 = static_cast<T>(1.0 / (1.0 + g * (g + k)));
            s.gain = static_cast<T>(m.gain * k); // band-pass peak is 1/k: scale it to `gain`
        }
        reset();
    }

    void reset() noexcept
    {
        for (auto& s : sections_) s.ic1 = s.ic2 = T(0);
    }

    /// [audio thread] Bridge force in, body output out (scaled by outputScale).
    T processSample(T force) noexcept
    {
        T y = static_cast<T>(params_.direct) * force;
        for (int i = 0; i < active_; ++i) {
            Section& s = sections_[static_cast<std::size_t>(i)];
            const T v1 = s.a1 * (s.ic1 + s.g * (force - s.ic2));
            const T v2 = s.ic2 + s.g * v1;
            s.ic1 = T(2) * v1 - s.ic1;
            s.ic2 = T(2) * v2 - s.ic2;
            y += s.gain * v1;
        }
        return y * static_cast<T>(params_.outputScale);
    }

    void processBlock(const T* in, T* out, int n) noexcept
    {
        for (int i = 0; i < n; ++i) out[i] = processSample(in[i]);
    }

    int activeModes() const noexcept { return active_; }
    const BodyParams& params() const noexcept { return params_; }

private:
    struct Section {
        T g = T(0), k = T(1), a1 = T(1), gain = T(0), ic1 = T(0), ic2 = T(0);
    };
    double fs_ = 48000.0;
    BodyParams params_;
    std::array<Section, BodyParams::maxModes> sections_{};
    int count_ = 0, active_ = 0;
};

} // namespace rosin::dsp
