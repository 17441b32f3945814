// lab/: presets, gesture files and the `rosin` command end to end.
#include <gtest/gtest.h>
#include <sndfile.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "rosin/lab/Error.h"
#include "rosin/lab/Gesture.h"
#include "rosin/presets/Presets.h"

namespace fs = std::filesystem;
using namespace rosin::lab;
namespace presets = rosin::presets;

namespace {
const fs::path kPresets = fs::path(ROSIN_SOURCE_DIR) / "presets";

struct CliRun {
    int status;
    std::string output;
};

/// Runs the CLI with a shell command line; captures stdout and stderr together.
CliRun runRosin(const std::string& args)
{
    const std::string cmd = std::string(ROSIN_CLI) + " " + args + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    std::string out;
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    const int status = pclose(p);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

class TempDir {
public:
    TempDir() : path_(fs::temp_directory_path() / ("rosin-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++)))
    {
        fs::create_directories(path_);
    }
    ~TempDir() { fs::remove_all(path_); }
    const fs::path& path() const { return path_; }
    std::size_t fileCount() const { return static_cast<std::size_t>(std::distance(fs::directory_iterator(path_), fs::directory_iterator())); }

private:
    static inline int counter_ = 0;
    fs::path path_;
};

void writeFile(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
} // namespace

TEST(Presets, EveryInstrumentHasItsFourStringsAtTheRightPitch)
{
    const auto all = presets::allStrings(presets::Library());
    const std::map<std::string, double> pitch{
        {"violin-G", 196.00}, {"violin-D", 293.66}, {"violin-A", 440.00}, {"violin-E", 659.26},
        {"viola-C", 130.81},  {"viola-G", 196.00},  {"viola-D", 293.66},  {"viola-A", 440.00},
        {"cello-C", 65.41},   {"cello-G", 98.00},   {"cello-D", 146.83},  {"cello-A", 220.00},
        {"double-bass-E", 41.20}, {"double-bass-A", 55.00}, {"double-bass-D", 73.42}, {"double-bass-G", 98.00}};
    ASSERT_EQ(all.size(), pitch.size());
    for (const auto& p : all) {
        ASSERT_TRUE(pitch.count(p.id)) << p.id;
        EXPECT_NEAR(p.params.fundamental(), pitch.at(p.id), 0.01 * 0.01 * pitch.at(p.id)) << p.id;
        EXPECT_TRUE(p.params.validate().empty()) << p.id;
    }
}

TEST(Presets, CelloDIsThePhysicsReferenceString)
{
    const auto d = presets::findString(presets::Library(), "cello-d").params; // ids are case-insensitive
    EXPECT_NEAR(d.length, 0.69, 1e-12);
    EXPECT_NEAR(d.tension, 102.6, 1e-12);
    EXPECT_NEAR(d.massPerLength * 1e3, 2.50, 0.01);
    EXPECT_NEAR(d.waveSpeed(), 202.6, 0.1);
    EXPECT_NEAR(d.impedance(), 0.506, 0.001);
    EXPECT_NEAR(d.torsionSpeedRatio, 5.2, 1e-12);
    EXPECT_NEAR(d.torsionImpedanceRatio, 2.0, 1e-12);
    const auto builtin = rosin::dsp::StringParams::celloD();
    EXPECT_NEAR(d.massPerLength, builtin.massPerLength, 1e-9);
}

TEST(Presets, RosinPresetsCarryTheirGlassTransitions)
{
    const presets::Library library;
    EXPECT_DOUBLE_EQ(presets::findRosin(library, "violin").glassTransitionCelsius, 49.0);
    EXPECT_DOUBLE_EQ(presets::findRosin(library, "bass").glassTransitionCelsius, 16.0);
    EXPECT_THROW(presets::findRosin(library, "gouda"), presets::PresetError);
}

TEST(Presets, TheFactorySetNeedsNoFilesAndUserFoldersAddToIt)
{
    // The factory set is compiled in: nothing on disk is read for it.
    const presets::Library factory;
    EXPECT_EQ(factory.list("instruments"), (std::vector<std::string>{"cello", "double-bass", "viola", "violin"}));
    EXPECT_EQ(presets::loadInstrument(factory, "cello").origin, "factory:instruments/cello.json");
    EXPECT_GE(factory.list("controllers").size(), 4u);

    // A user folder adds a rosin of its own and replaces the factory violin rosin.
    TempDir a, b;
    fs::create_directories(a.path() / "rosin");
    fs::create_directories(b.path() / "rosin");
    writeFile(a.path() / "rosin" / "amber.json", R"({"format": "rosin-rosin/1", "glass_transition_C": 41.5})");
    writeFile(a.path() / "rosin" / "violin.json", R"({"format": "rosin-rosin/1", "glass_transition_C": 47.0})");
    writeFile(b.path() / "rosin" / "violin.json", R"({"format": "rosin-rosin/1", "glass_transition_C": 45.0})");
    presets::Library user;
    user.addFolder(a.path());
    EXPECT_EQ(user.list("rosin"), (std::vector<std::string>{"amber", "bass", "violin"}));
    EXPECT_DOUBLE_EQ(presets::findRosin(user, "amber").glassTransitionCelsius, 41.5);
    EXPECT_DOUBLE_EQ(presets::findRosin(user, "violin").glassTransitionCelsius, 47.0);
    EXPECT_DOUBLE_EQ(presets::findRosin(user, "bass").glassTransitionCelsius, 16.0); // still the factory's
    // An instrument from the factory picks up the user's rosin of the same name.
    EXPECT_DOUBLE_EQ(presets::loadInstrument(user, "violin").rosinTg, 47.0);

    // $ROSIN_PRESETS: the first folder listed wins.
    ::setenv("ROSIN_PRESETS", (b.path().string() + ":" + a.path().string()).c_str(), 1);
    const presets::Library fromEnv = presets::Library::standard();
    ::unsetenv("ROSIN_PRESETS");
    EXPECT_DOUBLE_EQ(presets::findRosin(fromEnv, "violin").glassTransitionCelsius, 45.0);
    EXPECT_DOUBLE_EQ(presets::findRosin(fromEnv, "amber").glassTransitionCelsius, 41.5);
}

TEST(Presets, BrokenStringFileNamesTheFileAndField)
{
    TempDir dir;
    const fs::path f = dir.path() / "broken.json";
    writeFile(f, R"({"format": "rosin-strings/1", "strings": [{"name": "X", "frequency_hz": 100, "length_m": 0.5,
                 "tension_N": "loud", "radius_m": 1e-3}]})");
    try {
        presets::loadStrings(presets::Library(), f.string());
        FAIL() << "expected an error";
    } catch (const presets::PresetError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("broken.json"), std::string::npos) << msg;
        EXPECT_NE(msg.find("tension_N"), std::string::npos) << msg;
    }
    writeFile(f, R"({"format": "rosin-strings/2", "strings": []})");
    EXPECT_THROW(presets::loadStrings(presets::Library(), f.string()), presets::PresetError);
}

