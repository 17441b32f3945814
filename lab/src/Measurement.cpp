#include "rosin/lab/Measurement.h"

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "rosin/lab/Error.h"
#include "rosin/lab/Output.h"

namespace rosin::lab {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

[[noreturn]] void fail(const fs::path& file, const std::string& field, const std::string& what)
{
    throw LabError(file.string() + ": field '" + field + "' " + what);
}

double positive(const json& obj, const char* key, const fs::path& file, const std::string& where, bool required = true,
                double def = 0.0)
{
    if (!obj.is_object() || !obj.contains(key)) {
        if (required) fail(file, where + key, "is missing");
        return def;
    }
    const json& v = obj[key];
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() <= 0.0)
        fail(file, where + key, "must be a positive number");
    return v.get<double>();
}

/// steady_sliding.csv: header `speed_m_s,mu` and optionally `,force_n`; every value finite,
/// speeds >= 0, mu > 0 (MEASUREMENT_FORMAT.md).
std::vector<SteadySlidingPoint> readSteadySliding(const fs::path& file)
{
    std::ifstream in(file);
    if (!in) throw LabError(file.string() + ": cannot be read");
    std::string line;
    if (!std::getline(in, line)) throw LabError(file.string() + ":1: empty file (expected the header speed_m_s,mu)");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> cols;
    for (std::stringstream ss(line); std::getline(ss, line, ',');) cols.push_back(line);
    int iv = -1, im = -1, iforce = -1;
    for (int k = 0; k < static_cast<int>(cols.size()); ++k) {
        if (cols[static_cast<std::size_t>(k)] == "speed_m_s") iv = k;
        else if (cols[static_cast<std::size_t>(k)] == "mu") im = k;
        else if (cols[static_cast<std::size_t>(k)] == "force_n") iforce = k;
    }
    if (iv < 0 || im < 0) throw LabError(file.string() + ":1: header must name the columns speed_m_s and mu");
    std::vector<SteadySlidingPoint> out;
    int lineNo = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        std::vector<double> v;
        for (std::stringstream ss(line); std::getline(ss, line, ',');) {
            char* end = nullptr;
            const double x = std::strtod(line.c_str(), &end);
            if (end == line.c_str() || !std::isfinite(x))
                throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field '" + cols[std::min(v.size(), cols.size() - 1)] + "' is not a number");
            v.push_back(x);
        }
        if (v.size() != cols.size()) throw LabError(file.string() + ":" + std::to_string(lineNo) + ": expected " + std::to_string(cols.size()) + " values");
        SteadySlidingPoint p{v[static_cast<std::size_t>(iv)], v[static_cast<std::size_t>(im)], iforce >= 0 ? v[static_cast<std::size_t>(iforce)] : 0.0};
        if (p.speed < 0.0) throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field 'speed_m_s' must not be negative");
        if (!(p.mu > 0.0)) throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field 'mu' must be positive");
        if (iforce >= 0 && !(p.force > 0.0)) throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field 'force_n' must be positive");
        out.push_back(p);
    }
    if (out.size() < 2) throw LabError(file.string() + ": needs at least two rows of steady-sliding data");
    return out;
}

std::vector<double> readWavChannel(const fs::path& file, int channel, double manifestRate, std::vector<std::string>& warnings)
{
    SF_INFO info{};
    SNDFILE* sf = sf_open(file.c_str(), SFM_READ, &info);
    if (!sf) throw LabError(file.string() + ": not a readable WAV (" + sf_strerror(nullptr) + ")");
    if (channel < 0 || channel >= info.channels) {
        sf_close(sf);
        throw LabError(file.string() + ": channel " + std::to_string(channel) + " does not exist (the file has " +
                       std::to_string(info.channels) + ")");
    }
    // libsndfile reads a cut-off file up to where the data stops and notes in its log that
    // the data chunk "should be" shorter than the header says: that is a truncated recording.
    char log[4096] = {0};
    sf_command(sf, SFC_GET_LOG_INFO, log, sizeof log);
    std::vector<double> all(static_cast<std::size_t>(info.frames) * static_cast<std::size_t>(info.channels));
    const sf_count_t got = sf_readf_double(sf, all.data(), info.frames);
    sf_close(sf);
    std::istringstream lines(log);
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("data", 0) == 0 && line.find("should be") != std::string::npos)
            throw LabError(file.string() + ": truncated: the header's data size is larger than the file (" + line + ")");
    if (got != info.frames) throw LabError(file.string() + ": truncated: read " + std::to_string(got) + " of " + std::to_string(info.frames) + " frames");
    if (std::abs(info.samplerate - manifestRate) > 0.5)
        warnings.push_back(file.string() + ": the file says " + std::to_string(info.samplerate) + " Hz, the manifest " +
                           std::to_string(manifestRate) + " Hz; the manifest's rate is used");
    std::vector<double> x(static_cast<std::size_t>(info.frames));
    for (sf_count_t i = 0; i < info.frames; ++i) {
        x[i] = all[static_cast<std::size_t>(i) * static_cast<std::size_t>(info.channels) + static_cast<std::size_t>(channel)];
        if (!std::isfinite(x[i])) throw LabError(file.string() + ": sample " + std::to_string(i) + " is not a finite number");
    }
    if (x.size() < 64) throw LabError(file.string() + ": too short (" + std::to_string(x.size()) + " samples)");
    return x;
}

