// What the editor's live views need from the audio thread: one frame per sample of the voice
// being watched, through a frame ring (rt/FrameRing.h: the writer never waits, frames are
// dropped when nobody reads).
#pragma once
#include <cstdint>

#include "rosin/rt/FrameRing.h"

namespace rosin::engine {

struct ViewFrame {
    float bridgeForce = 0;  ///< N, the string's force on the bridge (before the body)
    float velocity = 0;     ///< string velocity at the bow (m/s)
    float bowSpeed = 0;     ///< signed bow speed (m/s)
    float friction = 0;     ///< friction force on the string (N)
    float force = 0;        ///< bow force (N)
    float temperature = 0;  ///< contact temperature rise above ambient (K)
    float beta = 0;         ///< bow position (fraction of the vibrating length)
    float frequency = 0;    ///< the note's stopped-string fundamental (Hz)
    std::uint8_t stick = 1;
    std::uint8_t string = 0;    ///< which string of the instrument (0 = lowest)
    std::uint8_t noteStart = 0; ///< 1 on the first frame of a new note
    std::uint8_t bowed = 1;     ///< 0 while a finger or stick excites the string (pizzicato, col legno)
};

/// The views' channel from the audio thread to the editor.
using ViewRing = rt::FrameRing<ViewFrame>;

} // namespace rosin::engine
