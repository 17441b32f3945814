// What the window sees of the Synth: the newest note's physics written sample by sample into
// the view ring while someone listens, and each voice's state. Audio thread for the tap; the
// getters are read by the processor's views.
#include "rosin/engine/Synth.h"

namespace rosin::engine {

void Synth::setVoiceTap(float* bridgeForce, std::uint8_t* stick, int capacity) noexcept
{
    tap_.bridge = bridgeForce;
    tap_.stick = stick;
    tap_.capacity = bridgeForce ? capacity : 0;
    tap_.count = 0;
    tapVoice_ = nullptr;
    tapArmed_ = bridgeForce != nullptr;
}

void Synth::chooseWatched() noexcept
{
    // The watched note ended: follow the newest one still sounding.
    const Voice* best = nullptr;
    for (const auto& v : voices_)
        if (v.active() && !v.stolen() && (best == nullptr || v.order() > best->order())) best = &v;
    if (best != watched_) watchedIsNew_ = best != nullptr;
    watched_ = best;
}

int Synth::activeVoiceCount() const noexcept
{
    int n = 0;
    for (const auto& v : voices_) n += v.active() ? 1 : 0;
    return n;
}

VoiceInfo Synth::voiceInfo(int i) const noexcept
{
    if (i < 0 || i >= static_cast<int>(voices_.size())) return {};
    return voices_[static_cast<std::size_t>(i)].info();
}

} // namespace rosin::engine