std::vector<double> readCsvForce(const fs::path& file, double manifestRate)
{
    std::ifstream in(file);
    if (!in) throw LabError(file.string() + ": cannot open");
    std::string line;
    if (!std::getline(in, line)) throw LabError(file.string() + ": empty file");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line != "time_s,force") throw LabError(file.string() + ":1: header must be 'time_s,force'");
    std::vector<double> t, x;
    int lineNo = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        const auto comma = line.find(',');
        if (comma == std::string::npos) throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field 'force' is missing");
        auto number = [&](const std::string& s, const char* field) {
            if (const std::optional<double> v = wholeNumber(s); v && std::isfinite(*v)) return *v;
            throw LabError(file.string() + ":" + std::to_string(lineNo) + ": field '" + field + "' is not a finite number");
        };
        t.push_back(number(line.substr(0, comma), "time_s"));
        x.push_back(number(line.substr(comma + 1), "force"));
    }
    if (x.size() < 64) throw LabError(file.string() + ": too short (" + std::to_string(x.size()) + " rows)");
    const double rate = static_cast<double>(t.size() - 1) / (t.back() - t.front());
    if (!(rate > 0) || std::abs(rate / manifestRate - 1.0) > 0.01)
        throw LabError(file.string() + ": field 'time_s' steps at " + std::to_string(rate) +
                       " Hz, contradicting the manifest's sample_rate_hz " + std::to_string(manifestRate));
    return x;
}

} // namespace

Gesture strokeGesture(const MeasuredStroke& s, double beta)
{
    Gesture g;
    g.beta = beta;
    if (s.gesture == "exp_speed") {
        g.kind = GestureKind::ExpSpeed;
        g.speed = s.v0;
        g.timeConstant = s.tv;
        g.force = s.force;
    } else if (s.gesture == "exp_force") {
        g.kind = GestureKind::ExpForce;
        g.speed = s.speed;
        g.timeConstant = s.tf;
        g.force = s.f0;
    } else {
        g.kind = GestureKind::Guettler;
        g.acceleration = s.accel;
        g.force = s.force;
    }
    return g;
}

