#include "RosinProcessor.h"

#include <chrono>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <thread>

#include "RosinEditor.h"
#include "StateFormat.h"
#include "rosin/hid/Recording.h"
#include "rosin/engine/Presets.h"

// The headless host defines this (strong, exported) to count allocations and locks between
// enter (1) and exit (0) on the calling thread. In a DAW it is absent and never called.
extern "C" void rosin_audit_scope(int entering) __attribute__((weak));

namespace rosin::plugin {
namespace {
using engine::Control;
using engine::ControlEvent;
using engine::Param;
using engine::paramCount;
using engine::paramInfo;

constexpr double swapFadeSeconds = 0.01; ///< the old engine fades under the new one: no click, at any rate

double steadySeconds() noexcept
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

float engineValue(int index, float raw)
{
    const auto& info = paramInfo(index);
    return info.steps > 0 ? info.min + raw : raw; // choices arrive as an index
}

juce::String formatValue(int index, float value)
{
    const auto& info = paramInfo(index);
    const float a = std::abs(value);
    const int decimals = a >= 100.0f ? 0 : a >= 10.0f ? 1 : a >= 1.0f ? 2 : 3;
    juce::String text(value, decimals);
    if (!info.unit.empty()) text << " " << juce::String(info.unit.data(), info.unit.size());
    return text;
}
} // namespace

const juce::StringArray& RosinProcessor::instrumentNames()
{
    static const juce::StringArray names{"violin", "viola", "cello", "double-bass"};
    return names;
}

/// Off the audio thread: builds engines when the instrument parameter moves, and keeps house.
class RosinProcessor::Loader : public juce::Thread {
public:
    explicit Loader(RosinProcessor& owner) : juce::Thread("Rosin housekeeping"), owner_(owner) {}

