// The live physics views, drawn by the same code in the plugin's editor (juce::Graphics) and in
// the lab's PNG figures (cairo): a bridge-force scope shaded by stick and slip, the contact
// temperature trace, the friction loop (friction coefficient against sliding speed) and the
// playability map with the current gesture as a point.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "rosin/lab/Classifier.h"
#include "rosin/lab/Painter.h"
#include "rosin/lab/Playability.h"

namespace rosin::lab {

/// Round tick positions covering [lo, hi].
std::vector<double> niceTicks(double lo, double hi, int target = 6);

/// Guettler-diagram colours shared with the lab's figures (PHYSICS.md 6.6): light = a short
/// transient, dark = a long one; failures by regime.
Color transientColor(int periods);
Color regimeColor(Regime r);

/// One sample of the voice being watched, in physical units.
struct LiveSample {
    float bridgeForce = 0, velocity = 0, bowSpeed = 0, friction = 0, force = 0, temperature = 0, beta = 0, frequency = 0;
    bool stick = true, noteStart = false, bowed = true;
    int string = 0;
};

/// The recent past of the watched voice: a fixed ring (allocated once) and what the views read
/// from it. Lives with the reader (the editor's message thread or a lab figure).
class LiveHistory {
public:
    explicit LiveHistory(double sampleRate = 48000.0, double seconds = 2.0);
    void push(const LiveSample& s) noexcept;
    void clear() noexcept;
    double sampleRate() const noexcept { return fs_; }
    std::size_t size() const noexcept { return count_; }
    std::size_t capacity() const noexcept { return ring_.size(); }
    unsigned long long total() const noexcept { return total_; }
    const LiveSample& back(std::size_t age = 0) const noexcept; ///< age 0 = newest
    double ambientCelsius = 20.0;

    struct Scope {
        std::vector<double> time, force; ///< s from the trigger, N
        std::vector<unsigned char> stick;
        bool triggered = false;          ///< aligned on a slip onset (else free running)
        double period = 0;               ///< s
    };
    /// The last `periods` nominal periods, starting at a slip onset so the picture stands still.
    Scope scope(double periods = 3.0) const;

    struct Trace {
        std::vector<double> time, low, high; ///< s before now, contact temperature (C) min/max per column
    };
    Trace temperature(double seconds, int columns) const;

    struct Loop {
        std::vector<double> slide, mu; ///< sliding speed v - v_b (m/s), friction / bow force
    };
    Loop loop(double periods = 2.0) const;

    struct Gesture {
        bool valid = false;
        double force = 0, speed = 0, beta = 0, acceleration = 0; ///< N, m/s, -, m/s^2 (the latest attack)
        double frequency = 0;
        int string = 0;
    };
    Gesture gesture() const;

private:
    std::vector<LiveSample> ring_;
    std::size_t head_ = 0, count_ = 0;
    unsigned long long total_ = 0, lastNoteStart_ = 0;
    bool sawNoteStart_ = false;
    double fs_;
};

struct ViewTheme {
    Color background, panel, grid, text, dim, trace, stickShade, slipShade, temperature, loop, point, reference;
    double fontSize = 12.0; ///< px: the editor scales it with the window
    static ViewTheme dark(double fontSize = 12.0);
    static ViewTheme light(double fontSize = 12.0); ///< printed figures
};

void drawScope(Painter& p, const Rect& r, const ViewTheme& t, const LiveHistory& h);
void drawTemperature(Painter& p, const Rect& r, const ViewTheme& t, const LiveHistory& h, double seconds = 2.0);
void drawLoop(Painter& p, const Rect& r, const ViewTheme& t, const LiveHistory& h);
/// `map` may be null or partly computed; `status` is shown when there is nothing to draw.
void drawPlayability(Painter& p, const Rect& r, const ViewTheme& t, const PlayabilityMap* map, const LiveHistory::Gesture& g,
                     const std::string& status = {}, double muS = 1.2, double muD = 0.35);

} // namespace rosin::lab