MeasurementSet readMeasurementSet(const fs::path& folder)
{
    const fs::path manifest = folder / "manifest.json";
    if (!fs::is_directory(folder)) throw LabError(folder.string() + ": no such measurement set folder");
    std::ifstream in(manifest);
    if (!in) throw LabError(manifest.string() + ": missing (every set needs a manifest.json)");
    json doc;
    try {
        doc = json::parse(in);
    } catch (const json::exception& e) {
        throw LabError(manifest.string() + ": not valid JSON (" + e.what() + ")");
    }
    if (!doc.is_object() || doc.value("format", "") != "rosin-measurement/1")
        fail(manifest, "format", "must be \"rosin-measurement/1\"");
    MeasurementSet set;
    set.folder = folder;
    set.description = doc.value("description", "");
    if (!doc.contains("rig") || !doc["rig"].is_object()) fail(manifest, "rig", "is missing");
    const json& rig = doc["rig"];
    if (!rig.contains("string") || !rig["string"].is_object()) fail(manifest, "rig.string", "is missing");
    const json& str = rig["string"];
    set.stringName = str.value("name", "");
    set.f0 = positive(str, "f0_hz", manifest, "rig.string.");
    if (str.contains("length_m")) set.length = positive(str, "length_m", manifest, "rig.string.");
    if (str.contains("tension_n")) set.tension = positive(str, "tension_n", manifest, "rig.string.");
    if (str.contains("z0_kg_per_s")) set.z0 = positive(str, "z0_kg_per_s", manifest, "rig.string.");
    set.beta = positive(rig, "beta", manifest, "rig.");
    if (set.beta >= 0.5) fail(manifest, "rig.beta", "must be below 0.5");
    // A prior narrower than 0.1 % leaves the fits nothing to move; one wider than 20 % is not a
    // measured rig.
    const auto uncertainty = [&](const json& obj, const char* key, const std::string& where) {
        const double u = positive(obj, key, manifest, where);
        if (u < 0.001 || u > 0.2) fail(manifest, where + key, "must be a fraction from 0.001 to 0.2 (0.01 is +-1 %)");
        return u;
    };
    if (str.contains("tension_uncertainty")) set.tensionUncertainty = uncertainty(str, "tension_uncertainty", "rig.string.");
    if (rig.contains("beta_uncertainty")) set.betaUncertainty = uncertainty(rig, "beta_uncertainty", "rig.");
    // A string constant the lab measured, one of a pair that is stated together: it must be there
    // once its partner is, and within what any string has.
    const auto measured = [&](const char* key, const char* pair, double lo, double hi, const char* what) {
        if (!str.contains(key)) fail(manifest, std::string("rig.string.") + key, std::string("is missing (") + pair + " are stated together)");
        const double v = positive(str, key, manifest, "rig.string.");
        if (v < lo || v > hi) fail(manifest, std::string("rig.string.") + key, what);
        return v;
    };
    // A measured Q comes as a pair: the model's losses are set by both ends of its band.
    if (str.contains("q_f0") || str.contains("q_5khz")) {
        set.qAtF0 = measured("q_f0", "q_f0 and q_5khz", 5.0, 1e5, "must be a Q from 5 to 100000");
        set.qAt5kHz = measured("q_5khz", "q_f0 and q_5khz", 5.0, 1e5, "must be a Q from 5 to 100000");
    }
    // So do the torsional constants: the roll's softening involves Z_t c_t, its decay Q_t.
    if (str.contains("torsion_speed_ratio") || str.contains("q_torsion")) {
        const char* pair = "torsion_speed_ratio and q_torsion";
        set.torsionSpeedRatio = measured("torsion_speed_ratio", pair, 1.2, 15.0, "must be a c_t / c from 1.2 to 15");
        set.qTorsion = measured("q_torsion", pair, 3.0, 1000.0, "must be a torsional Q from 3 to 1000");
    }
    set.exciter = rig.value("exciter", "unknown");
    if (set.exciter != "bow" && set.exciter != "rod" && set.exciter != "unknown")
        fail(manifest, "rig.exciter", "must be \"bow\", \"rod\" or \"unknown\"");
    if (rig.contains("ambient_c")) {
        if (!rig["ambient_c"].is_number() || !std::isfinite(rig["ambient_c"].get<double>()))
            fail(manifest, "rig.ambient_c", "must be a number");
        set.ambient = rig["ambient_c"].get<double>();
    }
    if (!rig.contains("sensor") || !rig["sensor"].is_object()) fail(manifest, "rig.sensor", "is missing");
    const json& sensor = rig["sensor"];
    if (sensor.value("quantity", "bridge_force") != "bridge_force") fail(manifest, "rig.sensor.quantity", "must be \"bridge_force\"");
    set.units = sensor.value("units", "");
    if (set.units != "N" && set.units != "V") fail(manifest, "rig.sensor.units", "must be \"N\" or \"V\"");
    set.sampleRate = positive(sensor, "sample_rate_hz", manifest, "rig.sensor.");
    if (!doc.contains("gesture") || !doc["gesture"].is_object()) fail(manifest, "gesture", "is missing");
    set.gesture = doc["gesture"].value("kind", "");
    auto strokeKind = [](const std::string& k) { return k == "guettler" || k == "exp_speed" || k == "exp_force"; };
    if (!strokeKind(set.gesture) && set.gesture != "mixed")
        fail(manifest, "gesture.kind", "must be \"guettler\", \"exp_speed\", \"exp_force\" or \"mixed\"");
    if (!doc.contains("transients") || !doc["transients"].is_array() || doc["transients"].empty())
        fail(manifest, "transients", "must be a non-empty array");
    std::set<std::string> ids;
    int index = 0;
    for (const json& t : doc["transients"]) {
        const std::string where = "transients[" + std::to_string(index++) + "].";
        if (!t.is_object()) fail(manifest, where.substr(0, where.size() - 1), "must be an object");
        MeasuredStroke s;
        s.id = t.value("id", "");
        if (s.id.empty()) fail(manifest, where + "id", "is missing");
        if (!ids.insert(s.id).second) fail(manifest, where + "id", "repeats '" + s.id + "'");
        if (!t.contains("file") || !t["file"].is_string()) fail(manifest, where + "file", "is missing");
        s.file = folder / t["file"].get<std::string>();
        s.channel = t.value("channel", 0);
        if (s.channel < 0) fail(manifest, where + "channel", "must not be negative");
        // A stroke may name its own gesture; in a mixed set every stroke must.
        s.gesture = set.gesture;
        if (t.contains("gesture")) {
            if (!t["gesture"].is_string() || !strokeKind(t["gesture"].get<std::string>()))
                fail(manifest, where + "gesture", "must be \"guettler\", \"exp_speed\" or \"exp_force\"");
            s.gesture = t["gesture"].get<std::string>();
        } else if (set.gesture == "mixed") {
            fail(manifest, where + "gesture", "is missing (gesture.kind is \"mixed\": each transient names its own)");
        }
        if (s.gesture == "guettler") {
            s.accel = positive(t, "accel_m_s2", manifest, where);
            s.force = positive(t, "force_n", manifest, where);
        } else if (s.gesture == "exp_speed") {
            s.v0 = positive(t, "v0_m_s", manifest, where);
            s.tv = positive(t, "tv_s", manifest, where);
            s.force = positive(t, "force_n", manifest, where);
        } else {
            s.speed = positive(t, "speed_m_s", manifest, where);
            s.f0 = positive(t, "f0_n", manifest, where);
            s.tf = positive(t, "tf_s", manifest, where);
        }
        if (t.contains("trigger_s")) {
            if (!t["trigger_s"].is_number() || t["trigger_s"].get<double>() < 0) fail(manifest, where + "trigger_s", "must be a number >= 0");
            s.trigger = t["trigger_s"].get<double>();
        }
        if (!fs::exists(s.file)) fail(manifest, where + "file", "names " + s.file.string() + ", which does not exist");
        if (s.file.extension() == ".wav") s.signal = readWavChannel(s.file, s.channel, set.sampleRate, set.warnings);
        else if (s.file.extension() == ".csv") s.signal = readCsvForce(s.file, set.sampleRate);
        else fail(manifest, where + "file", "must be a .wav or .csv file");
        set.strokes.push_back(std::move(s));
    }
    if (doc.contains("two_ended")) {
        if (!doc["two_ended"].is_array()) fail(manifest, "two_ended", "must be an array");
        int k = 0;
        for (const json& t : doc["two_ended"]) {
            const std::string where = "two_ended[" + std::to_string(k++) + "].";
            TwoEndedRecording r;
            r.id = t.value("id", "");
            if (r.id.empty()) fail(manifest, where + "id", "is missing");
            if (!t.contains("file") || !t["file"].is_string()) fail(manifest, where + "file", "is missing");
            r.file = folder / t["file"].get<std::string>();
            if (!fs::exists(r.file)) fail(manifest, where + "file", "names " + r.file.string() + ", which does not exist");
            r.bowSpeed = positive(t, "bow_speed_m_s", manifest, where);
            r.force = positive(t, "force_n", manifest, where);
            r.bridgeChannel = t.value("bridge_channel", 0);
            r.farChannel = t.value("far_end_channel", 1);
            if (r.bridgeChannel == r.farChannel) fail(manifest, where + "far_end_channel", "must differ from bridge_channel");
            r.bridge = readWavChannel(r.file, r.bridgeChannel, set.sampleRate, set.warnings);
            r.far = readWavChannel(r.file, r.farChannel, set.sampleRate, set.warnings);
            set.twoEnded.push_back(std::move(r));
        }
    }
    if (doc.contains("steady_sliding")) {
        const json& ss = doc["steady_sliding"];
        if (!ss.is_object() || !ss.contains("file") || !ss["file"].is_string()) fail(manifest, "steady_sliding.file", "is missing");
        set.steadySliding = folder / ss["file"].get<std::string>();
        if (!fs::exists(*set.steadySliding)) fail(manifest, "steady_sliding.file", "names a file that does not exist");
        set.steady = readSteadySliding(*set.steadySliding);
    }
    return set;
}