    void run() override
    {
        while (!threadShouldExit()) {
            wait(5); // polls: the audio thread never signals (signalling takes a lock)
            owner_.housekeeping();
            owner_.pollHid();
            owner_.followInstrumentParameter();
        }
    }

private:
    RosinProcessor& owner_;
};

juce::AudioProcessorValueTreeState::ParameterLayout RosinProcessor::createLayout()
{
    juce::AudioProcessorValueTreeState::ParameterLayout layout;
    for (int i = 0; i < paramCount; ++i) {
        const auto& info = paramInfo(i);
        const juce::String id(info.id.data(), info.id.size()), name(info.name.data(), info.name.size());
        if (info.steps > 0) {
            juce::StringArray choices = juce::StringArray::fromTokens(juce::String(info.choices.data(), info.choices.size()), "|", "");
            // Spare slots keep every choice's normalised value when one is added (Parameters.h).
            const juce::String last = choices[choices.size() - 1];
            while (choices.size() < info.steps) choices.add(last + " (spare " + juce::String(choices.size() + 1) + ")");
            layout.add(std::make_unique<juce::AudioParameterChoice>(juce::ParameterID{id, 1}, name, choices, juce::roundToInt(info.def - info.min)));
            continue;
        }
        juce::NormalisableRange<float> range(info.min, info.max);
        if (info.centre > info.min && info.centre < info.max && std::abs(info.centre - 0.5f * (info.min + info.max)) > 1e-6f)
            range.setSkewForCentre(info.centre);
        auto attributes = juce::AudioParameterFloatAttributes()
                              .withLabel(juce::String(info.unit.data(), info.unit.size()))
                              .withStringFromValueFunction([i](float v, int) { return formatValue(i, v); })
                              .withValueFromStringFunction([](const juce::String& t) { return t.getFloatValue(); });
        layout.add(std::make_unique<juce::AudioParameterFloat>(juce::ParameterID{id, 1}, name, range, info.def, attributes));
    }
    layout.add(std::make_unique<juce::AudioParameterChoice>(juce::ParameterID{instrumentParamId, 1}, "Instrument", instrumentNames(), 2));
    layout.add(std::make_unique<juce::AudioParameterChoice>(juce::ParameterID{hidParamId, 1}, "HID controller", juce::StringArray{"Off", "On"}, 0));
    return layout;
}

RosinProcessor::RosinProcessor()
    : AudioProcessor(BusesProperties().withOutput("Output", juce::AudioChannelSet::stereo(), true)),
      state_(*this, nullptr, "RosinState", createLayout())
{
    for (int i = 0; i < paramCount; ++i) {
        const auto& info = paramInfo(i);
        raw_[static_cast<std::size_t>(i)] = state_.getRawParameterValue(juce::String(info.id.data(), info.id.size()));
        jassert(raw_[static_cast<std::size_t>(i)] != nullptr);
    }
    instrumentRaw_ = state_.getRawParameterValue(instrumentParamId);
    hidRaw_ = state_.getRawParameterValue(hidParamId);
    // ROSIN_HID_REPLAY=capture.hid plays a recorded controller (demonstrations, the validation
    // pass); otherwise the real devices through hidapi.
    std::unique_ptr<hid::DeviceBackend> backend;
    if (const char* replay = std::getenv("ROSIN_HID_REPLAY"); replay && *replay) {
        try {
            backend = hid::makeReplayBackend(hid::readRecording(replay), true);
        } catch (const std::exception& e) {
            stateProblem_ = juce::String("ROSIN_HID_REPLAY: ") + e.what();
        }
    }
    const bool replaying = backend != nullptr;
    hid_ = std::make_unique<hid::HidInput>(replaying ? std::move(backend) : hid::makeHidapiBackend());
    if (!replaying) hid_->watcherFactory = [] { return hid::makeLibusbWatcher(); }; // hot-plug while the input runs
    pushed_.fill(std::numeric_limits<float>::quiet_NaN());
    const int index = juce::roundToInt(instrumentRaw_->load());
    requestedInstrument_.store(index);
    settledInstrument_.store(index);
    loader_ = std::make_unique<Loader>(*this);
    loader_->startThread();
}

RosinProcessor::~RosinProcessor()
{
    loader_->stopThread(2000); // first: it is the retire queues' only consumer
    hid_->stop();
    engines_.collect();
    map_.collect();
    delete retiring_;
    delete current_;
}

engine::ParamValues RosinProcessor::currentParams() const
{
    engine::ParamValues v{};
    for (int i = 0; i < paramCount; ++i) v[static_cast<std::size_t>(i)] = engineValue(i, raw_[static_cast<std::size_t>(i)]->load());
    return v;
}

std::unique_ptr<engine::Synth> RosinProcessor::buildSynth(const presets::InstrumentPreset& preset, double sampleRate, int tag)
{
    auto synth = std::make_unique<engine::Synth>();
    synth->prepare(sampleRate, preset, currentParams());
    synth->setTag(tag);
    return synth;
}

void RosinProcessor::setPhysical(Param p, double value)
{
    // Host parameters hold choices as an index from 0; the engine's table counts from `min`.
    const auto& info = paramInfo(p);
    if (auto* param = state_.getParameter(juce::String(info.id.data(), info.id.size())))
        param->setValueNotifyingHost(param->convertTo0to1(static_cast<float>(info.steps > 0 ? value - info.min : value)));
}

void RosinProcessor::housekeeping()
{
    engines_.collect();
    map_.collect();
    // Host parameters that a learned controller or a keyswitch moved: the latest value of each,
    // so the slider, automation, the saved session and the views agree with what plays.
    // A move made on a state that has since been restored over is dropped: the restore is newer.
    std::array<float, paramCount> latest{};
    std::array<int, paramCount> count{}, stale{};
    {
        const std::lock_guard<std::mutex> lock(hostChangeMutex_);
        const std::uint32_t generation = stateGeneration_.load(std::memory_order_acquire);
        HostChange c;
        while (toHost_.pop(c))
            if (c.param >= 0 && c.param < paramCount) {
                const auto i = static_cast<std::size_t>(c.param);
                if (c.generation != generation) {
                    ++stale[i];
                    continue;
                }
                latest[i] = c.value;
                ++count[i];
            }
        for (int i = 0; i < paramCount; ++i)
            if (count[static_cast<std::size_t>(i)] > 0) setPhysical(static_cast<Param>(i), latest[static_cast<std::size_t>(i)]);
    }
    for (std::size_t i = 0; i < count.size(); ++i)
        if (count[i] + stale[i] > 0) inFlight_[i].fetch_sub(count[i] + stale[i], std::memory_order_release);
    Learn l;
    while (learned_.pop(l)) {
        const auto& info = paramInfo(l.param);
        map_.set(l.cc, l.param, info.min, info.max, false);
    }
}

void RosinProcessor::pollHid()
{
    const bool wanted = hidRaw_->load() > 0.5f;
    if (wanted && !hid_->running()) hid_->start();
    if (!wanted && hid_->running()) hid_->stop();
}

void RosinProcessor::prepareToPlay(double sampleRate, int maximumExpectedSamplesPerBlock)
{
    // The host guarantees the audio thread is stopped here: this thread stands in for it.
    const std::lock_guard<std::mutex> lock(loadMutex_);
    fadeLength_ = std::max(1, juce::roundToInt(swapFadeSeconds * sampleRate));
    fadeBuffer_.setSize(2, std::max(maximumExpectedSamplesPerBlock, fadeLength_));
    const int index = wantedInstrument();
    // A pending engine never played: it is retired (the housekeeping thread frees it).
    if (engine::Synth* pending = engines_.takePending()) {
        if (!engines_.retire(pending)) delete pending; // the queue is full: nobody else can hold it now
    }
    delete retiring_;
    retiring_ = nullptr;
    retiringLeft_ = 0;
    const bool keep = current_ != nullptr && current_->sampleRate() == sampleRate && current_->tag() == index;
    if (!keep) {
        delete current_;
        current_ = nullptr;
        instrumentName_ = instrumentNames()[index];
        try {
            current_ = buildSynth(presets::loadInstrument(library_, instrumentName_.toStdString()), sampleRate, index).release();
            enginesInstalled_.fetch_add(1, std::memory_order_relaxed);
        } catch (const std::exception& e) {
            DBG("Rosin: " << e.what()); // no engine: processBlock outputs silence
        }
    }
    if (current_) {
        current_->attach(&performance_);
        current_->setViewTap(viewRing_.get());
        if (!keep) current_->resumeHeldNotes();
    }
    requestedInstrument_.store(index);
    settledInstrument_.store(index);
    installedInstrument_ = index;
    sampleRate_.store(sampleRate);
    pushed_.fill(std::numeric_limits<float>::quiet_NaN());
    lastBlockStart_ = -1.0;
}

void RosinProcessor::releaseResources()
{
    // The stream stopped (the audio thread with it): nothing sounds or is held any more. The MPE
    // zones and bend ranges stay (a controller sends them once); the engine stays built.
    performance_.stop();
    if (current_) current_->reset();
    delete retiring_;
    retiring_ = nullptr;
    retiringLeft_ = 0;
}

bool RosinProcessor::isBusesLayoutSupported(const BusesLayout& layouts) const
{
    const auto out = layouts.getMainOutputChannelSet();
    return out == juce::AudioChannelSet::stereo() || out == juce::AudioChannelSet::mono();
}

void RosinProcessor::swapEngine() noexcept
{
    // The old engine needs a slot in the retire queue before a new one comes in.
    if (retiring_ != nullptr && retiringLeft_ <= 0 && engines_.retire(retiring_)) retiring_ = nullptr;
    if (retiring_ != nullptr || !engines_.hasPending()) return;
    engine::Synth* next = engines_.takePending();
    if (next == nullptr) return;
    if (next->sampleRate() != sampleRate_.load(std::memory_order_relaxed)) { // built for a rate that has since changed
        if (!engines_.retire(next)) retiring_ = next, retiringLeft_ = 0;
        return;
    }
    if (current_) {
        retiring_ = current_;
        retiring_->setViewTap(nullptr); // the views follow the new engine only
        retiring_->releaseAll();
        retiringLeft_ = fadeLength_;
    }
    current_ = next;
    current_->attach(&performance_);
    current_->setViewTap(viewRing_.get());
    pushParameters(*current_, true);
    current_->resumeHeldNotes(); // the player still holds them: they sound on the new instrument
    installedInstrument_ = next->tag();
    enginesInstalled_.fetch_add(1, std::memory_order_relaxed);
}

void RosinProcessor::pushParameters(engine::Synth& synth, bool all) noexcept
{
    for (int i = 0; i < paramCount; ++i) {
        const float v = raw_[static_cast<std::size_t>(i)]->load(std::memory_order_relaxed);
        // A learned controller already moved the engine; its host parameter catches up.
        if (!all && inFlight_[static_cast<std::size_t>(i)].load(std::memory_order_acquire) > 0) continue;
        if (all || v != pushed_[static_cast<std::size_t>(i)]) {
            synth.setParameter(i, engineValue(i, v));
            pushed_[static_cast<std::size_t>(i)] = v;
        }
    }
}

float RosinProcessor::engineParameter(Param p) const noexcept
{
    return current_ != nullptr ? current_->parameter(static_cast<int>(p)) : std::numeric_limits<float>::quiet_NaN();
}

void RosinProcessor::addEvent(const ControlEvent& e) noexcept
{
    if (eventCount_ >= maxBlockEvents) {
        ++droppedEvents_;
        return;
    }
    // Insertion keeps the block's events in frame order (sources arrive each in its own order).
    int at = eventCount_++;
    while (at > 0 && events_[static_cast<std::size_t>(at - 1)].frame > e.frame) {
        events_[static_cast<std::size_t>(at)] = events_[static_cast<std::size_t>(at - 1)];
        --at;
    }
    events_[static_cast<std::size_t>(at)] = e;
}

void RosinProcessor::hidEvents(int numSamples) noexcept
{
    // An event read at time t lands where t falls in the span of the previous block: one block of
    // constant latency, and the timing between events is kept.
    const double fs = sampleRate_.load(std::memory_order_relaxed);
    hid::Event h;
    while (hid_->queue().pop(h)) {
        int frame = 0;
        if (lastBlockStart_ > 0.0 && fs > 0.0)
            frame = juce::jlimit(0, numSamples - 1, static_cast<int>(std::floor((h.seconds - lastBlockStart_) * fs)));
        ControlEvent e;
        e.frame = frame;
        e.channel = 0;
        switch (h.kind) {
        case hid::Event::Kind::Bow:
            for (const auto& [kind, value] : {std::pair{Control::DirectForce, h.force}, std::pair{Control::DirectSpeed, h.speed},
                                              std::pair{Control::DirectPosition, h.position}, std::pair{Control::StringChoice, static_cast<float>(h.string)},
                                              std::pair{Control::Engage, h.engaged ? 1.0f : 0.0f}}) {
                e.kind = kind;
                e.value = value;
                addEvent(e);
            }
            break;
        case hid::Event::Kind::NoteOn:
        case hid::Event::Kind::NoteOff:
            e.kind = h.kind == hid::Event::Kind::NoteOn ? Control::NoteOn : Control::NoteOff;
            e.note = h.note;
            e.value = 100.0f / 127.0f;
            addEvent(e);
            break;
        case hid::Event::Kind::Released:
            e.kind = Control::DirectRelease;
            addEvent(e);
            break;
        }
    }
}

void RosinProcessor::gatherEvents(const juce::MidiBuffer& midi, int numSamples) noexcept
{
    eventCount_ = 0;
    const engine::ControllerTable& table = map_.acquire();
    static const engine::ParamValues defaults = engine::defaultParams();
    const engine::ParamValues& params = current_ ? current_->parameters() : defaults;
    ControlEvent out[engine::MidiDecoder::maxEvents];
    auto decode = [&](const std::uint8_t* data, int size, int frame) {
        const int n = decoder_.decode(data, size, frame, performance_, params, &table, map_.learning(), out);
        for (int k = 0; k < n; ++k) {
            if (out[k].kind == Control::Learned) {
                if (map_.claimLearn() >= 0) learned_.push({out[k].note, out[k].index});
                continue;
            }
            addEvent(out[k]);
        }
    };
    UiMidi m;
    while (uiMidi_.pop(m)) decode(m.bytes.data(), m.size, 0);
    for (const auto meta : midi) decode(meta.data, meta.numBytes, juce::jlimit(0, std::max(0, numSamples - 1), meta.samplePosition));
}

void RosinProcessor::handle(engine::Synth& synth, const ControlEvent& e) noexcept
{
    synth.apply(e);
    if (e.kind == Control::Parameter && e.index >= 0 && e.index < paramCount) {
        // The host parameter follows (the housekeeping thread moves it); until then the
        // parameter push leaves the engine's value alone.
        inFlight_[static_cast<std::size_t>(e.index)].fetch_add(1, std::memory_order_acq_rel);
        if (!toHost_.push({e.index, synth.parameter(e.index), stateGeneration_.load(std::memory_order_acquire)})) inFlight_[static_cast<std::size_t>(e.index)].fetch_sub(1, std::memory_order_acq_rel);
    }
}

void RosinProcessor::renderCurrent(float* left, float* right, int from, int to) noexcept
{
    if (right != nullptr) {
        current_->render(left + from, right + from, to - from);
        return;
    }
    // A mono bus gets both channels' mix, rendered through the fade buffer in pieces of its size.
    float* l = fadeBuffer_.getWritePointer(0);
    float* r = fadeBuffer_.getWritePointer(1);
    for (int start = from; start < to;) {
        const int len = std::min(to - start, fadeBuffer_.getNumSamples());
        current_->render(l, r, len);
        for (int i = 0; i < len; ++i) left[start + i] = 0.5f * (l[i] + r[i]);
        start += len;
    }
}

void RosinProcessor::processBlock(juce::AudioBuffer<float>& buffer, juce::MidiBuffer& midi) { process(buffer, midi, false); }

void RosinProcessor::processBlockBypassed(juce::AudioBuffer<float>& buffer, juce::MidiBuffer& midi) { process(buffer, midi, true); }

void RosinProcessor::process(juce::AudioBuffer<float>& buffer, juce::MidiBuffer& midi, bool bypassed)
{
    if (rosin_audit_scope) rosin_audit_scope(1);
    juce::ScopedNoDenormals noDenormals;
    const int n = buffer.getNumSamples();
    const double blockStart = steadySeconds();

    // Offline (a bounce, the headless host) an instrument change must land on this block, not
    // whenever the loader gets to it: wait until the loader has settled it (built, or failed),
    // without locking or allocating. Live, the old instrument plays on until the new one is ready.
    const int wanted = juce::roundToInt(instrumentRaw_->load(std::memory_order_relaxed));
    if (isNonRealtime() && wanted != installedInstrument_ && sampleRate_.load() > 0.0) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
        while (settledInstrument_.load(std::memory_order_acquire) != wanted && std::chrono::steady_clock::now() < deadline)
            std::this_thread::yield();
    }
    swapEngine();

