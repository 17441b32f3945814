// From device reports to the bow: a synthetic pen stroke and gamepad input through the real
// descriptors, the decoder and the mapper; curves, calibration, mapping files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "rosin/hid/Descriptor.h"
#include "rosin/hid/Mapping.h"
#include "rosin/hid/Recording.h"

using namespace rosin::hid;
namespace fs = std::filesystem;

namespace {
const fs::path data = ROSIN_HID_DATA;

/// Builds reports for a descriptor by usage (the inverse of the decoder).
struct ReportWriter {
    const Descriptor& d;
    int id;
    std::vector<std::uint8_t> bytes;

    ReportWriter(const Descriptor& desc, int reportId) : d(desc), id(reportId)
    {
        const ReportInfo* r = d.report(ReportType::Input, id);
        bytes.assign(static_cast<std::size_t>(r->bytes() + (d.numbered ? 1 : 0)), 0);
        if (d.numbered) bytes[0] = static_cast<std::uint8_t>(id);
    }
    ReportWriter& set(Usage u, std::int64_t value)
    {
        const Field* f = d.find(ReportType::Input, id, u);
        if (!f) throw std::runtime_error("no such field");
        const std::size_t base = d.numbered ? 1 : 0;
        for (int b = 0; b < f->bitSize; ++b) {
            const std::size_t bit = static_cast<std::size_t>(f->bitOffset + b);
            auto& byte = bytes[base + bit / 8];
            if ((static_cast<std::uint64_t>(value) >> b) & 1u) byte |= static_cast<std::uint8_t>(1u << (bit % 8));
            else byte &= static_cast<std::uint8_t>(~(1u << (bit % 8)));
        }
        return *this;
    }
};
} // namespace

namespace {
/// The events of one report: its bow state and the notes that started or ended in it.
struct Report {
    Event bow;
    std::vector<Event> notes;
};
Report split(const std::vector<Event>& events)
{
    Report r;
    for (const Event& e : events) {
        if (e.kind == Event::Kind::Bow) r.bow = e;
        else r.notes.push_back(e);
    }
    return r;
}
} // namespace

TEST(HidMapping, PenStrokeGivesForceSpeedPositionAndOneBowChange)
{
    const Descriptor d = parseDescriptor(readBinary(data / "huion_h640p_256c_006d_pen.rdesc.bin"));
    DeviceDecoder decoder(d, {});
    ASSERT_EQ(decoder.kind(), DeviceKind::Tablet);
    BowMapper mapper(HidMapping::defaultFor(DeviceKind::Tablet));
    DeviceState s;
    std::vector<Report> out;
    const double dt = 0.005; // 200 reports per second
    double t = 0.0, x = 0.2;
    auto report = [&](bool tip, double pressure, double xPos, double tilt) {
        ReportWriter w(d, 10);
        w.set(usages::inRange, 1).set(usages::tipSwitch, tip ? 1 : 0);
        w.set(usages::x, std::llround(xPos * 32767)).set(usages::y, 16384);
        w.set(usages::tipPressure, std::llround(pressure * 8191)).set(usages::xTilt, std::llround(tilt * 127));
        ASSERT_TRUE(decoder.apply(w.bytes.data(), w.bytes.size(), s));
        std::vector<Event> events;
        mapper.update(s, t, events);
        out.push_back(split(events));
        t += dt;
    };
    for (int i = 0; i < 10; ++i) report(false, 0.0, x, -0.5);                   // hovering
    for (int i = 1; i <= 20; ++i) report(true, i / 20.0, x, -0.5);              // pressure up, still
    const std::size_t moveStart = out.size();
    for (int i = 0; i < 100; ++i) report(true, 1.0, x += 0.4 * dt / 0.5, -0.5); // right: 0.8 of the width per s
    const std::size_t reverse = out.size();
    for (int i = 0; i < 100; ++i) report(true, 1.0, x -= 0.4 * dt / 0.5, -0.5); // back
    report(false, 0.0, x, -0.5);                                                 // lift

    // Hovering: no bow. Touch: note on; the force follows the pressure curve up to 1 (twice the
    // instrument's nominal bow force).
    EXPECT_FALSE(out[5].bow.engaged);
    ASSERT_EQ(out[10].notes.size(), 1u);
    EXPECT_EQ(out[10].notes[0].kind, Event::Kind::NoteOn);
    EXPECT_EQ(out[10].notes[0].note, 50);
    EXPECT_TRUE(out[10].bow.engaged);
    for (std::size_t i = 11; i < 30; ++i) EXPECT_GE(out[i].bow.force, out[i - 1].bow.force);
    EXPECT_NEAR(out[29].bow.force, 1.0, 0.005);
    EXPECT_NEAR(out[20].bow.force, std::pow(0.55, 1.5), 0.005); // 11th of 20 steps
    // Speed: 0.8 widths/s x 0.75 = 0.6 (1.2 x the nominal bow speed) once the 30 ms smoothing
    // has settled; then the reverse.
    const double v = 0.8 * 0.75;
    EXPECT_NEAR(out[reverse - 1].bow.speed, v, 0.01 * v);
    EXPECT_NEAR(out[out.size() - 2].bow.speed, -v, 0.01 * v); // the last report before the lift
    EXPECT_NEAR(out[moveStart + 50].bow.position, 0.5, 1e-3); // y centred: the nominal bow position
    EXPECT_EQ(out[moveStart + 50].bow.string, 0); // tilt -0.5 of the -0.6..0.6 range: the lowest string
    int changes = 0;
    std::size_t at = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
        if (out[i].bow.bowChange) { ++changes; at = i; }
    EXPECT_EQ(changes, 1);
    EXPECT_GE(at, reverse);
    EXPECT_LE((at - reverse) * dt, 0.03); // heard within 30 ms of the hand turning
    EXPECT_FALSE(out.back().bow.engaged);
    ASSERT_EQ(out.back().notes.size(), 1u);
    EXPECT_EQ(out.back().notes[0].kind, Event::Kind::NoteOff);
    EXPECT_EQ(out.back().notes[0].note, 50);
    EXPECT_EQ(out.back().bow.force, 0.0f);
}

