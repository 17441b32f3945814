// The editor's live physics: frames of the sounding note arrive from the audio thread through
// the processor's ViewRing (lock-free; the audio thread never waits for the window) and are
// drawn by the lab's view code: scope with stick/slip shading, contact temperature, friction
// loop, and a playability map computed on a background thread for the string being played.
#pragma once
#include <juce_gui_basics/juce_gui_basics.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>

#include "rosin/engine/Presets.h"
#include "rosin/engine/ViewTap.h"
#include "rosin/lab/Playability.h"
#include "rosin/lab/Views.h"

namespace rosin::plugin { class RosinProcessor; }

namespace rosin::ui {

/// Computes playability maps off the message thread; a new request cancels the one running.
class PlayabilityWorker : private juce::Thread {
public:
    PlayabilityWorker();
    ~PlayabilityWorker() override;
    void request(const lab::PlayabilitySpec& spec);                 ///< [message thread]
    std::shared_ptr<const lab::PlayabilityMap> latest() const;      ///< [message thread] partial while computing
    bool busy() const noexcept { return busy_.load(); }

private:
    void run() override;
    mutable std::mutex mutex_; // between this thread and the message thread only
    std::optional<lab::PlayabilitySpec> pending_;
    std::shared_ptr<const lab::PlayabilityMap> latest_;
    std::atomic<bool> cancel_{false}, busy_{false};
};

class LiveViews : public juce::Component, private juce::Timer {
public:
    explicit LiveViews(plugin::RosinProcessor& processor);
    ~LiveViews() override;
    void paint(juce::Graphics& g) override;

    void setMapKind(lab::MapKind kind);
    lab::MapKind mapKind() const noexcept { return kind_; }
    double fontSize() const noexcept;
    /// For tests and the status line: what has been seen.
    unsigned long long framesSeen() const noexcept { return history_.total(); }
    const lab::LiveHistory& history() const noexcept { return history_; }
    bool mapReady() const;
    void refreshNow() { timerCallback(); } ///< drain and redraw without waiting for the timer

private:
    struct MapKey {
        std::string instrument;
        int string = -1, semitone = 0, kind = 0;
        std::array<long, 8> physics{};
        bool operator==(const MapKey&) const = default;
    };
    void timerCallback() override;
    void drain();
    void updateMap();
    std::array<juce::Rectangle<int>, 4> panels() const;

    plugin::RosinProcessor& processor_;
    lab::LiveHistory history_;
    std::vector<engine::ViewFrame> buffer_;
    PlayabilityWorker worker_;
    lab::MapKind kind_ = lab::MapKind::Schelleng;
    std::optional<MapKey> requested_, candidate_;
    int candidateTicks_ = 0;
    std::string instrumentName_;
    engine::InstrumentPreset instrument_;
    bool instrumentLoaded_ = false;
};

} // namespace rosin::ui