    float* left = buffer.getWritePointer(0);
    float* right = buffer.getNumChannels() > 1 ? buffer.getWritePointer(1) : nullptr;
    for (int ch = 2; ch < buffer.getNumChannels(); ++ch) buffer.clear(ch, 0, n);
    gatherEvents(midi, n);
    hidEvents(n);
    if (current_ == nullptr || fadeBuffer_.getNumSamples() < 1) {
        // No engine (a preset that failed to load): silence, but the player's state still follows.
        for (int k = 0; k < eventCount_; ++k) performance_.apply(events_[static_cast<std::size_t>(k)]);
        buffer.clear();
    } else {
        // After a restore every parameter goes to the engine, also one whose value equals the last
        // pushed one while a controller had moved the engine away from it.
        const std::uint32_t generation = stateGeneration_.load(std::memory_order_acquire);
        pushParameters(*current_, generation != pushedGeneration_);
        pushedGeneration_ = generation;
        int pos = 0;
        for (int k = 0; k < eventCount_;) {
            const int at = std::min(n, events_[static_cast<std::size_t>(k)].frame);
            renderCurrent(left, right, pos, at);
            pos = std::max(pos, at);
            for (; k < eventCount_ && events_[static_cast<std::size_t>(k)].frame <= pos; ++k) handle(*current_, events_[static_cast<std::size_t>(k)]);
        }
        renderCurrent(left, right, pos, n);
        activeVoices_.store(current_->activeVoiceCount(), std::memory_order_relaxed);
    }