TEST(HidMapping, GamepadTriggerDrivesBowForceAndTheStickTheSpeed)
{
    const Descriptor d = parseDescriptor(readBinary(data / "xbox_wireless_bt_045e_02fd.rdesc.bin"));
    DeviceDecoder decoder(d, {});
    ASSERT_EQ(decoder.kind(), DeviceKind::Gamepad);
    BowMapper mapper(HidMapping::defaultFor(DeviceKind::Gamepad));
    DeviceState s;
    double previous = -1.0;
    std::vector<Event> events;
    for (int v = 0; v <= 1023; v += 31) {
        ReportWriter w(d, 1);
        w.set(usages::x, 65535).set(usages::y, 32768).set(usages::z, 32768).set(usages::rz, 32768);
        w.set(usages::accelerator, v).set(usages::brake, 0);
        ASSERT_TRUE(decoder.apply(w.bytes.data(), w.bytes.size(), s));
        events.clear();
        mapper.update(s, v * 0.001, events);
        const Event c = split(events).bow;
        EXPECT_GE(c.force, previous);
        previous = c.force;
        EXPECT_EQ(c.engaged, c.force > 1e-4f);
        EXPECT_NEAR(c.speed, 1.0, 1e-3); // stick full right: the curve's top speed
    }
    EXPECT_NEAR(previous, std::pow((1023.0 / 1023.0 - 0.03) / 0.97, 1.5), 0.005);
    // Button 1 holds note 43; releasing it ends the note.
    ReportWriter press(d, 1);
    press.set(usages::button(1), 1);
    ASSERT_TRUE(decoder.apply(press.bytes.data(), press.bytes.size(), s));
    events.clear();
    mapper.update(s, 2.0, events);
    ASSERT_EQ(split(events).notes.size(), 1u);
    EXPECT_EQ(split(events).notes[0].note, 43);
    ReportWriter release(d, 1);
    ASSERT_TRUE(decoder.apply(release.bytes.data(), release.bytes.size(), s));
    events.clear();
    mapper.update(s, 2.1, events);
    ASSERT_EQ(split(events).notes.size(), 1u);
    EXPECT_EQ(split(events).notes[0].kind, Event::Kind::NoteOff);
    EXPECT_EQ(split(events).notes[0].note, 43);
}

