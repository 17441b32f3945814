// What the message and housekeeping threads load into the processor: instrument, exciter and
// controller presets, HID maps, and the plugin's saved state. None of it runs on the audio
// thread; a new engine reaches it only through the pointer hand-off (engines_.publish).
#include "RosinProcessor.h"

#include "StateFormat.h"
#include "rosin/engine/Presets.h"

namespace rosin::plugin {
using engine::Param;
using engine::paramInfo;

void RosinProcessor::loadHidMapping(const juce::String& name)
{
    hid_->setMapping(hid::HidMapping::fromDocument(library_.open("controllers", name.toStdString(), "")));
}

int RosinProcessor::wantedInstrument() const noexcept
{
    return juce::jlimit(0, instrumentNames().size() - 1, juce::roundToInt(instrumentRaw_->load()));
}

void RosinProcessor::followInstrumentParameter()
{
    if (sampleRate_.load() <= 0.0 || wantedInstrument() == requestedInstrument_.load()) return;
    const std::lock_guard<std::mutex> lock(loadMutex_);
    // Asked again under the lock: a preset loaded meanwhile by another thread has moved the
    // parameter with it, and a value read before that load would undo the preset.
    const int wanted = wantedInstrument();
    if (wanted == requestedInstrument_.load()) return;
    try {
        loadInstrumentLocked(instrumentNames()[wanted], false);
    } catch (const std::exception& e) {
        DBG("Rosin: " << e.what());
        requestedInstrument_.store(wanted); // do not retry a broken file every few ms
        settledInstrument_.store(wanted);   // an offline render must not wait for it
    }
}

void RosinProcessor::loadInstrument(const juce::String& name, bool applyDefaults)
{
    const std::lock_guard<std::mutex> lock(loadMutex_);
    loadInstrumentLocked(name, applyDefaults);
}

void RosinProcessor::loadInstrumentLocked(const juce::String& name, bool applyDefaults)
{
    const int index = instrumentNames().indexOf(name);
    if (index >= 0) requestedInstrument_.store(index);
    const auto preset = presets::loadInstrument(library_, name.toStdString());
    if (applyDefaults) {
        setPhysical(Param::BowForce, preset.bowForce);
        setPhysical(Param::BowSpeed, preset.bowSpeed);
        setPhysical(Param::BowPosition, preset.bowPosition);
        setPhysical(Param::AttackAccel, preset.attackAccel);
        setPhysical(Param::RosinTg, preset.rosinTg);
    }
    if (index >= 0)
        if (auto* param = state_.getParameter(instrumentParamId))
            if (juce::roundToInt(instrumentRaw_->load()) != index) param->setValueNotifyingHost(param->convertTo0to1(static_cast<float>(index)));
    instrumentName_ = name;
    const double rate = sampleRate_.load();
    if (rate > 0.0) engines_.publish(buildSynth(preset, rate, index), index);
    if (index >= 0) settledInstrument_.store(index);
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

juce::String RosinProcessor::lastStateProblem() const
{
    const std::lock_guard<std::mutex> lock(loadMutex_);
    return stateProblem_;
}

void RosinProcessor::getStateInformation(juce::MemoryBlock& destData)
{
    auto tree = state_.copyState();
    std::unique_ptr<juce::XmlElement> xml(tree.createXml());
    xml->setAttribute("format", "rosin-state/" + juce::String(stateVersion));
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
    state::LoadedState loaded = state::read(data, sizeInBytes, state_.state.getType().toString(), stateVersion);
    if (loaded.tree == nullptr) { // not ours, or from a newer build: keep the current state
        DBG("Rosin: " << loaded.problem);
        const std::lock_guard<std::mutex> lock(loadMutex_);
        stateProblem_ = loaded.problem;
        return;
    }
    for (const auto& m : loaded.hidMappings) hid_->setMapping(m);
    const int before = juce::roundToInt(instrumentRaw_->load());
    {
        // Controller moves still on their way to the host parameters belong to the state being
        // replaced: they are dropped, and the engine takes every restored value at the next block.
        const std::lock_guard<std::mutex> lock(hostChangeMutex_);
        state_.replaceState(juce::ValueTree::fromXml(*loaded.tree));
        stateGeneration_.fetch_add(1, std::memory_order_acq_rel);
    }
    map_.assign(loaded.mappings);
    {
        const std::lock_guard<std::mutex> lock(loadMutex_);
        stateProblem_ = loaded.problem; // what was skipped (a broken HID map), else empty
    }
    // The same instrument keeps its engine (and what it is playing): the parameters reach it
    // through the next block's push. Another instrument is built and swapped in.
    const int index = wantedInstrument();
    if (index == before && requestedInstrument_.load() == index) return;
    try {
        loadInstrument(instrumentNames()[index], false);
    } catch (const std::exception& e) {
        DBG("Rosin: " << e.what());
        settledInstrument_.store(index);
    }
}

} // namespace rosin::plugin
