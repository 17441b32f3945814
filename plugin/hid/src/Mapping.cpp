#include "rosin/hid/Mapping.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "rosin/presets/Document.h"
#include <stdexcept>

namespace rosin::hid {
namespace {
constexpr std::array<const char*, 15> sourceNames{"none", "pressure", "x", "y", "tilt_x", "tilt_y", "axis_x", "axis_y",
                                                  "axis_z", "axis_rx", "axis_ry", "axis_rz", "slider", "trigger_l", "trigger_r"};
constexpr std::array<const char*, 5> kindNames{"tablet", "gamepad", "spacemouse", "joystick", "other"};

bool hasApplication(const Descriptor& d, Usage u)
{
    return std::find(d.applications.begin(), d.applications.end(), u) != d.applications.end();
}
} // namespace

const char* kindName(DeviceKind k) { return kindNames[static_cast<std::size_t>(k)]; }

DeviceKind parseKind(const std::string& name)
{
    for (std::size_t i = 0; i < kindNames.size(); ++i)
        if (name == kindNames[i]) return static_cast<DeviceKind>(i);
    throw std::runtime_error("unknown device kind '" + name + "' (tablet, gamepad, spacemouse, joystick, other)");
}

DeviceKind classify(const Descriptor& d)
{
    if (hasApplication(d, usages::digitizer) || hasApplication(d, usages::pen) || d.findInput(usages::tipPressure))
        return DeviceKind::Tablet;
    if (hasApplication(d, usages::gamepad)) return DeviceKind::Gamepad;
    if (hasApplication(d, usages::multiAxis)) return DeviceKind::SpaceMouse;
    if (hasApplication(d, usages::joystick)) return DeviceKind::Joystick;
    return DeviceKind::Other;
}

DeviceDecoder::DeviceDecoder(Descriptor descriptor, Quirks quirks, DeviceKind kind)
    : descriptor_(std::move(descriptor)), quirks_(quirks), kind_(kind != DeviceKind::Other ? kind : classify(descriptor_))
{
}

bool DeviceDecoder::apply(const std::uint8_t* report, std::size_t size, DeviceState& s) const
{
    if (report == nullptr || size == 0) return false;
    int id = 0;
    const std::uint8_t* payload = report;
    std::size_t payloadSize = size;
    if (descriptor_.numbered) {
        id = report[0];
        ++payload;
        --payloadSize;
    }
    const ReportInfo* info = descriptor_.report(ReportType::Input, id);
    if (info == nullptr || payloadSize < static_cast<std::size_t>(info->bytes())) return false;
    const bool tablet = kind_ == DeviceKind::Tablet;
    bool sawTriggers = false;
    for (const Field& f : descriptor_.fields) {
        if (f.type != ReportType::Input || f.reportId != id || f.constant()) continue;
        const std::int64_t raw = extractRaw(f, payload, payloadSize);
        if (!f.variable()) { // array: the value names a usage (buttons pressed, keys)
            if (raw < f.logicalMin || raw > f.logicalMax) continue;
            const Usage u = f.usage + static_cast<Usage>(raw - f.logicalMin);
            if (usagePage(u) == 0x09 && usageId(u) >= 1 && usageId(u) <= 64) s.buttons |= 1ull << (usageId(u) - 1);
            continue;
        }
        const double n = normalisedValue(f, raw);
        const double centred = f.isSigned() ? n : 2.0 * n - 1.0;
        auto axis = [&](int index) {
            double& a = s.axes[static_cast<std::size_t>(index)];
            if (f.relative() && !quirks_.forceAbsolute) a = std::clamp(a + 0.01 * static_cast<double>(raw), -1.0, 1.0);
            else a = centred;
        };
        switch (f.usage) {
        case usages::tipPressure: s.pressure = n; break;
        case usages::tipSwitch: s.tip = raw != 0; break;
        case usages::inRange: s.inRange = raw != 0; break;
        case usages::xTilt: s.tiltX = f.isSigned() ? n : 2.0 * n - 1.0; break;
        case usages::yTilt: s.tiltY = f.isSigned() ? n : 2.0 * n - 1.0; break;
        case usages::x: if (tablet) s.x = n; else axis(0); break;
        case usages::y: if (tablet) s.y = n; else axis(1); break;
        case usages::z: axis(2); break;
        case usages::rx: axis(3); break;
        case usages::ry: axis(4); break;
        case usages::rz: axis(5); break;
        case usages::slider: axis(6); break;
        case usages::brake: s.triggerL = n; sawTriggers = true; break;
        case usages::accelerator: s.triggerR = n; sawTriggers = true; break;
        case usages::hat:
            if (isNull(f, raw)) s.hat = -1;
            else if (quirks_.hatDegreesPerStep > 0) s.hat = static_cast<int>(std::lround(raw * quirks_.hatDegreesPerStep / 45.0)) % 8;
            else s.hat = static_cast<int>(raw - f.logicalMin) % 8;
            break;
        default:
            if (usagePage(f.usage) == 0x09 && f.bitSize == 1) {
                const int b = usageId(f.usage);
                if (b >= 1 && b <= 64) {
                    if (raw) s.buttons |= 1ull << (b - 1);
                    else s.buttons &= ~(1ull << (b - 1));
                }
            }
            break;
        }
    }
    // A DualShock 4 reports its analog triggers as Rx/Ry (sticks are X/Y/Z/Rz).
    if (kind_ == DeviceKind::Gamepad && !sawTriggers && descriptor_.find(ReportType::Input, id, usages::rx)) {
        s.triggerL = 0.5 * (s.axes[3] + 1.0);
        s.triggerR = 0.5 * (s.axes[4] + 1.0);
    }
    return true;
}

const char* sourceName(Source s) { return sourceNames[static_cast<std::size_t>(s)]; }

Source parseSource(const std::string& name)
{
    for (std::size_t i = 0; i < sourceNames.size(); ++i)
        if (name == sourceNames[i]) return static_cast<Source>(i);
    throw std::runtime_error("unknown source '" + name + "'");
}

double read(const DeviceState& s, Source src)
{
    switch (src) {
    case Source::None: return 0.0;
    case Source::Pressure: return s.pressure;
    case Source::X: return s.x;
    case Source::Y: return s.y;
    case Source::TiltX: return s.tiltX;
    case Source::TiltY: return s.tiltY;
    case Source::AxisX: return s.axes[0];
    case Source::AxisY: return s.axes[1];
    case Source::AxisZ: return s.axes[2];
    case Source::AxisRx: return s.axes[3];
    case Source::AxisRy: return s.axes[4];
    case Source::AxisRz: return s.axes[5];
    case Source::Slider: return s.axes[6];
    case Source::TriggerL: return s.triggerL;
    case Source::TriggerR: return s.triggerR;
    }
    return 0.0;
}

double Curve::operator()(double x) const
{
    if (!std::isfinite(x)) x = inMin;
    const double span = inMax - inMin;
    double t = span != 0.0 ? (x - inMin) / span : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    if (invert) t = 1.0 - t;
    // A symmetric range (a centred stick) has its dead zone around the middle; else at the start.
    const bool centred = inMin < 0.0 && inMax > 0.0;
    if (centred) {
        double c = 2.0 * t - 1.0;
        const double a = std::abs(c);
        c = a <= deadzone ? 0.0 : std::copysign(std::pow((a - deadzone) / (1.0 - deadzone), exponent), c);
        t = 0.5 * (c + 1.0);
    } else {
        t = t <= deadzone ? 0.0 : std::pow((t - deadzone) / (1.0 - deadzone), exponent);
    }
    return outMin + t * (outMax - outMin);
}

HidMapping HidMapping::defaultFor(DeviceKind kind)
{
    HidMapping m;
    m.kind = kind;
    m.name = kindName(kind);
    if (kind != DeviceKind::Tablet) {
        // Sticks, pucks and throttles hold their position: the axis is the speed, no pen to touch.
        m.speed = Source::AxisX;
        m.speedFromMotion = false;
        m.positionCurve = {-1.0, 1.0, 0.0, 1.0};
        m.stringSelect = Source::None;
        m.requireTip = false;
        m.tipNote = -1;
        m.buttonNotes = {50, 57, -1, -1, -1, -1, -1, -1};
    }
    switch (kind) {
    case DeviceKind::Tablet: break; // the struct defaults are the tablet (CONTROLLERS.md 5)
    case DeviceKind::Gamepad:
        m.force = Source::TriggerR;
        m.forceCurve = {0.0, 1.0, 0.0, 1.0, 1.5, 0.03};
        m.position = Source::AxisY;
        m.buttonNotes = {43, 50, 57, 64, -1, -1, -1, -1};
        break;
    case DeviceKind::SpaceMouse:
        m.force = Source::AxisZ;
        m.forceCurve = {-1.0, 0.0, 0.0, 1.0, 1.5, 0.05, true}; // push down (negative Z) = more force
        m.position = Source::AxisY;
        break;
    case DeviceKind::Joystick:
        m.force = Source::AxisY;
        m.forceCurve = {-1.0, 1.0, 0.0, 1.0, 1.5, 0.0, true}; // pull back = more force
        m.position = Source::Slider;
        break;
    case DeviceKind::Other: m.force = Source::None; m.buttonNotes.fill(-1); break;
    }
    return m;
}

namespace {
nlohmann::json curveJson(const Curve& c)
{
    return {{"in", {c.inMin, c.inMax}}, {"out", {c.outMin, c.outMax}}, {"exponent", c.exponent},
            {"deadzone", c.deadzone}, {"invert", c.invert}};
}

Curve curveFrom(const presets::Document& d, const nlohmann::json& j, const std::string& where, Curve c)
{
    auto pair = [&](const char* key, double& a, double& b) {
        if (!j.contains(key)) return;
        const auto& v = j[key];
        if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number()) d.fail(where + "." + key + " must be [low, high]");
        a = v[0].get<double>();
        b = v[1].get<double>();
        if (!std::isfinite(a) || !std::isfinite(b)) d.fail(where + "." + key + " must be finite");
    };
    pair("in", c.inMin, c.inMax);
    pair("out", c.outMin, c.outMax);
    if (c.inMin == c.inMax) d.fail(where + ".in must span a range");
    const std::string w = where + ": ";
    c.exponent = d.number(j, "exponent", w, false, c.exponent, 1e-6, 10.0);
    c.deadzone = d.number(j, "deadzone", w, false, c.deadzone, 0.0, 0.999);
    c.invert = d.flag(j, "invert", w, c.invert);
    return c;
}
} // namespace

