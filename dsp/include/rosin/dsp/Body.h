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
/// stable for any coefficient, and their band-pass output peaks at exactly `gain`. The modes
/// are independent, so they are stored lane by lane and stepped in 16-byte vector packs.
template <typename T>
class ModalBody {
    typedef T Pack __attribute__((vector_size(16)));
    static constexpr int lanes = static_cast<int>(16 / sizeof(T));
    static constexpr int maxPacks = (BodyParams::maxModes + lanes - 1) / lanes;

public:
    /// [setup thread] No allocation: the mode array is fixed.
    void prepare(double sampleRate, const BodyParams& params) noexcept
    {
        retune(sampleRate, params);
        reset();
    }

    /// [audio thread] New modes (a mute on the bridge) without clearing what is ringing.
    void retune(double sampleRate, const BodyParams& params) noexcept
    {
        params_ = params;
        active_ = 0;
        for (int p = 0; p < maxPacks; ++p) g_[p] = k_[p] = a1_[p] = gain_[p] = Pack{};
        const int count = std::clamp(params.count, 0, BodyParams::maxModes);
        for (int i = 0; i < count; ++i) {
            const BodyMode& m = params.modes[static_cast<std::size_t>(i)];
            if (!(m.frequency > 0.0) || m.frequency >= 0.49 * sampleRate || !(m.q > 0.0)) continue;
            const double g = std::tan(std::numbers::pi * m.frequency / sampleRate);
            const double k = 1.0 / m.q;
            const int pack = active_ / lanes, lane = active_ % lanes;
            g_[pack][lane] = static_cast<T>(g);
            k_[pack][lane] = static_cast<T>(k);
            a1_[pack][lane] = static_cast<T>(1.0 / (1.0 + g * (g + k)));
            gain_[pack][lane] = static_cast<T>(m.gain * k); // band-pass peak is 1/k: scale it to `gain`
            ++active_;
        }
        packs_ = (active_ + lanes - 1) / lanes;
        direct_ = static_cast<T>(params.direct);
        scale_ = static_cast<T>(params.outputScale);
        // Modes that vanished keep no energy behind.
        for (int p = packs_; p < maxPacks; ++p) ic1_[p] = ic2_[p] = Pack{};
    }

    void reset() noexcept
    {
        for (int p = 0; p < maxPacks; ++p) ic1_[p] = ic2_[p] = Pack{};
    }

    /// [audio thread] Bridge force in, body output out (scaled by outputScale).
    T processSample(T force) noexcept
    {
        const Pack x = Pack{} + force;
        Pack sum{};
        for (int p = 0; p < packs_; ++p) {
            const Pack v1 = a1_[p] * (ic1_[p] + g_[p] * (x - ic2_[p]));
            const Pack v2 = ic2_[p] + g_[p] * v1;
            ic1_[p] = T(2) * v1 - ic1_[p];
            ic2_[p] = T(2) * v2 - ic2_[p];
            sum += gain_[p] * v1;
        }
        T y = direct_ * force;
        for (int l = 0; l < lanes; ++l) y += sum[l];
        return y * scale_;
    }

    void processBlock(const T* in, T* out, int n) noexcept
    {
        for (int i = 0; i < n; ++i) out[i] = processSample(in[i]);
    }

    int activeModes() const noexcept { return active_; }
    const BodyParams& params() const noexcept { return params_; }

private:
    BodyParams params_;
    // Plain arrays: GCC drops the vector attribute inside std::array.
    static constexpr auto packSlots = static_cast<std::size_t>(maxPacks);
    Pack g_[packSlots]{}, k_[packSlots]{}, a1_[packSlots]{}, gain_[packSlots]{}, ic1_[packSlots]{}, ic2_[packSlots]{};
    T direct_ = T(0.2), scale_ = T(1);
    int active_ = 0, packs_ = 0;
};

} // namespace rosin::dsp
