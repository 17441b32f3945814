// Headless plugin host: loads the BUILT Rosin VST3 or LV2 (or any instrument plugin), plays
// timed MIDI and parameter automation at any rate and block size, and returns the audio. The
// API is plain C++ so tests and the CLI do not need JUCE headers; JUCE lives in PluginHost.cpp.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "AuditCounter.h"

namespace rosin::host {

struct TimedMidi {
    double seconds = 0.0;
    std::vector<std::uint8_t> bytes;
};

struct Automation {
    double seconds = 0.0;   ///< applied at the start of the block containing this time
    std::string paramId;
    float normalised = 0.0f; ///< the host's 0-1 value, as a DAW automation lane sends it
};

struct HostedParam {
    std::string id, name, text;
    float normalised = 0.0f, defaultNormalised = 0.0f;
    int steps = 0; ///< 0 continuous, else the number of discrete values
};

struct RenderRequest {
    double sampleRate = 48000.0;
    int blockSize = 512;
    double seconds = 1.0;
    std::vector<TimedMidi> midi;
    std::vector<Automation> automation;
    bool audit = false; ///< count allocations and locks inside the plugin's processBlock
};

struct AuditCounts {
    std::uint64_t blocks = 0;
    audit::Tally plugin; ///< inside Rosin's processBlock
    audit::Tally call;   ///< the whole host -> plugin call (the format wrapper too)
    bool pluginScopeSeen = false; ///< the plugin reported its scope (it is Rosin, built with the hook)
};

struct RenderResult {
    std::vector<float> left, right;
    AuditCounts audit;
};

struct BenchResult {
    double bestPassSeconds = 0.0, medianPassSeconds = 0.0;
    long long samplesPerPass = 0;
    double rms = 0.0, peak = 0.0;
};

class PluginHost {
public:
    /// Loads a .vst3 bundle or an .lv2 bundle. Throws std::runtime_error with the reason.
    explicit PluginHost(const std::filesystem::path& plugin);
    ~PluginHost();
    PluginHost(const PluginHost&) = delete;
    PluginHost& operator=(const PluginHost&) = delete;

    std::string formatName() const;
    std::string pluginName() const;
    std::vector<HostedParam> parameters() const;
    /// Sets a parameter by ID: "0.6" through the plugin's own text parser, "@0.25" normalised.
    void setParameter(const std::string& id, const std::string& value);
    float getParameter(const std::string& id) const;
    /// The names of a discrete parameter's values, as the plugin reports them to the host.
    std::vector<std::string> choices(const std::string& id) const;
    /// One parameter by ID (throws when the plugin has none by that ID).
    HostedParam parameter(const std::string& id) const;

    std::vector<char> getState() const;
    void setState(const std::vector<char>& state);
    /// Back to the state the plugin had when it was loaded.
    void restoreInitialState();

    /// Prepares at the request's rate and block (a fresh engine), then renders.
    RenderResult render(const RenderRequest& request);

    // Streaming, as a DAW drives a plugin (the validation pass): start at a rate, block size,
    // mode and output channel count (1 or 2: the bus layout), then blocks one at a time.
    /// Throws when the plugin refuses the layout.
    void startStream(double sampleRate, int maxBlock, bool realtime, int outputChannels);
    /// One block of n <= maxBlock samples; MIDI as (frame, bytes). Writes n samples per output
    /// channel (right is ignored for a mono layout). With `audited`, the audit counts this call.
    void processStream(int n, const std::vector<std::pair<int, std::vector<std::uint8_t>>>& midi, float* left, float* right,
                       bool audited);
    void stopStream();
    /// [any thread] A parameter by its index in parameters(), normalised: a host's automation thread.
    void setParameterNormalised(int index, float value);
    int parameterCount() const;
    /// The index of the host's bypass parameter (normalised 1 = bypassed), or -1 when it has none.
    int bypassParameterIndex() const;
    /// The index of a parameter by the plugin's own ID (as setParameter takes it), or -1.
    int parameterIndex(const std::string& id) const;

    /// Times processBlock as a DAW would call it (real-time mode): `midi` is sent in the first
    /// block, `warmup` seconds run untimed, then `reps` passes of `seconds` each are timed.
    BenchResult bench(double sampleRate, int blockSize, double seconds, int reps, double warmup,
                      const std::vector<TimedMidi>& midi);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// MIDI file (type 0 or 1, all tracks merged) to timed messages. Throws naming the file.
std::vector<TimedMidi> readMidiFile(const std::filesystem::path& file);
/// A saved host state (VST3 or LV2, as getState() returns it) with Rosin's own XML state edited by
/// `edit` (it receives and returns the RosinState XML text). Throws when no Rosin state is inside.
std::vector<char> editRosinState(const std::vector<char>& hostState, const std::function<std::string(const std::string&)>& edit);
/// Text event list: "seconds hexbyte hexbyte ..." per line, '#' comments. Throws naming file and line.
std::vector<TimedMidi> readEventList(const std::filesystem::path& file);
/// Writes 32-bit float stereo WAV atomically (temp file + rename). Throws naming the file.
void writeWav(const std::filesystem::path& file, const std::vector<float>& left, const std::vector<float>& right,
              double sampleRate);

} // namespace rosin::host
