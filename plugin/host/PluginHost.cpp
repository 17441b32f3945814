#include "PluginHost.h"

#include <juce_audio_formats/juce_audio_formats.h>
#include <juce_audio_processors/juce_audio_processors.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "AuditCounter.h"

namespace rosin::host {
namespace fs = std::filesystem;

struct PluginHost::Impl {
    juce::ScopedJuceInitialiser_GUI juce; // message manager on this thread: plugin creation needs it
    juce::AudioPluginFormatManager formats;
    std::unique_ptr<juce::AudioPluginInstance> plugin;
    juce::MemoryBlock initialState;
    juce::AudioBuffer<float> stream;
    juce::MidiBuffer streamMidi;
    std::string format;

    /// A parameter by the plugin's own ID. Formats spell it differently: VST3 hosts see JUCE's
    /// 31-bit hash of the ID, LV2 a "des:URI:ID" designation; both are matched here.
    juce::AudioProcessorParameter* find(const std::string& id) const
    {
        const juce::String wanted(id);
        const juce::String hashed(static_cast<int>(static_cast<juce::uint32>(wanted.hashCode()) & 0x7fffffffu));
        for (auto* p : plugin->getParameters())
            if (auto* hosted = dynamic_cast<juce::HostedAudioProcessorParameter*>(p)) {
                const juce::String pid = hosted->getParameterID();
                if (pid == wanted || pid == hashed || pid.endsWith(":" + wanted)) return p;
            }
        // LV2 and some wrappers name ports by symbol: fall back to the parameter's name.
        for (auto* p : plugin->getParameters())
            if (p->getName(256).toStdString() == id) return p;
        return nullptr;
    }
};

PluginHost::PluginHost(const fs::path& path) : impl_(std::make_unique<Impl>())
{
    if (!fs::exists(path)) throw std::runtime_error(path.string() + ": no such plugin bundle");
    juce::OwnedArray<juce::PluginDescription> types;
    const juce::File bundle(fs::absolute(path).string());
    if (path.extension() == ".lv2") {
        auto* lv2 = new juce::LV2PluginFormat();
        impl_->formats.addFormat(lv2);
        // LV2 plugins are found by URI after a search of the folder holding the bundle.
        const auto uris = lv2->searchPathsForPlugins(juce::FileSearchPath(bundle.getParentDirectory().getFullPathName()), false, false);
        for (const auto& uri : uris) lv2->findAllTypesForFile(types, uri);
        impl_->format = "LV2";
    } else if (path.extension() == ".vst3") {
        auto* vst3 = new juce::VST3PluginFormat();
        impl_->formats.addFormat(vst3);
        vst3->findAllTypesForFile(types, bundle.getFullPathName());
        impl_->format = "VST3";
    } else {
        throw std::runtime_error(path.string() + ": not a .vst3 or .lv2 bundle");
    }
    if (types.isEmpty()) throw std::runtime_error(path.string() + ": no plugin found in the bundle");
    juce::String error;
    impl_->plugin = impl_->formats.createPluginInstance(*types[0], 48000.0, 512, error);
    if (!impl_->plugin) throw std::runtime_error(path.string() + ": cannot load (" + error.toStdString() + ")");
    impl_->plugin->enableAllBuses();
    impl_->plugin->getStateInformation(impl_->initialState);
}

PluginHost::~PluginHost()
{
    if (impl_->plugin) impl_->plugin->releaseResources();
    impl_->plugin.reset();
}

std::string PluginHost::formatName() const { return impl_->format; }
std::string PluginHost::pluginName() const { return impl_->plugin->getName().toStdString(); }

std::vector<HostedParam> PluginHost::parameters() const
{
    std::vector<HostedParam> out;
    for (auto* p : impl_->plugin->getParameters()) {
        HostedParam h;
        if (auto* hosted = dynamic_cast<juce::HostedAudioProcessorParameter*>(p)) h.id = hosted->getParameterID().toStdString();
        h.name = p->getName(256).toStdString();
        h.normalised = p->getValue();
        h.defaultNormalised = p->getDefaultValue();
        h.text = p->getCurrentValueAsText().toStdString();
        h.steps = p->isDiscrete() || p->isBoolean() ? p->getNumSteps() : 0;
        out.push_back(h);
    }
    return out;
}

void PluginHost::setParameter(const std::string& id, const std::string& value)
{
    auto* p = impl_->find(id);
    if (!p) throw std::runtime_error("no parameter '" + id + "' in " + pluginName());
    float v = 0.0f;
    if (!value.empty() && value[0] == '@') v = std::stof(value.substr(1));
    else v = p->getValueForText(juce::String(value));
    if (!std::isfinite(v)) throw std::runtime_error("parameter '" + id + "': value '" + value + "' is not a number");
    p->setValueNotifyingHost(std::clamp(v, 0.0f, 1.0f));
}

std::vector<std::string> PluginHost::choices(const std::string& id) const
{
    auto* p = impl_->find(id);
    if (!p) throw std::runtime_error("no parameter '" + id + "' in " + pluginName());
    std::vector<std::string> out;
    for (const auto& s : p->getAllValueStrings()) out.push_back(s.toStdString());
    if (out.empty()) // no list from the format: ask for the text of each step
        for (int i = 0, n = std::max(2, p->getNumSteps()); i < n; ++i) out.push_back(p->getText(static_cast<float>(i) / static_cast<float>(n - 1), 256).toStdString());
    return out;
}

HostedParam PluginHost::parameter(const std::string& id) const
{
    auto* p = impl_->find(id);
    if (!p) throw std::runtime_error("no parameter '" + id + "' in " + pluginName());
    HostedParam h;
    h.id = id;
    h.name = p->getName(256).toStdString();
    h.normalised = p->getValue();
    h.defaultNormalised = p->getDefaultValue();
    h.text = p->getCurrentValueAsText().toStdString();
    h.steps = p->isDiscrete() || p->isBoolean() ? p->getNumSteps() : 0;
    return h;
}

float PluginHost::getParameter(const std::string& id) const
{
    auto* p = impl_->find(id);
    if (!p) throw std::runtime_error("no parameter '" + id + "'");
    return p->getValue();
}

std::vector<char> PluginHost::getState() const
{
    juce::MemoryBlock block;
    impl_->plugin->getStateInformation(block);
    const char* d = static_cast<const char*>(block.getData());
    return {d, d + block.getSize()};
}

void PluginHost::setState(const std::vector<char>& state)
{
    impl_->plugin->setStateInformation(state.data(), static_cast<int>(state.size()));
}

void PluginHost::restoreInitialState()
{
    impl_->plugin->setStateInformation(impl_->initialState.getData(), static_cast<int>(impl_->initialState.getSize()));
}

RenderResult PluginHost::render(const RenderRequest& req)
{
    if (!(req.sampleRate >= 8000.0 && req.sampleRate <= 768000.0)) throw std::runtime_error("sample rate out of range");
    if (req.blockSize < 1 || req.blockSize > 65536) throw std::runtime_error("block size must be 1-65536");
    auto& plugin = *impl_->plugin;
    plugin.setNonRealtime(true);
    plugin.setPlayConfigDetails(0, 2, req.sampleRate, req.blockSize);
    plugin.prepareToPlay(req.sampleRate, req.blockSize);

    const auto total = static_cast<std::int64_t>(std::llround(req.seconds * req.sampleRate));
    RenderResult result;
    result.left.resize(static_cast<std::size_t>(total));
    result.right.resize(static_cast<std::size_t>(total));

    // Events by sample, sorted; automation by the block it falls in.
    struct Frame { std::int64_t frame; const TimedMidi* msg; };
    std::vector<Frame> events;
    for (const auto& m : req.midi) events.push_back({std::llround(m.seconds * req.sampleRate), &m});
    std::stable_sort(events.begin(), events.end(), [](const Frame& a, const Frame& b) { return a.frame < b.frame; });
    std::vector<std::pair<std::int64_t, const Automation*>> autos;
    for (const auto& a : req.automation) {
        if (!impl_->find(a.paramId)) throw std::runtime_error("automation: no parameter '" + a.paramId + "'");
        autos.push_back({std::llround(a.seconds * req.sampleRate), &a});
    }
    std::stable_sort(autos.begin(), autos.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

    const int channels = std::max(2, std::max(plugin.getTotalNumInputChannels(), plugin.getTotalNumOutputChannels()));
    juce::AudioBuffer<float> buffer(channels, req.blockSize);
    juce::MidiBuffer midi;
    midi.ensureSize(4096);
    std::size_t nextEvent = 0, nextAuto = 0;
    audit::reset();
    for (std::int64_t start = 0; start < total; start += req.blockSize) {
        const int n = static_cast<int>(std::min<std::int64_t>(req.blockSize, total - start));
        while (nextAuto < autos.size() && autos[nextAuto].first < start + n) {
            impl_->find(autos[nextAuto].second->paramId)->setValueNotifyingHost(std::clamp(autos[nextAuto].second->normalised, 0.0f, 1.0f));
            ++nextAuto;
        }
        midi.clear();
        while (nextEvent < events.size() && events[nextEvent].frame < start + n) {
            const auto& b = events[nextEvent].msg->bytes;
            midi.addEvent(b.data(), static_cast<int>(b.size()), static_cast<int>(std::max<std::int64_t>(0, events[nextEvent].frame - start)));
            ++nextEvent;
        }
        buffer.setSize(channels, n, false, false, true);
        buffer.clear();
        if (req.audit) audit::enterCall();
        plugin.processBlock(buffer, midi);
        if (req.audit) audit::exitCall();
        std::copy_n(buffer.getReadPointer(0), n, result.left.begin() + start);
        std::copy_n(buffer.getReadPointer(1), n, result.right.begin() + start);
        ++result.audit.blocks;
    }
    const audit::Counts c = audit::read();
    if (req.audit) {
        result.audit.plugin = c.plugin;
        result.audit.call = c.call;
    }
    result.audit.pluginScopeSeen = c.scopeSeen;
    plugin.releaseResources();
    return result;
}

void PluginHost::startStream(double sampleRate, int maxBlock, bool realtime, int outputChannels)
{
    auto& plugin = *impl_->plugin;
    auto layout = plugin.getBusesLayout();
    if (layout.outputBuses.isEmpty()) throw std::runtime_error(pluginName() + ": no output bus");
    layout.outputBuses.getReference(0) = outputChannels == 1 ? juce::AudioChannelSet::mono() : juce::AudioChannelSet::stereo();
    if (!plugin.setBusesLayout(layout))
        throw std::runtime_error(pluginName() + " (" + impl_->format + ") refuses " + (outputChannels == 1 ? "a mono" : "a stereo") + " output");
    plugin.setNonRealtime(!realtime);
    plugin.setPlayConfigDetails(0, outputChannels, sampleRate, maxBlock);
    plugin.prepareToPlay(sampleRate, maxBlock);
    impl_->stream.setSize(std::max(2, plugin.getTotalNumOutputChannels()), maxBlock);
    impl_->streamMidi.ensureSize(4096);
}

void PluginHost::processStream(int n, const std::vector<std::pair<int, std::vector<std::uint8_t>>>& midi, float* left, float* right,
                               bool audited)
{
    auto& buffer = impl_->stream;
    buffer.setSize(buffer.getNumChannels(), n, false, false, true);
    buffer.clear();
    impl_->streamMidi.clear();
    for (const auto& [frame, bytes] : midi) impl_->streamMidi.addEvent(bytes.data(), static_cast<int>(bytes.size()), std::clamp(frame, 0, n - 1));
    if (audited) audit::enterCall();
    impl_->plugin->processBlock(buffer, impl_->streamMidi);
    if (audited) audit::exitCall();
    std::copy_n(buffer.getReadPointer(0), n, left);
    if (right) std::copy_n(buffer.getReadPointer(impl_->plugin->getTotalNumOutputChannels() > 1 ? 1 : 0), n, right);
}

void PluginHost::stopStream() { impl_->plugin->releaseResources(); }

int PluginHost::parameterCount() const { return impl_->plugin->getParameters().size(); }

int PluginHost::bypassParameterIndex() const
{
    auto* bypass = impl_->plugin->getBypassParameter();
    return bypass != nullptr ? impl_->plugin->getParameters().indexOf(bypass) : -1;
}

int PluginHost::parameterIndex(const std::string& id) const
{
    auto* p = impl_->find(id);
    return p != nullptr ? impl_->plugin->getParameters().indexOf(p) : -1;
}

void PluginHost::setParameterNormalised(int index, float value)
{
    const auto& params = impl_->plugin->getParameters();
    if (index < 0 || index >= params.size()) throw std::runtime_error("no parameter " + std::to_string(index));
    params[index]->setValueNotifyingHost(std::clamp(value, 0.0f, 1.0f));
}

std::vector<char> editRosinState(const std::vector<char>& hostState, const std::function<std::string(const std::string&)>& edit)
{
    // Both formats carry the processor's state as JUCE base64 ("size.chars"): inside the VST3
    // state's IComponent element, or as the LV2 state's StateString literal.
    auto editText = [&](juce::String text, bool& done) {
        juce::String out;
        int at = 0;
        while (at < text.length()) {
            const int dot = text.indexOfChar(at, '.');
            if (dot < 0) break;
            int start = dot;
            while (start > 0 && juce::CharacterFunctions::isDigit(text[start - 1])) --start;
            int end = dot + 1;
            while (end < text.length() && (juce::CharacterFunctions::isLetterOrDigit(text[end]) || text[end] == '.' || text[end] == '+')) ++end;
            juce::MemoryBlock block;
            if (start < dot && end - dot > 16 && block.fromBase64Encoding(text.substring(start, end))) {
                if (auto xml = juce::AudioProcessor::getXmlFromBinary(block.getData(), static_cast<int>(block.getSize()));
                    xml && xml->hasTagName("RosinState")) {
                    std::unique_ptr<juce::XmlElement> edited(juce::XmlDocument::parse(juce::String(edit(xml->toString().toStdString()))));
                    if (!edited) throw std::runtime_error("editRosinState: the edited state is not XML");
                    juce::MemoryBlock again;
                    juce::AudioProcessor::copyXmlToBinary(*edited, again);
                    out += text.substring(at, start) + again.toBase64Encoding();
                    at = end;
                    done = true;
                    continue;
                }
            }
            out += text.substring(at, dot + 1);
            at = dot + 1;
        }
        return out + text.substring(at);
    };
    bool done = false;
    std::vector<char> result;
    if (auto outer = juce::AudioProcessor::getXmlFromBinary(hostState.data(), static_cast<int>(hostState.size()))) {
        for (auto* e : outer->getChildIterator())
            if (e->getFirstChildElement() != nullptr && e->getFirstChildElement()->isTextElement() && e->getAllSubText().length() > 16) {
                const juce::String text = editText(e->getAllSubText(), done);
                e->deleteAllTextElements();
                e->addTextElement(text);
            }
        juce::MemoryBlock block;
        juce::AudioProcessor::copyXmlToBinary(*outer, block);
        result.assign(static_cast<const char*>(block.getData()), static_cast<const char*>(block.getData()) + block.getSize());
    } else {
        const juce::String text = editText(juce::String::fromUTF8(hostState.data(), static_cast<int>(hostState.size())), done);
        const std::string s = text.toStdString();
        result.assign(s.begin(), s.end());
    }
    if (!done) throw std::runtime_error("editRosinState: no Rosin state inside the host state");
    return result;
}

BenchResult PluginHost::bench(double sampleRate, int blockSize, double seconds, int reps, double warmup,
                              const std::vector<TimedMidi>& midiIn)
{
    auto& plugin = *impl_->plugin;
    plugin.setNonRealtime(false);
    plugin.setPlayConfigDetails(0, 2, sampleRate, blockSize);
    plugin.prepareToPlay(sampleRate, blockSize);
    juce::AudioBuffer<float> buffer(2, blockSize);
    juce::MidiBuffer midi, empty;
    for (const auto& m : midiIn) midi.addEvent(m.bytes.data(), static_cast<int>(m.bytes.size()), 0);
    buffer.clear();
    plugin.processBlock(buffer, midi);
    const auto warm = static_cast<long long>(warmup * sampleRate);
    for (long long done = blockSize; done < warm; done += blockSize) {
        buffer.clear();
        plugin.processBlock(buffer, empty);
    }
    BenchResult r;
    r.samplesPerPass = static_cast<long long>(seconds * sampleRate) / blockSize * blockSize;
    std::vector<double> passes;
    double sumsq = 0.0;
    long long count = 0;
    for (int rep = 0; rep < reps; ++rep) {
        double passSumsq = 0.0;
        const auto t0 = std::chrono::steady_clock::now();
        for (long long done = 0; done < r.samplesPerPass; done += blockSize) {
            buffer.clear();
            plugin.processBlock(buffer, empty);
            const float* l = buffer.getReadPointer(0);
            for (int i = 0; i < blockSize; ++i) {
                passSumsq += static_cast<double>(l[i]) * l[i];
                r.peak = std::max(r.peak, static_cast<double>(std::abs(l[i])));
            }
        }
        passes.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        sumsq += passSumsq;
        count += r.samplesPerPass;
    }
    std::sort(passes.begin(), passes.end());
    r.bestPassSeconds = passes.front();
    r.medianPassSeconds = passes[passes.size() / 2];
    r.rms = std::sqrt(sumsq / static_cast<double>(std::max(1LL, count)));
    plugin.releaseResources();
    return r;
}

std::vector<TimedMidi> readMidiFile(const fs::path& file)
{
    juce::File f(fs::absolute(file).string());
    juce::FileInputStream in(f);
    if (!in.openedOk()) throw std::runtime_error(file.string() + ": cannot open MIDI file");
    juce::MidiFile mf;
    if (!mf.readFrom(in)) throw std::runtime_error(file.string() + ": not a standard MIDI file");
    if (mf.getTimeFormat() == 0) throw std::runtime_error(file.string() + ": no time format in the header");
    mf.convertTimestampTicksToSeconds();
    std::vector<TimedMidi> out;
    for (int t = 0; t < mf.getNumTracks(); ++t) {
        const auto* track = mf.getTrack(t);
        for (const auto* e : *track) {
            const auto& m = e->message;
            if (m.isMetaEvent() || m.isSysEx()) continue;
            const auto* raw = m.getRawData();
            out.push_back({m.getTimeStamp(), std::vector<std::uint8_t>(raw, raw + m.getRawDataSize())});
        }
    }
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.seconds < b.seconds; });
    return out;
}

