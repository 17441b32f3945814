// What the player is doing, whatever the source: per-channel controls (normalised, as the
// ControlEvents brought them), MPE zones, sustain, a controller's hand on the bow, and the notes
// held down. It belongs to the performance, not to an engine: the plugin keeps one across
// engine swaps (another instrument, another rate), so an MPE zone sent once, a bend range, the
// pedal and the held notes survive. Audio thread only; no allocation.
#pragma once
#include <array>
#include <cstdint>

#include "rosin/engine/Controls.h"

namespace rosin::engine {

class Performance {
public:
    static constexpr int channels = 16;
    static constexpr int maxHeld = 64;

    struct Channel {
        float force = -1.0f, speed = -1.0f, position = -1.0f; ///< normalised; < 0 = not sent yet
        float vibrato = 0.0f, volume = 1.0f, bend = 0.0f;      ///< 0..1, 0..1, semitones
        bool sustain = false;
        /// A controller's hand on the bow (HID): kept, passed to zone members and forgotten as one.
        /// Its force and position stay apart from the channel's (CC2, CC74) so that a keyboard
        /// played after the tablet is put down gets its own values back.
        struct Hand {
            bool holds = false, engaged = false;    ///< a controller holds the bow; it touches the string
            float speed = 0.0f;                     ///< -1..1, signed
            float force = -1.0f, position = -1.0f;  ///< 0..1; < 0 = not sent, the channel's apply
            int preferredString = -1;               ///< string chosen by a controller, -1 none
        } hand;
    };
    struct Held {
        std::int8_t channel = 0, note = 0;
        float velocity = 0.0f;
        bool sustained = false; ///< the key is up but the pedal holds it
    };

    void reset() noexcept;
    /// The stream stopped (the host released the plugin): held notes, the pedal and controller
    /// values are forgotten (a host sends them again when it plays); the MPE zones stay, since a
    /// controller sends its configuration once, when it is set up.
    void stop() noexcept;
    /// The event's effect on the player's state (controls, zones, sustain, held notes).
    void apply(const ControlEvent& e) noexcept;

    /// The MPE parameter: a lower zone of 15 members until a configuration message says otherwise.
    void setMpeDefault(bool on) noexcept { mpeDefault_ = on; }
    int lowerMembers() const noexcept { return lower_ >= 0 ? lower_ : (mpeDefault_ ? 15 : 0); }
    int upperMembers() const noexcept { return upper_ >= 0 ? upper_ : 0; }
    /// The zone master (0 or 15) of a member channel, else -1.
    int masterOf(int channel) const noexcept;
    bool isMaster(int channel) const noexcept;

    const Channel& channel(int c) const noexcept { return channels_[static_cast<std::size_t>(c & 15)]; }
    /// A channel's controls with its zone master's filled in where the member sent none, and
    /// both bends added.
    Channel effective(int c) const noexcept;

    int heldCount() const noexcept { return heldCount_; }
    const Held& held(int i) const noexcept { return held_[static_cast<std::size_t>(i)]; }

private:
    void removeHeld(int channel, int note) noexcept;
    void releaseSustained(int channel) noexcept;

    std::array<Channel, channels> channels_{};
    int lower_ = -1, upper_ = -1;
    bool mpeDefault_ = false;
    std::array<Held, maxHeld> held_{};
    int heldCount_ = 0;
};

} // namespace rosin::engine