void writeMeasurementSet(const fs::path& folder, const MeasurementSet& set, int wavFormat)
{
    if (fs::exists(folder)) throw LabError(folder.string() + ": already exists (choose a new folder)");
    const fs::path parent = folder.has_parent_path() ? folder.parent_path() : fs::path(".");
    if (!fs::is_directory(parent)) throw LabError(folder.string() + ": the directory " + parent.string() + " does not exist");
    // Build under a temporary name, then rename: a half-written set never appears.
    std::string hidden = ".";
    hidden += folder.filename().string();
    hidden += ".partial";
    const fs::path tmp = parent / hidden;
    fs::remove_all(tmp);
    fs::create_directories(tmp / "transients");
    try {
        json strokes = json::array();
        for (const auto& s : set.strokes) {
            const std::string rel = "transients/" + s.id + ".wav";
            if (wavFormat != SF_FORMAT_FLOAT && wavFormat != SF_FORMAT_DOUBLE) {
                double peak = 0.0;
                for (double v : s.signal) peak = std::max(peak, std::abs(v));
                if (peak >= 1.0)
                    throw LabError(s.id + ": peak " + std::to_string(peak) + " " + set.units +
                                   " would clip a PCM file (full scale 1.0): use float WAV or units V");
            }
            writeWavFrames(tmp / rel, s.signal, 1, set.sampleRate, wavFormat);
            json t{{"id", s.id}, {"file", rel}, {"channel", 0}};
            if (set.gesture == "mixed") t["gesture"] = s.gesture;
            if (s.gesture == "guettler") { t["accel_m_s2"] = s.accel; t["force_n"] = s.force; }
            else if (s.gesture == "exp_speed") { t["v0_m_s"] = s.v0; t["tv_s"] = s.tv; t["force_n"] = s.force; }
            else { t["speed_m_s"] = s.speed; t["f0_n"] = s.f0; t["tf_s"] = s.tf; }
            if (s.trigger) t["trigger_s"] = *s.trigger;
            strokes.push_back(t);
        }
        json twoEnded = json::array();
        if (!set.twoEnded.empty()) fs::create_directories(tmp / "two_ended");
        for (const auto& r : set.twoEnded) {
            const std::string rel = "two_ended/" + r.id + ".wav";
            std::vector<double> frames(2 * r.bridge.size());
            for (std::size_t i = 0; i < r.bridge.size(); ++i) {
                frames[2 * i] = r.bridge[i];
                frames[2 * i + 1] = r.far[i];
            }
            writeWavFrames(tmp / rel, frames, 2, set.sampleRate, SF_FORMAT_FLOAT);
            twoEnded.push_back({{"id", r.id}, {"bow_speed_m_s", r.bowSpeed}, {"force_n", r.force}, {"file", rel},
                                {"bridge_channel", 0}, {"far_end_channel", 1}});
        }
        json str{{"name", set.stringName}, {"f0_hz", set.f0}};
        if (set.length) str["length_m"] = *set.length;
        if (set.tension) str["tension_n"] = *set.tension;
        if (set.z0) str["z0_kg_per_s"] = *set.z0;
        if (set.tensionUncertainty) str["tension_uncertainty"] = *set.tensionUncertainty;
        if (set.qAtF0 && set.qAt5kHz) {
            str["q_f0"] = *set.qAtF0;
            str["q_5khz"] = *set.qAt5kHz;
        }
        if (set.torsionSpeedRatio && set.qTorsion) {
            str["torsion_speed_ratio"] = *set.torsionSpeedRatio;
            str["q_torsion"] = *set.qTorsion;
        }
        json rig{{"string", str}, {"beta", set.beta}, {"exciter", set.exciter},
                 {"sensor", {{"quantity", "bridge_force"}, {"units", set.units}, {"sample_rate_hz", set.sampleRate}}}};
        if (set.betaUncertainty) rig["beta_uncertainty"] = *set.betaUncertainty;
        if (set.ambient) rig["ambient_c"] = *set.ambient;
        const json doc{{"format", "rosin-measurement/1"}, {"description", set.description}, {"rig", rig},
                       {"gesture", {{"kind", set.gesture}}}, {"transients", strokes}};
        json full = doc;
        if (!twoEnded.empty()) full["two_ended"] = twoEnded;
        if (!set.steady.empty()) {
            std::ofstream csv(tmp / "steady_sliding.csv");
            const bool withForce = std::all_of(set.steady.begin(), set.steady.end(), [](const auto& p) { return p.force > 0.0; });
            csv << (withForce ? "speed_m_s,mu,force_n\n" : "speed_m_s,mu\n");
            char row[96];
            for (const auto& p : set.steady) {
                if (withForce) std::snprintf(row, sizeof row, "%.9g,%.9g,%.9g\n", p.speed, p.mu, p.force);
                else std::snprintf(row, sizeof row, "%.9g,%.9g\n", p.speed, p.mu);
                csv << row;
            }
            full["steady_sliding"] = {{"file", "steady_sliding.csv"}};
        }
        std::ofstream(tmp / "manifest.json") << full.dump(1) << "\n";
        fs::rename(tmp, folder);
    } catch (...) {
        std::error_code ec;
        fs::remove_all(tmp, ec);
        throw;
    }
}

} // namespace rosin::lab