std::vector<TimedMidi> readEventList(const fs::path& file)
{
    std::ifstream in(file);
    if (!in) throw std::runtime_error(file.string() + ": cannot open event list");
    std::vector<TimedMidi> out;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        ++number;
        if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        std::istringstream s(line);
        TimedMidi m;
        if (!(s >> m.seconds)) {
            if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
            throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": expected a time in seconds");
        }
        if (!std::isfinite(m.seconds) || m.seconds < 0.0)
            throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": time must be >= 0");
        std::string hex;
        while (s >> hex) {
            std::size_t used = 0;
            int v = -1;
            try { v = std::stoi(hex, &used, 16); } catch (...) { used = 0; }
            if (used != hex.size() || v < 0 || v > 255)
                throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": '" + hex + "' is not a hex byte");
            m.bytes.push_back(static_cast<std::uint8_t>(v));
        }
        if (m.bytes.empty() || m.bytes[0] < 0x80)
            throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": a message starts with a status byte (80-EF)");
        out.push_back(std::move(m));
    }
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.seconds < b.seconds; });
    return out;
}

void writeWav(const fs::path& file, const std::vector<float>& left, const std::vector<float>& right, double sampleRate)
{
    const fs::path tmp = file.string() + ".partial";
    {
        juce::File out(fs::absolute(tmp).string());
        out.deleteFile();
        auto stream = std::make_unique<juce::FileOutputStream>(out);
        if (!stream->openedOk()) throw std::runtime_error(file.string() + ": cannot write");
        juce::WavAudioFormat wav;
        std::unique_ptr<juce::AudioFormatWriter> writer(wav.createWriterFor(stream.get(), sampleRate, 2, 32, {}, 0));
        if (!writer) throw std::runtime_error(file.string() + ": cannot write WAV at this rate");
        stream.release(); // owned by the writer now
        const float* chans[2] = {left.data(), right.data()};
        juce::AudioBuffer<float> view(const_cast<float**>(chans), 2, static_cast<int>(left.size()));
        if (!writer->writeFromAudioSampleBuffer(view, 0, view.getNumSamples())) throw std::runtime_error(file.string() + ": write failed");
    }
    std::error_code ec;
    fs::rename(tmp, file, ec);
    if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
}

} // namespace rosin::host