TEST(GestureFile, ReadsRowsAndInterpolatesLinearly)
{
    TempDir dir;
    const fs::path f = dir.path() / "g.csv";
    writeFile(f, "# a comment\nbeta,time,speed,force\n0.1,0,0,0.5\n0.2,1,0.2,1.5\n");
    Gesture g;
    g.kind = GestureKind::File;
    g.rows = loadGestureFile(f);
    const auto c = g.at(0.25);
    EXPECT_NEAR(c.force, 0.75, 1e-12);
    EXPECT_NEAR(c.speed, 0.05, 1e-12);
    EXPECT_NEAR(c.beta, 0.125, 1e-12);
    EXPECT_NEAR(g.at(5.0).force, 1.5, 1e-12); // holds the last row
}

TEST(GestureFile, BadRowsAreReportedWithFileLineAndField)
{
    TempDir dir;
    const fs::path f = dir.path() / "bad.csv";
    const std::pair<std::string, std::string> cases[] = {
        {"time,force,speed\n0,1,0\n", "'beta'"},
        {"time,force,speed,beta\n0,1,0,0.1\n0.5,oops,0,0.1\n", "bad.csv:3: field 'force'"},
        {"time,force,speed,beta\n0,1,0,0.1\n0.5,nan,0,0.1\n", "bad.csv:3: field 'force'"},
        {"time,force,speed,beta\n0,1,0,0.1\n0,1,0,0.1\n", "bad.csv:3: field 'time'"},
        {"time,force,speed,beta\n0,1,0,0.1\n1,1,0,0.9\n", "bad.csv:3: field 'beta'"},
        {"time,force,speed,beta\n0,1,0,0.1\n1,500,0,0.1\n", "bad.csv:3: field 'force'"},
    };
    for (const auto& [text, expected] : cases) {
        writeFile(f, text);
        try {
            loadGestureFile(f);
            ADD_FAILURE() << "no error for: " << text;
        } catch (const LabError& e) {
            EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
        }
    }
}