TEST(HidMapping, EveryTransitionOfAReportArrivesInOrder)
{
    // Four buttons pressed in one report, then three released and one pressed in the next: the
    // old two-slot command lost all but two of them.
    HidMapping m = HidMapping::defaultFor(DeviceKind::Gamepad);
    m.buttonNotes = {43, 50, 57, 64, 67, 69, 71, 72};
    BowMapper mapper(m);
    DeviceState s;
    std::vector<Event> events;
    s.buttons = 0b1111;
    mapper.update(s, 1.0, events);
    Report r = split(events);
    ASSERT_EQ(r.notes.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(r.notes[i].kind, Event::Kind::NoteOn);
        EXPECT_EQ(r.notes[i].note, m.buttonNotes[i]);
        EXPECT_DOUBLE_EQ(r.notes[i].seconds, 1.0);
    }
    EXPECT_EQ(mapper.heldNotes(), 4);
    events.clear();
    s.buttons = 0b10001000;
    mapper.update(s, 1.01, events);
    r = split(events);
    ASSERT_EQ(r.notes.size(), 4u);
    EXPECT_EQ(r.notes[0].kind, Event::Kind::NoteOff);
    EXPECT_EQ(r.notes[2].note, 57);
    EXPECT_EQ(r.notes[3].kind, Event::Kind::NoteOn);
    EXPECT_EQ(r.notes[3].note, 72);
    EXPECT_EQ(mapper.heldNotes(), 2);
}

TEST(HidMapping, DualShockTriggersComeFromRxRy)
{
    const Descriptor d = parseDescriptor(readBinary(data / "sony_dualshock4_usb_054c_05c4.rdesc.bin"));
    DeviceDecoder decoder(d, {});
    DeviceState s;
    ReportWriter w(d, 1);
    w.set(usages::rx, 0).set(usages::ry, 255).set(usages::x, 128);
    ASSERT_TRUE(decoder.apply(w.bytes.data(), w.bytes.size(), s));
    EXPECT_DOUBLE_EQ(s.triggerL, 0.0);
    EXPECT_DOUBLE_EQ(s.triggerR, 1.0);
    EXPECT_NEAR(s.axes[0], 0.0, 0.01);
}

TEST(HidMapping, CurvesDeadZoneInvertAndExponent)
{
    const Curve c{0.0, 1.0, 0.0, 2.0, 2.0, 0.1};
    EXPECT_DOUBLE_EQ(c(0.05), 0.0);
    EXPECT_NEAR(c(0.55), 2.0 * 0.25, 1e-12);
    EXPECT_DOUBLE_EQ(c(2.0), 2.0);
    EXPECT_DOUBLE_EQ(c(std::nan("")), 0.0);
    Curve inv = c;
    inv.invert = true;
    EXPECT_DOUBLE_EQ(inv(1.0), 0.0);
    const Curve stick{-1.0, 1.0, -0.5, 0.5, 1.0, 0.1};
    EXPECT_DOUBLE_EQ(stick(0.05), 0.0);    // centred dead zone
    EXPECT_DOUBLE_EQ(stick(-0.05), 0.0);
    EXPECT_NEAR(stick(1.0), 0.5, 1e-12);
    EXPECT_NEAR(stick(-1.0), -0.5, 1e-12);
}

