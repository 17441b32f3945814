// Host tests: the BUILT Rosin VST3 and LV2, loaded headless the way a DAW loads them. Every
// test runs on both formats.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <string>

#include "AudioChecks.h"
#include "AuditCounter.h"
#include "PluginHost.h"
#include "rosin/engine/Parameters.h"

using namespace rosin;
using namespace rosin::host;

namespace {
TimedMidi msg(double t, std::initializer_list<int> bytes)
{
    TimedMidi m;
    m.seconds = t;
    for (int b : bytes) m.bytes.push_back(static_cast<std::uint8_t>(b));
    return m;
}
TimedMidi noteOn(double t, int note, int vel = 100, int ch = 0) { return msg(t, {0x90 | ch, note, vel}); }
TimedMidi noteOff(double t, int note, int ch = 0) { return msg(t, {0x80 | ch, note, 0}); }

std::vector<float> mono(const RenderResult& r)
{
    std::vector<float> m(r.left.size());
    for (std::size_t i = 0; i < m.size(); ++i) m[i] = r.left[i] + r.right[i];
    return m;
}

double maxStep(const std::vector<float>& x, std::size_t from, std::size_t to)
{
    double m = 0.0;
    for (std::size_t i = from + 1; i < to; ++i) m = std::max(m, std::abs(static_cast<double>(x[i]) - x[i - 1]));
    return m;
}

class Host : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override { host = std::make_unique<PluginHost>(GetParam()); }
    std::unique_ptr<PluginHost> host;
};

/// Every parameter Rosin declares (the engine's table plus the instrument choice).
std::vector<std::string> rosinParameterIds()
{
    std::vector<std::string> ids;
    for (int i = 0; i < engine::paramCount; ++i) ids.emplace_back(engine::paramInfo(i).id);
    ids.emplace_back("instrument");
    return ids;
}

std::string formatName(const ::testing::TestParamInfo<std::string>& info)
{
    return info.param.find(".vst3") != std::string::npos ? "VST3" : "LV2";
}
} // namespace

TEST_P(Host, LoadsTheBuiltBundleWithEveryParameter)
{
    EXPECT_EQ(host->pluginName(), "Rosin");
    for (const auto& id : rosinParameterIds()) {
        HostedParam p;
        ASSERT_NO_THROW(p = host->parameter(id)) << id;
        EXPECT_FALSE(p.name.empty()) << id;
    }
    // Every format labels the choices right (Debian's JUCE 7.0.5 wrote LV2 scale points at
    // normalised values: a fresh plugin showed "double-bass" for its cello).
    EXPECT_EQ(host->parameter("instrument").text, "cello");
    EXPECT_EQ(host->choices("instrument"), (std::vector<std::string>{"violin", "viola", "cello", "double-bass"}));
    EXPECT_EQ(host->parameter("articulation").text, "Detache");
    host->setParameter("bow_force", "1.25");
    EXPECT_NE(host->parameter("bow_force").text.find("1.25"), std::string::npos) << host->parameter("bow_force").text;
}

TEST_P(Host, NotesSoundAtTheRightPitch)
{
    for (int note : {43, 50, 57, 62, 69}) { // cello: open G, open D, stopped A3, D4, A4
        RenderRequest req;
        req.seconds = 1.0;
        req.midi = {noteOn(0.0, note)};
        const auto out = mono(host->render(req));
        const double f = test::pitchHz(out, req.sampleRate, 24000, 48000);
        EXPECT_LT(std::abs(test::cents(f, test::midiToHz(note))), 5.0) << "note " << note << ": " << f << " Hz";
    }
}

TEST_P(Host, SilenceAfterRelease)
{
    RenderRequest req;
    req.seconds = 3.0;
    req.midi = {noteOn(0.0, 50), noteOff(0.5, 50)};
    const auto out = mono(host->render(req));
    EXPECT_GT(test::rms(out, 12000, 24000), 1e-2);
    EXPECT_LT(test::peakAbs(out, 96000, 144000), 1e-6); // -120 dB in the last second
}

// Notes land on their sample in both formats. Controllers do in LV2 (MIDI atoms carry frame
// times); through VST3 they become parameter changes, and JUCE's VST3 host applies those at
// the start of the block, so for VST3 they are placed on frames that start a block at every
// size tested (multiples of 7 x 4096 = 28672).
TEST_P(Host, IdenticalOutputWhateverTheBlockSize)
{
    const double fs = 48000.0, common = 28672.0 / fs;
    RenderRequest req;
    req.seconds = 1.5;
    req.midi = {noteOn(0.0, 50, 90), noteOn(0.146, 57, 60), msg(common, {0xB0, 74, 90}), msg(common, {0xE0, 0x20, 0x45}),
                msg(common, {0xD0, 100}), noteOff(0.8, 50), noteOff(1.2, 57), msg(0.3003, {0xA0, 57, 100})};
    if (formatName({GetParam(), 0}) == "LV2")
        for (double t : {0.0625, 0.1001, 0.2117, 0.9})
            req.midi.push_back(msg(t, {0xB0, 2, static_cast<int>(t * 500) % 128}));
    req.blockSize = 512;
    const RenderResult reference = host->render(req);
    EXPECT_GT(test::peakAbs(reference.left, 0, reference.left.size()), 1e-2);
    for (int block : {1, 7, 64, 4096}) {
        req.blockSize = block;
        const RenderResult r = host->render(req);
        ASSERT_EQ(r.left, reference.left) << "block " << block;
        ASSERT_EQ(r.right, reference.right) << "block " << block;
    }
}