TEST(RosinCli, RenderWritesAWavInNewtonsAndACsvOfEveryQuantity)
{
    TempDir dir;
    const fs::path prefix = dir.path() / "stroke";
    const CliRun r = runRosin("render --force 1 --accel 1 --duration 0.1 --sample-rate 48000 --out " + prefix.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("first slip at"), std::string::npos) << r.output;

    SF_INFO info{};
    SNDFILE* sf = sf_open((prefix.string() + ".wav").c_str(), SFM_READ, &info);
    ASSERT_NE(sf, nullptr);
    EXPECT_EQ(info.samplerate, 48000);
    EXPECT_EQ(info.frames, 4800);
    EXPECT_EQ(info.format & SF_FORMAT_SUBMASK, SF_FORMAT_FLOAT);
    std::vector<double> wav(static_cast<std::size_t>(info.frames));
    sf_read_double(sf, wav.data(), info.frames);
    sf_close(sf);

    std::ifstream csv(prefix.string() + ".csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header, "time_s,bridge_force_N,bow_point_velocity_m_s,friction_force_N,contact_temperature_C,"
                      "temperature_rise_K,stick,bow_force_N,bow_speed_m_s,beta");
    std::size_t rows = 0;
    double maxRise = 0.0;
    bool sawSlip = false;
    for (std::string line; std::getline(csv, line); ++rows) {
        std::stringstream ss(line);
        std::vector<double> v;
        for (std::string cell; std::getline(ss, cell, ',');) v.push_back(std::stod(cell));
        ASSERT_EQ(v.size(), 10u);
        EXPECT_NEAR(v[1], wav[rows], 1e-6 * (1 + std::abs(v[1]))); // the WAV holds the bridge force in N
        EXPECT_NEAR(v[4], 20.0 + v[5], 1e-3);                      // ambient + rise
        maxRise = std::max(maxRise, v[5]);
        sawSlip |= v[6] == 0.0;
        if (v[6] == 1.0) {
            EXPECT_NEAR(v[2], v[8], 1e-6); // sticking: string moves with the bow
        }
    }
    EXPECT_EQ(rows, 4800u);
    EXPECT_TRUE(sawSlip);
    EXPECT_GT(maxRise, 1.0); // the default thermal model heats the contact
}

TEST(RosinCli, EveryGestureAndModelRenders)
{
    TempDir dir;
    const std::string common = " --duration 0.05 --sample-rate 44100 -q --no-csv --out " + (dir.path() / "x").string();
    for (const char* model : {"friction-curve", "thermal", "enhanced"}) {
        for (const char* gesture : {"guettler", "constant", "exp-speed", "exp-force"}) {
            const CliRun r = runRosin(std::string("render --model ") + model + " --gesture " + gesture + common);
            EXPECT_EQ(r.status, 0) << model << " " << gesture << ": " << r.output;
        }
    }
    const CliRun overridden = runRosin("render --set contact_radius_m=3e-4 --set q_low=300 --set tension_n=120 --duration 0.05 "
                                       "--no-csv --out " + (dir.path() / "o").string());
    EXPECT_EQ(overridden.status, 0) << overridden.output;
    EXPECT_NE(overridden.output.find("f0 146.83"), std::string::npos) << overridden.output; // pitch kept
    const CliRun hertz = runRosin("render --contact hertz --rosin bass --ambient 25 --dispersion --string violin-E" + common);
    EXPECT_EQ(hertz.status, 0) << hertz.output;
    const CliRun phrase = runRosin("render --gesture-file " + (kPresets / "gestures" / "demo-phrase.csv").string() +
                             " --listen --sample-rate 48000 -q --out " + (dir.path() / "phrase").string());
    ASSERT_EQ(phrase.status, 0) << phrase.output;
    SF_INFO info{};
    SNDFILE* sf = sf_open((dir.path() / "phrase.wav").c_str(), SFM_READ, &info);
    ASSERT_NE(sf, nullptr);
    sf_close(sf);
    EXPECT_EQ(info.frames, static_cast<sf_count_t>(3.6 * 48000)); // the file's own length
    EXPECT_EQ(info.format & SF_FORMAT_SUBMASK, SF_FORMAT_PCM_24);
}