TEST(HidMapping, MappingFilesRoundTripAndBadOnesNameTheField)
{
    HidMapping m = HidMapping::defaultFor(DeviceKind::SpaceMouse);
    m.forceCurve.exponent = 2.25;
    m.buttonNotes[1] = 62;
    const HidMapping back = HidMapping::fromJson(m.toJson(), "test");
    EXPECT_EQ(back.toJson(), m.toJson());
    EXPECT_EQ(back.kind, DeviceKind::SpaceMouse);
    auto error = [](const std::string& text) {
        try {
            HidMapping::fromJson(text, "map.json");
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(error("{").find("map.json: not valid JSON"), std::string::npos);
    EXPECT_NE(error(R"({"format":"rosin-hid/1","device":"theremin"})").find("device kind"), std::string::npos);
    EXPECT_NE(error(R"({"format":"rosin-hid/1","device":"tablet","force":{"source":"elbow"}})").find("source 'elbow'"), std::string::npos);
    EXPECT_NE(error(R"({"format":"rosin-hid/1","device":"tablet","force":{"curve":{"exponent":-1}}})").find("force.curve: field 'exponent'"), std::string::npos);
    EXPECT_NE(error(R"({"format":"rosin-hid/1","device":"tablet","speed":{"scale_m":"wide"}})").find("map.json"), std::string::npos);
}

TEST(HidMapping, VersionOneMapsBecomeTheSameBowNormalised)
{
    // A rosin-hid/1 map (newtons, m/s, beta) meant for the default bow: 1.1 N, 0.15 m/s, 0.0899.
    const HidMapping m = HidMapping::fromJson(R"({"format":"rosin-hid/1","device":"gamepad",
        "force":{"source":"trigger_r","curve":{"out":[0.0,1.1]}},
        "speed":{"source":"axis_x","from_motion":false,"curve":{"out":[-0.3,0.3]},"bow_change_m_s":0.03},
        "position":{"source":"axis_y","curve":{"out":[0.04495,0.1798]}}})", "old.json");
    EXPECT_NEAR(m.forceCurve.outMax, 0.5, 1e-9);  // 1.1 N is the nominal force
    EXPECT_NEAR(m.speedCurve.outMax, 1.0, 1e-9);  // 0.3 m/s is twice the nominal speed
    EXPECT_NEAR(m.speedCurve.outMin, -1.0, 1e-9);
    EXPECT_NEAR(m.bowChangeThreshold, 0.1, 1e-9);
    EXPECT_NEAR(m.positionCurve.outMin, 0.0, 1e-3); // half the nominal beta
    EXPECT_NEAR(m.positionCurve.outMax, 1.0, 1e-3); // twice it
    // A version-1 tablet map with nothing but its kind: version 1's defaults, converted.
    const HidMapping t = HidMapping::fromJson(R"({"format":"rosin-hid/1","device":"tablet"})", "old.json");
    EXPECT_NEAR(t.forceCurve.outMax, 1.0, 1e-9);            // 2.5 N is beyond twice nominal
    EXPECT_NEAR(t.speedScale, 0.22 / 0.3, 1e-9);
    EXPECT_NEAR(t.positionCurve.outMax, 1.0, 1e-9); // 0.25 is beyond twice the nominal: the top of the range
    // Saved again it is version 2.
    EXPECT_NE(t.toJson().find("rosin-hid/2"), std::string::npos);
}

TEST(HidMapping, ReleaseEndsEveryHeldNote)
{
    HidMapping m = HidMapping::defaultFor(DeviceKind::Tablet);
    m.buttonNotes = {60, 62, 64, -1, -1, -1, -1, -1};
    BowMapper mapper(m);
    DeviceState s;
    s.inRange = s.tip = true;
    s.pressure = 0.5;
    s.buttons = 0b111;
    std::vector<Event> events;
    mapper.update(s, 0.0, events);
    EXPECT_EQ(mapper.heldNotes(), 4); // the pen's note and three buttons
    events.clear();
    mapper.release(0.1, events);
    ASSERT_EQ(events.size(), 5u);
    std::vector<int> off;
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(events[i].kind, Event::Kind::NoteOff);
        off.push_back(events[i].note);
    }
    std::sort(off.begin(), off.end());
    EXPECT_EQ(off, (std::vector<int>{50, 60, 62, 64}));
    EXPECT_EQ(events.back().kind, Event::Kind::Released);
    EXPECT_EQ(mapper.heldNotes(), 0);
}

TEST(HidMapping, ShippedControllerMapsLoad)
{
    for (const std::string kind : {"tablet", "gamepad", "spacemouse", "joystick"}) {
        std::ifstream in(fs::path(ROSIN_PRESETS) / "controllers" / (kind + ".json"));
        ASSERT_TRUE(in) << kind;
        const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        const HidMapping m = HidMapping::fromJson(text, kind);
        EXPECT_EQ(kindName(m.kind), kind);
        EXPECT_NE(m.force, Source::None) << kind;
    }
}