    if (retiring_ != nullptr && retiringLeft_ > 0) {
        // The old engine fades out under the new one, linearly over swapFadeSeconds.
        const int m = std::min({n, retiringLeft_, fadeBuffer_.getNumSamples()});
        float* l = fadeBuffer_.getWritePointer(0);
        float* r = fadeBuffer_.getWritePointer(1);
        retiring_->render(l, r, m);
        for (int i = 0; i < m; ++i) {
            const float g = static_cast<float>(retiringLeft_ - i) / static_cast<float>(fadeLength_);
            if (right) {
                left[i] += g * l[i];
                right[i] += g * r[i];
            } else {
                left[i] += g * 0.5f * (l[i] + r[i]);
            }
        }
        retiringLeft_ -= m;
    }
    if (retiring_ != nullptr && retiringLeft_ <= 0 && engines_.retire(retiring_)) retiring_ = nullptr;
    lastBlockStart_ = blockStart;

    // The host's bypass: the engine above went on following the keys; only its output fades.
    const float target = bypassed ? 0.0f : 1.0f;
    if (outputGain_ == 0.0f && target == 0.0f) {
        buffer.clear();
    } else if (outputGain_ != target) {
        const float step = 1.0f / static_cast<float>(fadeLength_);
        for (int i = 0; i < n; ++i) {
            outputGain_ = target > outputGain_ ? std::min(target, outputGain_ + step) : std::max(target, outputGain_ - step);
            for (int ch = 0; ch < std::min(2, buffer.getNumChannels()); ++ch) buffer.getWritePointer(ch)[i] *= outputGain_;
        }
    }

    if (rosin_audit_scope) rosin_audit_scope(0);
}

bool RosinProcessor::pushUiMidi(const std::uint8_t* data, int size) noexcept
{
    if (size < 1 || size > 3) return false;
    UiMidi m;
    std::copy(data, data + size, m.bytes.begin());
    m.size = size;
    return uiMidi_.push(m);
}

juce::AudioProcessorEditor* RosinProcessor::createEditor() { return new ui::RosinEditor(*this); }

} // namespace rosin::plugin

juce::AudioProcessor* JUCE_CALLTYPE createPluginFilter() { return new rosin::plugin::RosinProcessor(); }
