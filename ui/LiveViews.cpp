#include "LiveViews.h"

#include <cmath>

#include "RosinProcessor.h"
#include "JucePainter.h"
#include "rosin/engine/Synth.h"

namespace rosin::ui {

PlayabilityWorker::PlayabilityWorker() : juce::Thread("Rosin playability map") { startThread(juce::Thread::Priority::low); }

PlayabilityWorker::~PlayabilityWorker()
{
    cancel_ = true;
    signalThreadShouldExit();
    notify();
    stopThread(10000);
}

void PlayabilityWorker::request(const lab::PlayabilitySpec& spec)
{
    {
        std::lock_guard<std::mutex> lock(mutex_);
        pending_ = spec;
    }
    cancel_ = true; // the map being computed is for a string nobody plays any more
    notify();
}

std::shared_ptr<const lab::PlayabilityMap> PlayabilityWorker::latest() const
{
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
}

void PlayabilityWorker::run()
{
    while (!threadShouldExit()) {
        std::optional<lab::PlayabilitySpec> spec;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            spec.swap(pending_);
        }
        if (!spec) {
            wait(-1);
            continue;
        }
        cancel_ = false;
        busy_ = true;
        try {
            lab::computePlayability(*spec, &cancel_, [this](const lab::PlayabilityMap& partial) {
                auto copy = std::make_shared<const lab::PlayabilityMap>(partial);
                std::lock_guard<std::mutex> lock(mutex_);
                latest_ = std::move(copy);
            });
        } catch (const std::exception&) {
            // An axis out of range (an absurd parameter): keep the last map.
        }
        busy_ = false;
    }
}

// ---------------------------------------------------------------------------------------------
LiveViews::LiveViews(plugin::RosinProcessor& processor)
    : processor_(processor), history_(48000.0, 2.0), buffer_(processor.viewRing().capacity())
{
    const double fs = processor.currentSampleRate();
    if (fs > 0) history_ = lab::LiveHistory(fs, 2.0);
    // Frames left over from an earlier window are stale: drop them, then listen.
    while (processor_.viewRing().read(buffer_.data(), buffer_.size()) > 0) {}
    processor_.viewRing().setListening(true);
    setOpaque(true);
    startTimerHz(30);
}

LiveViews::~LiveViews()
{
    stopTimer();
    processor_.viewRing().setListening(false);
}

void LiveViews::setMapKind(lab::MapKind kind)
{
    kind_ = kind;
    updateMap();
    repaint();
}

double LiveViews::fontSize() const noexcept
{
    const auto p = panels()[0];
    return juce::jlimit(13.0, 24.0, std::min(p.getHeight() / 14.0, p.getWidth() / 26.0));
}

bool LiveViews::mapReady() const
{
    const auto m = worker_.latest();
    return m && m->completed() == m->cells.size() && m->completed() > 0;
}

std::array<juce::Rectangle<int>, 4> LiveViews::panels() const
{
    auto area = getLocalBounds();
    const int gap = 6;
    auto top = area.removeFromTop((area.getHeight() - gap) / 2);
    area.removeFromTop(gap);
    const int half = (top.getWidth() - gap) / 2;
    return {top.withWidth(half), top.withTrimmedLeft(half + gap), area.withWidth(half), area.withTrimmedLeft(half + gap)};
}

void LiveViews::drain()
{
    const double fs = processor_.currentSampleRate();
    if (fs > 0 && std::abs(fs - history_.sampleRate()) > 0.5) history_ = lab::LiveHistory(fs, 2.0);
    history_.ambientCelsius = processor_.currentParams()[static_cast<std::size_t>(engine::Param::Ambient)];
    for (;;) {
        const std::size_t n = processor_.viewRing().read(buffer_.data(), buffer_.size());
        for (std::size_t i = 0; i < n; ++i) {
            const engine::ViewFrame& f = buffer_[i];
            lab::LiveSample s;
            s.bridgeForce = f.bridgeForce;
            s.velocity = f.velocity;
            s.bowSpeed = f.bowSpeed;
            s.friction = f.friction;
            s.force = f.force;
            s.temperature = f.temperature;
            s.beta = f.beta;
            s.frequency = f.frequency;
            s.stick = f.stick != 0;
            s.noteStart = f.noteStart != 0;
            s.bowed = f.bowed != 0;
            s.string = f.string;
            history_.push(s);
        }
        if (n < buffer_.size()) break;
    }
}