TEST_P(Host, PlaysInTuneAtEverySampleRate)
{
    for (double rate : {44100.0, 48000.0, 88200.0, 96000.0, 176400.0, 192000.0}) {
        RenderRequest req;
        req.sampleRate = rate;
        req.seconds = 1.0;
        req.midi = {noteOn(0.0, 57)};
        const auto out = mono(host->render(req));
        const auto half = static_cast<std::size_t>(rate / 2);
        const double f = test::pitchHz(out, rate, half, out.size());
        EXPECT_LT(std::abs(test::cents(f, test::midiToHz(57))), 5.0) << rate << " Hz: " << f;
        EXPECT_GT(test::rms(out, half, out.size()), 1e-2) << rate;
        for (float x : out) ASSERT_TRUE(std::isfinite(x));
    }
}

TEST_P(Host, StateRoundTripsExactly)
{
    host->setParameter("bow_force", "1.3");
    host->setParameter("friction_model", "@1.0");
    host->setParameter("ambient", "31.5");
    host->setParameter("instrument", "@0.0"); // violin
    host->setParameter("bow_position", "@0.123456");
    RenderRequest req;
    req.seconds = 0.5;
    req.midi = {noteOn(0.0, 67), msg(0.1, {0xB0, 2, 90})};
    const RenderResult before = host->render(req);
    const std::vector<char> saved = host->getState();

    host->restoreInitialState();
    EXPECT_NE(host->getState(), saved);
    EXPECT_NE(host->render(req).left, before.left);

    host->setState(saved);
    EXPECT_EQ(host->getState(), saved);
    EXPECT_NEAR(host->getParameter("ambient"), 31.5f / 40.0f, 1e-6);
    EXPECT_NEAR(host->getParameter("bow_position"), 0.123456f, 1e-6);
    EXPECT_EQ(host->parameter("instrument").text, "violin");
    EXPECT_EQ(host->render(req).left, before.left); // the same sound, to the bit
}

// Clicks: automating any parameter at block rate, through its whole range, must never make the
// output step further from one sample to the next than the same note does when that parameter
// is held at the values the ramp passes through (min, max, default), with a margin of 2x.
TEST_P(Host, AutomatingEveryParameterAtBlockRateMakesNoClicks)
{
    const double fs = 48000.0;
    const std::size_t from = 24000, to = 72000; // the automated window, 0.5-1.5 s
    for (const auto& id : rosinParameterIds()) {
        const HostedParam p = host->parameter(id);
        auto run = [&](const std::vector<Automation>& automation) {
            host->restoreInitialState();
            RenderRequest req;
            req.seconds = 1.6;
            req.blockSize = 256;
            req.midi = {noteOn(0.0, 50)};
            req.automation = automation;
            return mono(host->render(req));
        };
        double bound = 0.0;
        for (float v : {0.0f, 1.0f, p.defaultNormalised}) {
            const auto held = run({{0.0, id, v}});
            bound = std::max(bound, maxStep(held, from, to));
        }
        std::vector<Automation> ramp;
        const int blocks = static_cast<int>((to - from) / 256);
        for (int b = 0; b <= blocks; ++b) {
            const double x = static_cast<double>(b) / blocks; // default -> 0 -> 1 -> default
            float v = x < 0.25 ? static_cast<float>(p.defaultNormalised * (1.0 - 4.0 * x))
                      : x < 0.75 ? static_cast<float>(2.0 * (x - 0.25))
                                 : static_cast<float>(1.0 - (1.0 - p.defaultNormalised) * 4.0 * (x - 0.75));
            ramp.push_back({(static_cast<double>(from) + b * 256.0) / fs, id, std::clamp(v, 0.0f, 1.0f)});
        }
        const auto automated = run(ramp);
        for (float x : automated) ASSERT_TRUE(std::isfinite(x)) << id;
        EXPECT_LE(maxStep(automated, from, to + 4800), 2.0 * bound + 1e-3) << id << " (static bound " << bound << ")";
    }
}