TEST(RosinCli, BadArgumentsFailClearlyAndWriteNothing)
{
    TempDir dir;
    const std::string out = " --out " + (dir.path() / "x").string();
    const std::pair<std::string, std::string> cases[] = {
        {"render --force nan" + out, "--force"},
        {"render --force 1e9" + out, "--force"},
        {"render --beta 0.9" + out, "--beta"},
        {"render --model magic" + out, "--model"},
        {"render --string cello-Z" + out, "unknown string 'cello-Z'"},
        {"render --rosin gouda" + out, "unknown rosin"},
        {"render --sample-rate -5" + out, "--sample-rate"},
        {"render --gesture file" + out, "--gesture-file"},
        {"render --gesture-file /nonexistent.csv" + out, "/nonexistent.csv"},
        {"render --out /nonexistent-dir/x", "/nonexistent-dir"},
        {"frobnicate", "frobnicate"},
        {"render --set rod_effusivity=-3" + out, "--set rod_effusivity"},
        {"render --set colour=3" + out, "unknown parameter 'colour'"},
        {"diagnose some-set --model-discrepancy r_A=-0.1" + out, "--model-discrepancy r_A=-0.1"},
        {"diagnose some-set --model-discrepancy colour=0.1" + out, "--model-discrepancy colour=0.1"},
        {"diagnose some-set --model-discrepancy p" + out, "--model-discrepancy p"},
        {"diagnose some-set --model-discrepancy p=0.1x" + out, "--model-discrepancy p=0.1x"}, // trailing text, once read as 0.1
        {"diagnose some-set --model-discrepancy tension_scale=11" + out, "--model-discrepancy tension_scale=11"},
        {"study --pool /nonexistent-study" + out, "/nonexistent-study"},
        {"study --compare-splits /nonexistent-study" + out, "/nonexistent-study"},
        {"diagnose some-set --shift-margin 1.5" + out, "--shift-margin"},
        {"diagnose some-set --shift-margin nan" + out, "--shift-margin"},
        {"render --set tension_n=60N" + out, "--set tension_n: '60N' is not a number"},
    };
    for (const auto& [args, expected] : cases) {
        const CliRun r = runRosin(args);
        EXPECT_NE(r.status, 0) << args;
        EXPECT_NE(r.output.find(expected), std::string::npos) << args << " -> " << r.output;
        EXPECT_EQ(dir.fileCount(), 0u) << args;
    }
}

TEST(RosinCli, HelpExplainsTheCommandsAndGestures)
{
    const CliRun top = runRosin("--help");
    EXPECT_EQ(top.status, 0);
    for (const char* word : {"render", "strings", "bench", "Examples"}) EXPECT_NE(top.output.find(word), std::string::npos) << word;
    const CliRun render = runRosin("render --help");
    EXPECT_EQ(render.status, 0);
    for (const char* word : {"guettler", "exp-force", "--gesture-file", "newtons", "--contact", "--rosin"})
        EXPECT_NE(render.output.find(word), std::string::npos) << word;
    // CLI11 shows a two-way flag's spellings, not its default, so the text must say it
    const CliRun diagnose = runRosin("diagnose --help");
    EXPECT_EQ(diagnose.status, 0);
    const auto helpOf = [&](const std::string& flag) {
        const std::size_t at = diagnose.output.find("  " + flag + ",");
        if (at == std::string::npos) return std::string();
        return diagnose.output.substr(at, diagnose.output.find("\n  -", at + 1) - at); // up to the next option
    };
    EXPECT_NE(helpOf("--pairs").find("(default: off)"), std::string::npos) << helpOf("--pairs");
    EXPECT_NE(helpOf("--contact-restart").find("(default: on)"), std::string::npos) << helpOf("--contact-restart");
}

TEST(RosinCli, StringsListsEveryPreset)
{
    const CliRun r = runRosin("strings");
    ASSERT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("cello-D"), std::string::npos);
    EXPECT_NE(r.output.find("double-bass-E"), std::string::npos);
    EXPECT_NE(r.output.find("0.506"), std::string::npos); // cello D impedance
}

TEST(RosinCli, BenchFollowsThePeerProtocol)
{
    const CliRun r = runRosin("bench --seconds 0.2 --reps 2 --sr 48000 --block 256 --name ours --freq 440");
    ASSERT_EQ(r.status, 0) << r.output;
    const auto pos = r.output.find("RESULT ours ");
    ASSERT_NE(pos, std::string::npos) << r.output;
    std::stringstream ss(r.output.substr(pos + 12));
    double ns = 0, rt = 0, rms = 0;
    ss >> ns >> rt >> rms;
    EXPECT_GT(ns, 0.0);
    EXPECT_GT(rt, 1.0);  // faster than real time, or the voice is useless
    EXPECT_GT(rms, 1e-3); // it made a sound
    const auto f0 = r.output.find("f0 estimate     : ");
    ASSERT_NE(f0, std::string::npos);
    EXPECT_NEAR(std::stod(r.output.substr(f0 + 18)), 440.0, 440.0 * 0.01);
}
