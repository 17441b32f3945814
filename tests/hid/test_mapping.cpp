// From device reports to the bow: a synthetic pen stroke and gamepad input through the real
// descriptors, the decoder and the mapper; curves, calibration, mapping files.
#include <gtest/gtest.h>

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

TEST(HidMapping, PenStrokeGivesForceSpeedPositionAndOneBowChange)
{
    const Descriptor d = parseDescriptor(readBinary(data / "huion_h640p_256c_006d_pen.rdesc.bin"));
    DeviceDecoder decoder(d, {});
    ASSERT_EQ(decoder.kind(), DeviceKind::Tablet);
    BowMapper mapper(HidMapping::defaultFor(DeviceKind::Tablet));
    DeviceState s;
    std::vector<BowCommand> out;
    const double dt = 0.005; // 200 reports per second
    double t = 0.0, x = 0.2;
    auto report = [&](bool tip, double pressure, double xPos, double tilt) {
        ReportWriter w(d, 10);
        w.set(usages::inRange, 1).set(usages::tipSwitch, tip ? 1 : 0);
        w.set(usages::x, std::llround(xPos * 32767)).set(usages::y, 16384);
        w.set(usages::tipPressure, std::llround(pressure * 8191)).set(usages::xTilt, std::llround(tilt * 127));
        ASSERT_TRUE(decoder.apply(w.bytes.data(), w.bytes.size(), s));
        out.push_back(mapper.update(s, t));
        t += dt;
    };
    for (int i = 0; i < 10; ++i) report(false, 0.0, x, -0.5);                   // hovering
    for (int i = 1; i <= 20; ++i) report(true, i / 20.0, x, -0.5);              // pressure up, still
    const std::size_t moveStart = out.size();
    for (int i = 0; i < 100; ++i) report(true, 1.0, x += 0.4 * dt / 0.5, -0.5); // right: 0.8 of the width per s
    const std::size_t reverse = out.size();
    for (int i = 0; i < 100; ++i) report(true, 1.0, x -= 0.4 * dt / 0.5, -0.5); // back
    report(false, 0.0, x, -0.5);                                                 // lift

    // Hovering: no bow. Touch: note on; the force follows the pressure curve up to 2.5 N.
    EXPECT_FALSE(out[5].engaged);
    EXPECT_EQ(out[10].noteOn, 50);
    EXPECT_TRUE(out[10].engaged);
    for (std::size_t i = 11; i < 30; ++i) EXPECT_GE(out[i].force, out[i - 1].force);
    EXPECT_NEAR(out[29].force, 2.5, 0.01);
    EXPECT_NEAR(out[20].force, 2.5 * std::pow(0.55, 1.5), 0.01); // 11th of 20 steps
    // Speed: 0.8 widths/s x 0.22 m = 0.176 m/s once the 30 ms smoothing has settled; then the reverse.
    const double v = 0.8 * 0.22;
    EXPECT_NEAR(out[reverse - 1].speed, v, 0.01 * v);
    EXPECT_NEAR(out[out.size() - 2].speed, -v, 0.01 * v); // the last report before the lift
    EXPECT_NEAR(out[moveStart + 50].beta, 0.03 + 0.5 * 0.22, 1e-3);
    EXPECT_EQ(out[moveStart + 50].string, 0); // tilt -0.5 of the -0.6..0.6 range: the lowest string
    int changes = 0;
    std::size_t at = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
        if (out[i].bowChange) { ++changes; at = i; }
    EXPECT_EQ(changes, 1);
    EXPECT_GE(at, reverse);
    EXPECT_LE((at - reverse) * dt, 0.03); // heard within 30 ms of the hand turning
    EXPECT_FALSE(out.back().engaged);
    EXPECT_EQ(out.back().noteOff, 50);
    EXPECT_EQ(out.back().force, 0.0f);
}

TEST(HidMapping, GamepadTriggerDrivesBowForceAndTheStickTheSpeed)
{
    const Descriptor d = parseDescriptor(readBinary(data / "xbox_wireless_bt_045e_02fd.rdesc.bin"));
    DeviceDecoder decoder(d, {});
    ASSERT_EQ(decoder.kind(), DeviceKind::Gamepad);
    BowMapper mapper(HidMapping::defaultFor(DeviceKind::Gamepad));
    DeviceState s;
    double previous = -1.0;
    for (int v = 0; v <= 1023; v += 31) {
        ReportWriter w(d, 1);
        w.set(usages::x, 65535).set(usages::y, 32768).set(usages::z, 32768).set(usages::rz, 32768);
        w.set(usages::accelerator, v).set(usages::brake, 0);
        ASSERT_TRUE(decoder.apply(w.bytes.data(), w.bytes.size(), s));
        const BowCommand c = mapper.update(s, v * 0.001);
        EXPECT_GE(c.force, previous);
        previous = c.force;
        EXPECT_EQ(c.engaged, c.force > 1e-4f);
        EXPECT_NEAR(c.speed, 0.6, 1e-3); // stick full right: the curve's top speed
    }
    EXPECT_NEAR(previous, 2.5 * std::pow((1023.0 / 1023.0 - 0.03) / 0.97, 1.5), 0.01);
    // Button 1 holds note 43; releasing it ends the note.
    ReportWriter press(d, 1);
    press.set(usages::button(1), 1);
    ASSERT_TRUE(decoder.apply(press.bytes.data(), press.bytes.size(), s));
    EXPECT_EQ(mapper.update(s, 2.0).noteOn, 43);
    ReportWriter release(d, 1);
    ASSERT_TRUE(decoder.apply(release.bytes.data(), release.bytes.size(), s));
    EXPECT_EQ(mapper.update(s, 2.1).noteOff, 43);
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

TEST(HidMapping, CalibrationUsesTheRangeThePlayerReached)
{
    HidMapping m = HidMapping::defaultFor(DeviceKind::Tablet);
    Calibration cal;
    DeviceState s;
    for (double p : {0.1, 0.4, 0.7}) {
        s.pressure = p;
        s.y = 0.3 + 0.2 * p;
        cal.observe(s);
    }
    cal.apply(m);
    EXPECT_DOUBLE_EQ(m.forceCurve.inMin, 0.1);
    EXPECT_DOUBLE_EQ(m.forceCurve.inMax, 0.7);
    EXPECT_NEAR(m.forceCurve(0.7), 2.5, 1e-12); // the player's hardest press is the full force
    EXPECT_NEAR(m.positionCurve.inMax, 0.44, 1e-12);
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

TEST(HidMapping, ReleaseEndsHeldNotes)
{
    BowMapper mapper(HidMapping::defaultFor(DeviceKind::Tablet));
    DeviceState s;
    s.inRange = s.tip = true;
    s.pressure = 0.5;
    EXPECT_EQ(mapper.update(s, 0.0).noteOn, 50);
    const BowCommand r = mapper.release(0.1);
    EXPECT_FALSE(r.engaged);
    EXPECT_EQ(r.noteOff, 50);
    EXPECT_EQ(r.force, 0.0f);
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