std::string HidMapping::toJson() const
{
    nlohmann::json j{{"format", "rosin-hid/2"},
                     {"name", name},
                     {"device", kindName(kind)},
                     {"force", {{"source", sourceName(force)}, {"curve", curveJson(forceCurve)}}},
                     {"speed", {{"source", sourceName(speed)}, {"from_motion", speedFromMotion}, {"scale", speedScale},
                                {"curve", curveJson(speedCurve)}, {"smoothing_s", speedSmoothing},
                                {"bow_change", bowChangeThreshold}}},
                     {"position", {{"source", sourceName(position)}, {"curve", curveJson(positionCurve)}}},
                     {"string", {{"source", sourceName(stringSelect)}, {"curve", curveJson(stringCurve)}, {"count", strings}}},
                     {"require_tip", requireTip},
                     {"tip_note", tipNote},
                     {"button_notes", buttonNotes}};
    return j.dump(2);
}

HidMapping HidMapping::fromJson(const std::string& text, const std::string& where)
{
    return fromDocument(presets::Document::parse(text, where));
}

HidMapping HidMapping::fromDocument(const presets::Document& d)
{
    const std::string format = d.text(d.root(), "format", "", false, "");
    if (format != "rosin-hid/1" && format != "rosin-hid/2") d.fail("field 'format' is '" + format + "', expected 'rosin-hid/2' (or 1)");
    const bool v1 = format == "rosin-hid/1";
    const auto& j = d.root();
    HidMapping m;
    auto kindOf = [&](const std::string& name) {
        try {
            return parseKind(name);
        } catch (const std::runtime_error& e) {
            d.fail(std::string("field 'device': ") + e.what());
        }
    };
    auto sourceOf = [&](const std::string& name, const std::string& where) {
        try {
            return parseSource(name);
        } catch (const std::runtime_error& e) {
            d.fail(where + "field 'source': " + e.what());
        }
    };
    m = defaultFor(kindOf(d.text(j, "device")));
    m.name = d.text(j, "name", "", false, m.name);
    auto section = [&](const char* key, Source& src, Curve& curve) {
        const auto& s = d.object(j, key, "", false);
        const std::string where = std::string(key) + ": ";
        if (s.contains("source")) src = sourceOf(d.text(s, "source", where), where);
        if (s.contains("curve")) curve = curveFrom(d, d.object(s, "curve", where), std::string(key) + ".curve", curve);
    };
    if (v1) { // version 1's defaults, in its units, before the file's own values
        m.forceCurve.outMin = 0.0, m.forceCurve.outMax = 2.5;
        m.speedCurve.outMin = -0.6, m.speedCurve.outMax = 0.6;
        m.positionCurve.outMin = 0.03, m.positionCurve.outMax = 0.25;
    }
    section("force", m.force, m.forceCurve);
    section("speed", m.speed, m.speedCurve);
    section("position", m.position, m.positionCurve);
    section("string", m.stringSelect, m.stringCurve);
    const auto& speed = d.object(j, "speed", "", false);
    m.speedFromMotion = d.flag(speed, "from_motion", "speed: ", m.speedFromMotion);
    m.speedSmoothing = d.number(speed, "smoothing_s", "speed: ", false, m.speedSmoothing, 0.0, 0.999);
    if (v1) {
        // Version 1 wrote newtons, m/s and beta. Its maps meant them for the instruments' default
        // bow (1.1 N, 0.15 m/s, beta 0.0899), so they become the same bow there, normalised.
        constexpr double forceFull = 2.0 * 1.1, speedFull = 2.0 * 0.15, betaNominal = 0.0899;
        m.speedScale = d.number(speed, "scale_m", "speed: ", false, 0.22, 1e-6, 10.0) / speedFull;
        m.bowChangeThreshold = d.number(speed, "bow_change_m_s", "speed: ", false, 0.02, 0.0, 10.0) / speedFull;
        auto position = [&](double beta) { return std::clamp(0.5 + 0.5 * std::log2(std::max(beta, 1e-6) / betaNominal), 0.0, 1.0); };
        m.forceCurve.outMin = std::clamp(m.forceCurve.outMin / forceFull, 0.0, 1.0);
        m.forceCurve.outMax = std::clamp(m.forceCurve.outMax / forceFull, 0.0, 1.0);
        m.speedCurve.outMin = std::clamp(m.speedCurve.outMin / speedFull, -1.0, 1.0);
        m.speedCurve.outMax = std::clamp(m.speedCurve.outMax / speedFull, -1.0, 1.0);
        m.positionCurve.outMin = position(m.positionCurve.outMin);
        m.positionCurve.outMax = position(m.positionCurve.outMax);
    } else {
        m.speedScale = d.number(speed, "scale", "speed: ", false, m.speedScale, 1e-6, 100.0);
        m.bowChangeThreshold = d.number(speed, "bow_change", "speed: ", false, m.bowChangeThreshold, 0.0, 1.0);
        auto within = [&](const Curve& c, double lo, double hi, const char* what) {
            if (c.outMin < lo || c.outMin > hi || c.outMax < lo || c.outMax > hi)
                d.fail(std::string(what) + ".curve.out must lie within [" + nlohmann::json(lo).dump() + ", " + nlohmann::json(hi).dump() + "]");
        };
        within(m.forceCurve, 0.0, 1.0, "force");
        within(m.speedCurve, -1.0, 1.0, "speed");
        within(m.positionCurve, 0.0, 1.0, "position");
    }
    m.strings = d.integer(d.object(j, "string", "", false), "count", "string: ", false, m.strings, 1, 5);
    m.requireTip = d.flag(j, "require_tip", "", m.requireTip);
    m.tipNote = d.integer(j, "tip_note", "", false, m.tipNote, -1, 127);
    if (j.contains("button_notes")) {
        const auto& b = d.array(j, "button_notes");
        if (b.size() > m.buttonNotes.size()) d.fail("field 'button_notes' holds at most 8 notes");
        m.buttonNotes.fill(-1);
        for (std::size_t i = 0; i < b.size(); ++i) {
            if (!b[i].is_number_integer() || b[i].get<int>() < -1 || b[i].get<int>() > 127)
                d.fail("button_notes[" + std::to_string(i) + "] must be a note number 0-127, or -1");
            m.buttonNotes[i] = b[i].get<int>();
        }
    }
    return m;
}