TEST_P(Host, MpePerNoteControlAffectsOnlyItsNote)
{
    host->setParameter("mpe", "@1.0");
    const std::vector<TimedMidi> expression{msg(0.125, {0xD1, 120}), msg(0.1875, {0xB1, 74, 20}), msg(0.25, {0xE1, 0x00, 0x5E})};
    auto render = [&](std::vector<TimedMidi> midi) {
        RenderRequest req;
        req.seconds = 0.75;
        req.midi = std::move(midi);
        return host->render(req);
    };
    std::vector<TimedMidi> both{noteOn(0.0, 50, 100, 1), noteOn(0.0, 57, 100, 2)}, first{noteOn(0.0, 50, 100, 1)};
    both.insert(both.end(), expression.begin(), expression.end());
    first.insert(first.end(), expression.begin(), expression.end());
    const RenderResult mix = render(both), alone = render(first), second = render({noteOn(0.0, 57, 100, 2)}),
                       untouched = render({noteOn(0.0, 50, 100, 1)});
    double worst = 0.0;
    for (std::size_t i = 0; i < mix.left.size(); ++i)
        worst = std::max(worst, std::abs(static_cast<double>(mix.left[i]) - alone.left[i] - second.left[i]));
    EXPECT_LT(worst, 1e-5);
    EXPECT_GT(test::peakAbs(second.left, 0, second.left.size()), 1e-2);
    // The expression reached its own note.
    double change = 0.0;
    for (std::size_t i = 0; i < alone.left.size(); ++i) change = std::max(change, std::abs(static_cast<double>(alone.left[i]) - untouched.left[i]));
    EXPECT_GT(change, 1e-2);
}

// Real-time safety, measured: the host counts every malloc and pthread_mutex_lock on the audio
// thread between the plugin's own processBlock entry and exit, over a long render with notes,
// controllers, automation of every parameter and instrument preset changes.
TEST_P(Host, NoAllocationOrLockInsideProcessBlock)
{
    ASSERT_TRUE(audit::selfTest()) << "the counter must see an allocation it is shown";
    const auto params = rosinParameterIds();
    RenderRequest req;
    req.seconds = 24.0;
    req.blockSize = 256;
    req.audit = true;
    int k = 0;
    for (double t = 0.0; t < 23.0; t += 0.25, ++k) {
        const int note = 36 + (k * 7) % 48;
        req.midi.push_back(noteOn(t, note, 40 + (k * 13) % 87, k % 3));
        req.midi.push_back(msg(t + 0.05, {0xB0 | (k % 3), 2, (k * 17) % 128}));
        req.midi.push_back(msg(t + 0.07, {0xE0 | (k % 3), 0, (k * 29) % 128}));
        req.midi.push_back(msg(t + 0.09, {0xA0 | (k % 3), note, (k * 5) % 128}));
        req.midi.push_back(noteOff(t + 0.4 + 0.3 * (k % 4), note, k % 3));
        if (k % 16 == 0) req.midi.push_back(msg(t, {0xB0, 64, k % 32 == 0 ? 127 : 0}));
        if (k % 8 == 0) req.midi.push_back(noteOn(t, 12 + (k / 8) % 7, 100)); // keyswitch: every articulation in turn
    }
    for (int b = 0; b * 256.0 / 48000.0 < 22.0; ++b) {
        const auto& id = params[static_cast<std::size_t>(b) % params.size()];
        if (id == "instrument") continue;
        req.automation.push_back({b * 256.0 / 48000.0, id, static_cast<float>((b * 37) % 101) / 100.0f});
    }
    for (int i = 0; i < 6; ++i) req.automation.push_back({2.0 + 3.3 * i, "instrument", (i % 4) / 3.0f});
    const RenderResult r = host->render(req);
    EXPECT_TRUE(r.audit.pluginScopeSeen);
    EXPECT_GT(r.audit.blocks, 4000u);
    EXPECT_EQ(r.audit.plugin.allocations, 0u);
    EXPECT_EQ(r.audit.plugin.frees, 0u);
    EXPECT_EQ(r.audit.plugin.locks, 0u);
    EXPECT_EQ(r.audit.plugin.waits, 0u);
    EXPECT_EQ(r.audit.plugin.blocking, 0u);
    RecordProperty("allocations_in_host_call", std::to_string(r.audit.call.allocations));
    RecordProperty("locks_in_host_call", std::to_string(r.audit.call.locks));
    std::printf("[ audit    ] %s: %llu blocks; in processBlock %llu allocations, %llu locks; whole host call (wrappers) %llu allocations, %llu locks\n",
                formatName({GetParam(), 0}).c_str(), static_cast<unsigned long long>(r.audit.blocks),
                static_cast<unsigned long long>(r.audit.plugin.allocations), static_cast<unsigned long long>(r.audit.plugin.locks),
                static_cast<unsigned long long>(r.audit.call.allocations), static_cast<unsigned long long>(r.audit.call.locks));
    for (float x : r.left) ASSERT_TRUE(std::isfinite(x));
}

INSTANTIATE_TEST_SUITE_P(Formats, Host, ::testing::Values(std::string(ROSIN_VST3_BUNDLE), std::string(ROSIN_LV2_BUNDLE)), formatName);
