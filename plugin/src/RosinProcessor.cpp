#include "RosinProcessor.h"

#include <chrono>
#include <thread>

#include <cmath>
#include <limits>

#include "rosin/engine/Presets.h"
#include "RosinEditor.h"

// The headless host defines this (strong, exported) to count allocations and locks between
// enter (1) and exit (0) on the calling thread. In a DAW it is absent and never called.
extern "C" void rosin_audit_scope(int entering) __attribute__((weak));

namespace rosin::plugin {
namespace {
using engine::Param;
using engine::paramCount;
using engine::paramInfo;

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

/// Off the audio thread: builds engines when the instrument parameter moves, frees retired ones.
class RosinProcessor::Loader : public juce::Thread {
public:
    explicit Loader(RosinProcessor& owner) : juce::Thread("Rosin preset loader"), owner_(owner) {}

    void run() override
    {
        while (!threadShouldExit()) {
            wait(20); // polls: the audio thread never signals (signalling takes a lock)
            owner_.collectGarbage();
            owner_.pollHid();
            const double rate = owner_.sampleRate_.load();
            const int wanted = juce::roundToInt(owner_.instrumentRaw_->load());
            if (rate > 0.0 && wanted != owner_.loadedInstrument_.load()) {
                try {
                    owner_.loadInstrument(instrumentNames()[wanted], false);
                } catch (const std::exception& e) {
                    DBG("Rosin: " << e.what());
                    owner_.loadedInstrument_.store(wanted); // do not retry a broken file every 20 ms
                }
            }
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
            const juce::StringArray choices = juce::StringArray::fromTokens(juce::String(info.choices.data(), info.choices.size()), "|", "");
            layout.add(std::make_unique<juce::AudioParameterChoice>(juce::ParameterID{id, 1}, name, choices,
                                                                     juce::roundToInt(info.def - info.min)));
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
    layout.add(std::make_unique<juce::AudioParameterChoice>(juce::ParameterID{instrumentParamId, 1}, "Instrument",
                                                             instrumentNames(), 2));
    layout.add(std::make_unique<juce::AudioParameterChoice>(juce::ParameterID{hidParamId, 1}, "HID controller",
                                                             juce::StringArray{"Off", "On"}, 0));
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
    hid_ = std::make_unique<hid::HidInput>(hid::makeHidapiBackend());
    pushed_.fill(std::numeric_limits<float>::quiet_NaN());
    loadedInstrument_.store(juce::roundToInt(instrumentRaw_->load()));
    loader_ = std::make_unique<Loader>(*this);
    loader_->startThread();
}

RosinProcessor::~RosinProcessor()
{
    loader_->stopThread(2000);
    hid_->stop();
    collectGarbage();
    delete pending_.exchange(nullptr);
    delete retiring_;
    delete current_;
}

engine::ParamValues RosinProcessor::currentParams() const
{
    engine::ParamValues v{};
    for (int i = 0; i < paramCount; ++i) v[static_cast<std::size_t>(i)] = engineValue(i, raw_[static_cast<std::size_t>(i)]->load());
    return v;
}

std::unique_ptr<engine::Synth> RosinProcessor::buildSynth(const engine::InstrumentPreset& preset, double sampleRate, int tag)
{
    auto synth = std::make_unique<engine::Synth>();
    synth->prepare(sampleRate, preset, currentParams(), &map_);
    synth->setTag(tag);
    synth->setViewTap(viewRing_.get()); // the window's views follow whichever engine plays
    return synth;
}

void RosinProcessor::handOver(std::unique_ptr<engine::Synth> synth)
{
    // A pending engine the audio thread has not taken yet never played: free it here.
    delete pending_.exchange(synth.release(), std::memory_order_acq_rel);
}

void RosinProcessor::collectGarbage()
{
    engine::Synth* old = nullptr;
    while (trash_.pop(old)) delete old;
}

void RosinProcessor::setPhysical(engine::Param p, double value)
{
    // Host parameters hold choices as an index from 0; the engine's table counts from `min`.
    const auto& info = paramInfo(p);
    if (auto* param = state_.getParameter(juce::String(info.id.data(), info.id.size())))
        param->setValueNotifyingHost(param->convertTo0to1(static_cast<float>(info.steps > 0 ? value - info.min : value)));
}

void RosinProcessor::pollHid()
{
    const bool wanted = hidRaw_->load() > 0.5f;
    if (wanted && !hid_->running()) hid_->start();
    if (!wanted && hid_->running()) hid_->stop();
}

void RosinProcessor::loadHidMapping(const juce::String& name)
{
    hid_->setMapping(hid::HidMapping::fromDocument(library_.open("controllers", name.toStdString(), "rosin-hid/1")));
}

void RosinProcessor::drainHid(engine::Synth& synth) noexcept
{
    // Every note trigger counts; for the bow only the latest state matters.
    hid::BowCommand c;
    bool got = false;
    while (hid_->queue().pop(c)) {
        got = true;
        for (int off : {static_cast<int>(c.noteOff), static_cast<int>(c.noteOff2)})
            if (off >= 0) {
                const std::uint8_t msg[3] = {0x80, static_cast<std::uint8_t>(off), 0};
                synth.handleMidi(msg, 3);
            }
        for (int on : {static_cast<int>(c.noteOn), static_cast<int>(c.noteOn2)})
            if (on >= 0) {
                const std::uint8_t msg[3] = {0x90, static_cast<std::uint8_t>(on), 100};
                synth.handleMidi(msg, 3);
            }
        external_ = {true, c.engaged, c.force, c.speed, c.beta, c.string};
    }
    if (!hid_->running() && external_.active) { // switched off: the parameters play again
        external_ = {};
        got = true;
    }
    if (got) synth.setExternalBow(external_);
}

void RosinProcessor::loadInstrument(const juce::String& name, bool applyDefaults)
{
    const std::lock_guard<std::mutex> lock(loadMutex_);
    const int index = instrumentNames().indexOf(name);
    const auto preset = presets::loadInstrument(library_, name.toStdString());
    if (applyDefaults) {
        setPhysical(Param::BowForce, preset.bowForce);
        setPhysical(Param::BowSpeed, preset.bowSpeed);
        setPhysical(Param::BowPosition, preset.bowPosition);
        setPhysical(Param::AttackAccel, preset.attackAccel);
        setPhysical(Param::RosinTg, preset.rosinTg);
    }
    if (index >= 0) {
        if (auto* param = state_.getParameter(instrumentParamId))
            if (juce::roundToInt(instrumentRaw_->load()) != index)
                param->setValueNotifyingHost(param->convertTo0to1(static_cast<float>(index)));
        loadedInstrument_.store(index);
    }
    instrumentName_ = name;
    const double rate = sampleRate_.load();
    if (rate > 0.0) {
        collectGarbage();
        handOver(buildSynth(preset, rate, index));
    }
}

void RosinProcessor::loadExciter(const juce::String& name)
{
    const auto e = presets::loadExciter(library_, name.toStdString());
    setPhysical(Param::FrictionModel, static_cast<int>(e.model));
    setPhysical(Param::ContactLaw, e.contact == dsp::ContactLaw::PowerLaw ? 1.0 : 0.0);
    setPhysical(Param::Footprint, e.footprintRatio);
    setPhysical(Param::Ambient, e.ambient);
}

void RosinProcessor::loadMapping(const juce::String& name)
{
    const auto m = engine::loadControllerMap(library_, name.toStdString());
    map_.assign(m.entries);
    if (m.mpeGiven) setPhysical(Param::Mpe, m.mpe ? 1.0 : 0.0);
    if (m.articulation >= 0) setPhysical(Param::Articulation, m.articulation);
    if (m.articulationChannels >= 0) setPhysical(Param::ArticulationChannels, m.articulationChannels);
}

juce::String RosinProcessor::currentInstrument() const
{
    const std::lock_guard<std::mutex> lock(loadMutex_);
    return instrumentName_;
}

void RosinProcessor::prepareToPlay(double sampleRate, int maximumExpectedSamplesPerBlock)
{
    // The host guarantees the audio thread is stopped here: install directly.
    const std::lock_guard<std::mutex> lock(loadMutex_);
    delete pending_.exchange(nullptr);
    collectGarbage();
    delete retiring_;
    retiring_ = nullptr;
    delete current_;
    current_ = nullptr;
    const int index = juce::jlimit(0, instrumentNames().size() - 1, juce::roundToInt(instrumentRaw_->load()));
    instrumentName_ = instrumentNames()[index];
    try {
        const auto preset = presets::loadInstrument(library_, instrumentName_.toStdString());
        current_ = buildSynth(preset, sampleRate, index).release();
    } catch (const std::exception& e) {
        DBG("Rosin: " << e.what()); // no engine: processBlock outputs silence
    }
    loadedInstrument_.store(index);
    installedInstrument_ = index;
    sampleRate_.store(sampleRate);
    pushed_.fill(std::numeric_limits<float>::quiet_NaN());
    fadeBuffer_.setSize(2, std::max(maximumExpectedSamplesPerBlock, fadeSamples));
}

void RosinProcessor::releaseResources() {}

bool RosinProcessor::isBusesLayoutSupported(const BusesLayout& layouts) const
{
    return layouts.getMainOutputChannelSet() == juce::AudioChannelSet::stereo();
}

void RosinProcessor::renderSynth(engine::Synth& synth, juce::AudioBuffer<float>& buffer, const juce::MidiBuffer* midi,
                                 bool pushParams) noexcept
{
    if (pushParams)
        for (int i = 0; i < paramCount; ++i) {
            const float v = raw_[static_cast<std::size_t>(i)]->load(std::memory_order_relaxed);
            if (v != pushed_[static_cast<std::size_t>(i)]) {
                synth.setParameter(i, engineValue(i, v));
                pushed_[static_cast<std::size_t>(i)] = v;
            }
        }
    const int n = buffer.getNumSamples();
    float* left = buffer.getWritePointer(0);
    float* right = buffer.getWritePointer(1);
    int pos = 0;
    if (midi)
        for (const auto meta : *midi) {
            const int at = juce::jlimit(pos, n, meta.samplePosition);
            synth.render(left + pos, right + pos, at - pos);
            pos = at;
            synth.handleMidi(meta.data, meta.numBytes);
        }
    synth.render(left + pos, right + pos, n - pos);
}

void RosinProcessor::processBlock(juce::AudioBuffer<float>& buffer, juce::MidiBuffer& midi)
{
    if (rosin_audit_scope) rosin_audit_scope(1);
    juce::ScopedNoDenormals noDenormals;
    const int n = buffer.getNumSamples();
    for (int ch = 2; ch < buffer.getNumChannels(); ++ch) buffer.clear(ch, 0, n);

    // Offline (a bounce, the headless host) an instrument change must land on this block, not
    // whenever the loader gets to it: wait for the loader without locking or allocating. Live,
    // the old instrument plays on until the new one is ready.
    const int wanted = juce::roundToInt(instrumentRaw_->load(std::memory_order_relaxed));
    if (isNonRealtime() && wanted != installedInstrument_ && sampleRate_.load() > 0.0) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
        for (;;) {
            const engine::Synth* p = pending_.load(std::memory_order_acquire);
            if ((p != nullptr && p->tag() == wanted) || std::chrono::steady_clock::now() >= deadline) break;
            std::this_thread::yield();
        }
    }
    if (engine::Synth* next = pending_.load(std::memory_order_acquire)) {
        // Room to retire the current engine? (The loader empties the queue every 20 ms.)
        bool room = true;
        if (retiring_ != nullptr) {
            room = trash_.push(retiring_);
            if (room) retiring_ = nullptr;
        }
        if (room && pending_.compare_exchange_strong(next, nullptr, std::memory_order_acq_rel)) {
            if (current_) {
                retiring_ = current_;
                retiring_->setViewTap(nullptr); // the views follow the new engine only
                retiring_->releaseAll();
                retiringLeft_ = fadeSamples;
            }
            current_ = next;
            current_->setExternalBow(external_);
            installedInstrument_ = next->tag();
            pushed_.fill(std::numeric_limits<float>::quiet_NaN());
        }
    }

    if (current_ == nullptr || buffer.getNumChannels() < 2) {
        buffer.clear();
    } else {
        drainHid(*current_);
        UiMidi m;
        while (uiMidi_.pop(m)) current_->handleMidi(m.bytes.data(), m.size);
        renderSynth(*current_, buffer, &midi, true);
        activeVoices_.store(current_->activeVoiceCount(), std::memory_order_relaxed);
    }

    if (retiring_ != nullptr && retiringLeft_ > 0 && fadeBuffer_.getNumSamples() > 0) {
        // The old engine fades out (linearly, fadeSamples) under the new one: no click on a swap.
        const int m = std::min({n, retiringLeft_, fadeBuffer_.getNumSamples()});
        float* l = fadeBuffer_.getWritePointer(0);
        float* r = fadeBuffer_.getWritePointer(1);
        retiring_->render(l, r, m);
        for (int i = 0; i < m; ++i) {
            const float g = static_cast<float>(retiringLeft_ - i) / static_cast<float>(fadeSamples);
            if (buffer.getNumChannels() > 1) {
                buffer.addSample(0, i, g * l[i]);
                buffer.addSample(1, i, g * r[i]);
            }
        }
        retiringLeft_ -= m;
    }
    if (retiring_ != nullptr && retiringLeft_ <= 0 && trash_.push(retiring_)) retiring_ = nullptr;

    if (rosin_audit_scope) rosin_audit_scope(0);
}

void RosinProcessor::getStateInformation(juce::MemoryBlock& destData)
{
    auto tree = state_.copyState();
    std::unique_ptr<juce::XmlElement> xml(tree.createXml());
    xml->setAttribute("format", "rosin-state/1");
    auto* maps = xml->createNewChildElement("Mappings");
    for (const auto& e : map_.entries()) {
        auto* m = maps->createNewChildElement("Map");
        m->setAttribute("cc", e.cc);
        const auto& info = paramInfo(e.param);
        m->setAttribute("param", juce::String(info.id.data(), info.id.size()));
        m->setAttribute("min", static_cast<double>(e.min));
        m->setAttribute("max", static_cast<double>(e.max));
        m->setAttribute("invert", e.invert);
    }
    auto* hidXml = xml->createNewChildElement("Hid");
    for (auto kind : {hid::DeviceKind::Tablet, hid::DeviceKind::Gamepad, hid::DeviceKind::SpaceMouse, hid::DeviceKind::Joystick})
        hidXml->createNewChildElement("Mapping")->addTextElement(hid_->mapping(kind).toJson());
    copyXmlToBinary(*xml, destData);
}

void RosinProcessor::setStateInformation(const void* data, int sizeInBytes)
{
    std::unique_ptr<juce::XmlElement> xml(getXmlFromBinary(data, sizeInBytes));
    if (xml == nullptr || !xml->hasTagName(state_.state.getType())) return; // not ours: keep the current state
    std::vector<engine::MappingEntry> entries;
    if (auto* maps = xml->getChildByName("Mappings")) {
        for (auto* m : maps->getChildIterator()) {
            engine::MappingEntry e;
            e.cc = m->getIntAttribute("cc", -1);
            e.param = engine::paramIndex(m->getStringAttribute("param").toStdString());
            e.min = static_cast<float>(m->getDoubleAttribute("min"));
            e.max = static_cast<float>(m->getDoubleAttribute("max"));
            e.invert = m->getBoolAttribute("invert");
            if (e.cc >= 0 && e.cc < engine::ControllerMap::numControllers && e.param >= 0) entries.push_back(e);
        }
        xml->removeChildElement(maps, true);
    }
    if (auto* hidXml = xml->getChildByName("Hid")) {
        for (auto* m : hidXml->getChildIterator()) {
            try {
                hid_->setMapping(hid::HidMapping::fromJson(m->getAllSubText().toStdString(), "saved state"));
            } catch (const std::exception& e) {
                DBG("Rosin: " << e.what()); // keep the default map for that device
            }
        }
        xml->removeChildElement(hidXml, true);
    }
    xml->removeAttribute("format");
    state_.replaceState(juce::ValueTree::fromXml(*xml));
    map_.assign(entries);
    const int index = juce::jlimit(0, instrumentNames().size() - 1, juce::roundToInt(instrumentRaw_->load()));
    try {
        loadInstrument(instrumentNames()[index], false);
    } catch (const std::exception& e) {
        DBG("Rosin: " << e.what());
    }
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