void LiveViews::updateMap()
{
    const std::string name = processor_.currentInstrument().toStdString();
    if (name != instrumentName_) {
        instrumentName_ = name;
        try {
            instrument_ = presets::loadInstrument(processor_.presetLibrary(), name);
            instrumentLoaded_ = instrument_.stringCount > 0;
        } catch (const std::exception&) {
            instrumentLoaded_ = false;
        }
    }
    if (!instrumentLoaded_) return;
    const engine::ParamValues params = processor_.currentParams();
    const auto param = [&](engine::Param p) { return static_cast<double>(params[static_cast<std::size_t>(p)]); };
    int string = std::min(2, instrument_.stringCount - 1);
    double frequency = 0.0;
    if (history_.size() > 0) {
        string = juce::jlimit(0, instrument_.stringCount - 1, history_.back().string);
        frequency = history_.back().frequency;
    }
    const double open = instrument_.strings[static_cast<std::size_t>(string)].fundamental();
    const int semitone = frequency > open ? static_cast<int>(std::lround(12.0 * std::log2(frequency / open))) : 0;
    const double force = param(engine::Param::BowForce) * engine::stringForceScale(instrument_, string);
    const auto q = [](double x, double step) { return static_cast<long>(std::lround(x / step)); };
    const auto ql = [](double x) { return static_cast<long>(std::lround(std::log(std::max(1e-6, x)) / 0.05)); };
    MapKey key{name, string, semitone, static_cast<int>(kind_),
               {q(param(engine::Param::FrictionModel), 1), q(param(engine::Param::ContactLaw), 1), q(param(engine::Param::RosinTg), 0.5),
                q(param(engine::Param::Ambient), 0.5), q(param(engine::Param::Footprint), 0.01), ql(force),
                kind_ == lab::MapKind::Schelleng ? ql(param(engine::Param::BowSpeed)) : q(param(engine::Param::BowPosition), 0.005),
                kind_ == lab::MapKind::Guettler ? ql(param(engine::Param::AttackAccel)) : 0}};
    if (requested_ && *requested_ == key) return;
    // Wait until the choice has held still for a moment (a slider being dragged, a run of notes).
    if (!candidate_ || !(*candidate_ == key)) {
        candidate_ = key;
        candidateTicks_ = 0;
    }
    if (requested_ && ++candidateTicks_ < 8) return;
    requested_ = key;
    dsp::BowedStringConfig config = engine::stringConfig(instrument_, string, params);
    lab::PlayabilitySpec spec = lab::PlayabilitySpec::around(
        kind_, config, force, param(engine::Param::BowSpeed), param(engine::Param::BowPosition), param(engine::Param::AttackAccel),
        semitone > 0 ? open * std::exp2(semitone / 12.0) : 0.0, 14, 12);
    spec.sampleRate = 48000.0;
    worker_.request(spec);
}

void LiveViews::timerCallback()
{
    drain();
    updateMap();
    repaint();
}

void LiveViews::paint(juce::Graphics& g)
{
    const lab::ViewTheme theme = lab::ViewTheme::dark(fontSize());
    g.fillAll(toColour(theme.background));
    JucePainter painter(g);
    const auto p = panels();
    const auto rect = [](const juce::Rectangle<int>& r) {
        return lab::Rect{static_cast<double>(r.getX()), static_cast<double>(r.getY()), static_cast<double>(r.getWidth()),
                         static_cast<double>(r.getHeight())};
    };
    lab::drawScope(painter, rect(p[0]), theme, history_);
    lab::drawLoop(painter, rect(p[1]), theme, history_);
    lab::drawTemperature(painter, rect(p[2]), theme, history_);
    const auto map = worker_.latest();
    lab::drawPlayability(painter, rect(p[3]), theme, map.get(), history_.gesture(),
                         instrumentLoaded_ ? "computing the map..." : "no instrument preset");
}

} // namespace rosin::ui