void BowMapper::reset()
{
    haveLast_ = wasEngaged_ = false;
    speed_ = 0.0;
    direction_ = 0;
    heldTipNote_ = -1;
    lastButtons_ = 0;
    held_.clear();
}

void BowMapper::noteOn(int note, double seconds, std::vector<Event>& out)
{
    if (note < 0 || std::find(held_.begin(), held_.end(), note) != held_.end()) return;
    held_.push_back(note);
    Event e;
    e.kind = Event::Kind::NoteOn;
    e.seconds = seconds;
    e.note = static_cast<std::int8_t>(note);
    out.push_back(e);
}

void BowMapper::noteOff(int note, double seconds, std::vector<Event>& out)
{
    const auto it = std::find(held_.begin(), held_.end(), note);
    if (note < 0 || it == held_.end()) return;
    held_.erase(it);
    Event e;
    e.kind = Event::Kind::NoteOff;
    e.seconds = seconds;
    e.note = static_cast<std::int8_t>(note);
    out.push_back(e);
}

void BowMapper::update(const DeviceState& s, double seconds, std::vector<Event>& out)
{
    const HidMapping& m = mapping_;
    Event c;
    c.kind = Event::Kind::Bow;
    c.seconds = seconds;
    const double force = m.force == Source::None ? 0.0 : m.forceCurve(read(s, m.force));
    c.engaged = m.requireTip ? (s.tip || (s.inRange && s.pressure > 0.0)) : force > 1e-4;

    if (m.speedFromMotion) {
        const double coord = read(s, m.speed);
        if (haveLast_ && seconds > lastTime_) {
            const double dt = seconds - lastTime_;
            const double raw = (coord - lastCoord_) / dt * m.speedScale;
            const double a = m.speedSmoothing > 0.0 ? 1.0 - std::exp(-dt / m.speedSmoothing) : 1.0;
            speed_ += a * (raw - speed_);
        }
        lastCoord_ = coord;
    } else {
        speed_ = m.speed == Source::None ? 0.0 : m.speedCurve(read(s, m.speed));
    }
    if (!std::isfinite(speed_)) speed_ = 0.0;
    haveLast_ = true;
    lastTime_ = seconds;

    const int dir = speed_ > m.bowChangeThreshold ? 1 : speed_ < -m.bowChangeThreshold ? -1 : 0;
    if (dir != 0) {
        c.bowChange = direction_ != 0 && dir != direction_ && c.engaged;
        direction_ = dir;
    }
    c.force = static_cast<float>(c.engaged ? std::clamp(force, 0.0, 1.0) : 0.0);
    c.speed = static_cast<float>(std::clamp(speed_, -1.0, 1.0));
    c.position = static_cast<float>(m.position == Source::None ? 0.5 : std::clamp(m.positionCurve(read(s, m.position)), 0.0, 1.0));
    if (m.stringSelect != Source::None && m.strings > 0)
        c.string = static_cast<std::int8_t>(std::clamp(static_cast<int>(m.stringCurve(read(s, m.stringSelect)) * m.strings), 0, m.strings - 1));
    out.push_back(c);

    if (c.engaged && !wasEngaged_ && m.tipNote >= 0 && m.requireTip) {
        heldTipNote_ = m.tipNote;
        noteOn(heldTipNote_, seconds, out);
    }
    if (!c.engaged && wasEngaged_ && heldTipNote_ >= 0) {
        noteOff(heldTipNote_, seconds, out);
        heldTipNote_ = -1;
    }
    for (std::size_t b = 0; b < m.buttonNotes.size(); ++b) {
        const bool now = s.buttons & (1ull << b), before = lastButtons_ & (1ull << b);
        if (now && !before) noteOn(m.buttonNotes[b], seconds, out);
        if (!now && before) noteOff(m.buttonNotes[b], seconds, out);
    }
    lastButtons_ = s.buttons;
    wasEngaged_ = c.engaged;
}

void BowMapper::release(double seconds, std::vector<Event>& out)
{
    while (!held_.empty()) noteOff(held_.back(), seconds, out);
    Event r;
    r.kind = Event::Kind::Released;
    r.seconds = seconds;
    out.push_back(r);
    reset();
}

} // namespace rosin::hid
