// The descriptor parser and report decoder on every real descriptor in shared/data/hid, with
// the field positions, sizes, usages and ranges its README lists, and the recording replayed.
#include <gtest/gtest.h>

#include <map>

#include "rosin/hid/Descriptor.h"
#include "rosin/hid/Mapping.h"
#include "rosin/hid/Recording.h"

using namespace rosin::hid;
namespace fs = std::filesystem;

namespace {
const fs::path data = ROSIN_HID_DATA;

Descriptor load(const std::string& file) { return parseDescriptor(readBinary(data / file)); }

void expectField(const Descriptor& d, int id, Usage u, int offset, int size, std::int64_t lmin, std::int64_t lmax)
{
    const Field* f = d.find(ReportType::Input, id, u);
    ASSERT_NE(f, nullptr) << "report " << id << " usage " << std::hex << u;
    EXPECT_EQ(f->bitOffset, offset) << std::hex << u;
    EXPECT_EQ(f->bitSize, size) << std::hex << u;
    EXPECT_EQ(f->logicalMin, lmin) << std::hex << u;
    EXPECT_EQ(f->logicalMax, lmax) << std::hex << u;
}
} // namespace

TEST(HidDescriptor, WacomIntuosProPenReport)
{
    const Descriptor d = load("wacom_intuos_pro_m_gen3_056a_03f7.rdesc.bin");
    EXPECT_TRUE(d.numbered);
    EXPECT_EQ(classify(d), DeviceKind::Tablet);
    const Field* tip = d.find(ReportType::Input, 6, usages::tipSwitch);
    ASSERT_NE(tip, nullptr);
    EXPECT_EQ(tip->bitOffset, 8);
    EXPECT_EQ(tip->bitSize, 1);
    // The switches of one main item: 0D:42, 0D:44, 0D:5A, FF0D:5D, 0D:45, 0D:3C, 0D:32 at bits 8..14.
    const std::vector<Usage> switches{usages::tipSwitch, usages::barrelSwitch, usages::secondaryBarrel, usage(0xFF0D, 0x5D),
                                      usages::eraser, usages::invert, usages::inRange};
    for (std::size_t i = 0; i < switches.size(); ++i) {
        const Field* f = d.find(ReportType::Input, 6, switches[i]);
        ASSERT_NE(f, nullptr) << i;
        EXPECT_EQ(f->bitOffset, 8 + static_cast<int>(i)) << i;
    }
    expectField(d, 6, usages::x, 16, 16, 0, 26300);
    expectField(d, 6, usages::y, 32, 16, 0, 14800);
    expectField(d, 6, usages::tipPressure, 48, 16, 0, 4095);
    expectField(d, 6, usages::xTilt, 64, 16, -9000, 9000);
    expectField(d, 6, usages::yTilt, 80, 16, -9000, 9000);
    const Field* x = d.find(ReportType::Input, 6, usages::x);
    EXPECT_EQ(x->unitExponent, -3);
    EXPECT_EQ(x->unit, 0x11u); // SI linear, cm
    EXPECT_NEAR(physicalValue(*x, 26300), 26.3, 1e-9); // cm: 263.00 mm
    const Field* tilt = d.find(ReportType::Input, 6, usages::xTilt);
    EXPECT_TRUE(tilt->isSigned());
    EXPECT_EQ(tilt->unitExponent, -2);
    EXPECT_NEAR(physicalValue(*tilt, 9000), 90.0, 1e-9);
    // Report IDs up to 254 and a vendor page pressure of 8191 levels elsewhere in the descriptor.
    int maxId = 0;
    bool vendorPressure = false;
    for (const auto& f : d.fields) {
        maxId = std::max(maxId, f.reportId);
        vendorPressure = vendorPressure || (usagePage(f.usage) == 0xFF0D && f.logicalMax == 8191);
    }
    EXPECT_EQ(maxId, 254);
    EXPECT_TRUE(vendorPressure);
}

TEST(HidDescriptor, HuionLastUsageRepeatsAndNonsenseUnitsAreTolerated)
{
    const Descriptor d = load("huion_h640p_256c_006d_pen.rdesc.bin");
    EXPECT_EQ(classify(d), DeviceKind::Tablet);
    // Four usages, Report Count 6: fields 5 and 6 repeat Invert.
    std::vector<const Field*> bits;
    for (const auto& f : d.fields)
        if (f.reportId == 10 && f.type == ReportType::Input && f.bitSize == 1 && f.bitOffset < 6) bits.push_back(&f);
    ASSERT_EQ(bits.size(), 6u);
    EXPECT_EQ(bits[0]->usage, usages::tipSwitch);
    EXPECT_EQ(bits[3]->usage, usages::invert);
    EXPECT_EQ(bits[4]->usage, usages::invert);
    EXPECT_EQ(bits[5]->usage, usages::invert);
    expectField(d, 10, usages::inRange, 6, 1, 0, 1);
    expectField(d, 10, usages::x, 8, 16, 0, 32767);
    expectField(d, 10, usages::y, 24, 16, 0, 32767);
    expectField(d, 10, usages::tipPressure, 40, 16, 0, 8191);
    expectField(d, 10, usages::xTilt, 56, 8, -127, 127);
    expectField(d, 10, usages::yTilt, 64, 8, -127, 127);
    EXPECT_EQ(d.report(ReportType::Input, 10)->bytes() + 1, 10);
    EXPECT_EQ(d.find(ReportType::Input, 10, usages::x)->unit, 0x33u); // inch^3: a firmware error, kept as sent
    EXPECT_NE(d.report(ReportType::Input, 3), nullptr);               // the buttons' keyboard report
}

TEST(HidDescriptor, InklingFromItsRecordingHeader)
{
    const Recording r = readRecording(data / "wacom_inkling_056a_0221.hid");
    EXPECT_EQ(r.vendor, 0x056A);
    EXPECT_EQ(r.product, 0x0221);
    EXPECT_TRUE(r.reports.empty());
    const Descriptor d = parseDescriptor(r.descriptor);
    const Field* x = d.find(ReportType::Input, 2, usages::x);
    ASSERT_NE(x, nullptr);
    EXPECT_EQ(x->logicalMax, 1920);
    EXPECT_EQ(d.find(ReportType::Input, 2, usages::y)->logicalMax, 1920);
    EXPECT_EQ(d.find(ReportType::Input, 2, usages::tipPressure)->logicalMax, 1024);
    EXPECT_TRUE(d.find(ReportType::Input, 2, usages::xTilt)->isSigned());
    EXPECT_EQ(d.find(ReportType::Input, 2, usages::xTilt)->bitSize, 8);
    for (int b = 1; b <= 4; ++b) EXPECT_NE(d.find(ReportType::Input, 2, usages::button(b)), nullptr) << b;
    for (Usage u : {usages::tipSwitch, usages::eraser, usages::barrelSwitch, usages::inRange})
        EXPECT_NE(d.find(ReportType::Input, 2, u), nullptr) << std::hex << u;
}

TEST(HidDescriptor, PenPartnerRecordingReplaysThroughTheDecoder)
{
    const Recording r = readRecording(data / "wacom_penpartner_056a_0061.hid");
    EXPECT_EQ(r.name, "WACOM FT-0203-UV1.4-2");
    ASSERT_EQ(r.reports.size(), 874u);
    const Descriptor d = parseDescriptor(r.descriptor);
    // Report ID 2 is an Input and a Feature report: IDs count per report type.
    ASSERT_NE(d.report(ReportType::Input, 2), nullptr);
    ASSERT_NE(d.report(ReportType::Feature, 2), nullptr);
    EXPECT_EQ(d.report(ReportType::Input, 2)->bytes(), 7);
    EXPECT_EQ(d.report(ReportType::Input, 0x63)->bytes(), 7);
    EXPECT_EQ(d.report(ReportType::Feature, 2)->bytes(), 1);
    std::map<int, int> perId;
    double last = -1.0;
    DeviceDecoder decoder(d, {});
    DeviceState state;
    int decoded = 0;
    for (const auto& e : r.reports) {
        EXPECT_GE(e.seconds, last);
        last = e.seconds;
        ++perId[e.bytes.at(0)];
        decoded += decoder.apply(e.bytes.data(), e.bytes.size(), state) ? 1 : 0;
    }
    EXPECT_EQ(perId[2], 757);
    EXPECT_EQ(decoded, 874);
    EXPECT_NEAR(last, 12.7, 0.1);
    // Report 1 is a relative mouse: X/Y/Wheel signed 8-bit after 3 buttons and 5 padding bits.
    expectField(d, 1, usages::x, 8, 8, -127, 127);
    EXPECT_TRUE(d.find(ReportType::Input, 1, usages::x)->relative());
}

TEST(HidDescriptor, DualShock4)
{
    const Descriptor d = load("sony_dualshock4_usb_054c_05c4.rdesc.bin");
    EXPECT_EQ(classify(d), DeviceKind::Gamepad);
    expectField(d, 1, usages::x, 0, 8, 0, 255);
    expectField(d, 1, usages::y, 8, 8, 0, 255);
    expectField(d, 1, usages::z, 16, 8, 0, 255);
    expectField(d, 1, usages::rz, 24, 8, 0, 255);
    const Field* hat = d.find(ReportType::Input, 1, usages::hat);
    ASSERT_NE(hat, nullptr);
    EXPECT_EQ(hat->bitSize, 4);
    EXPECT_EQ(hat->logicalMax, 7);
    EXPECT_TRUE(hat->nullState());
    EXPECT_TRUE(isNull(*hat, 8));
    for (int b = 1; b <= 14; ++b) EXPECT_NE(d.find(ReportType::Input, 1, usages::button(b)), nullptr) << b;
    EXPECT_EQ(d.find(ReportType::Input, 1, usages::rx)->bitSize, 8);
    EXPECT_EQ(d.find(ReportType::Input, 1, usages::ry)->bitSize, 8);
    EXPECT_EQ(d.report(ReportType::Input, 1)->bytes() + 1, 64);
    EXPECT_NE(d.report(ReportType::Output, 5), nullptr);
}

TEST(HidDescriptor, XboxBluetoothTriggersOnTheSimulationPage)
{
    const Descriptor d = load("xbox_wireless_bt_045e_02fd.rdesc.bin");
    EXPECT_EQ(classify(d), DeviceKind::Gamepad);
    for (Usage u : {usages::x, usages::y, usages::z, usages::rz}) {
        const Field* f = d.find(ReportType::Input, 1, u);
        ASSERT_NE(f, nullptr);
        EXPECT_EQ(f->bitSize, 16);
        EXPECT_EQ(f->logicalMax, 65535); // read unsigned: the minimum is 0
        EXPECT_FALSE(f->isSigned());
    }
    const Field* brake = d.find(ReportType::Input, 1, usages::brake);
    const Field* accel = d.find(ReportType::Input, 1, usages::accelerator);
    ASSERT_TRUE(brake && accel);
    EXPECT_EQ(brake->bitSize, 10);
    EXPECT_EQ(brake->logicalMax, 1023);
    EXPECT_EQ(accel->bitOffset, brake->bitOffset + 16); // 10 bits then 6 padding
    const Field* hat = d.find(ReportType::Input, 1, usages::hat);
    ASSERT_NE(hat, nullptr);
    EXPECT_EQ(hat->logicalMin, 1);
    EXPECT_EQ(hat->logicalMax, 8);
    EXPECT_TRUE(isNull(*hat, 0));
    EXPECT_NE(d.find(ReportType::Input, 1, usages::button(15)), nullptr);
    EXPECT_NE(d.findInput(usage(0x0C, 0x224)), nullptr);
    EXPECT_EQ(d.report(ReportType::Input, 1)->bytes() + 1, 17);
}

TEST(HidDescriptor, RaptorButtonsRepeatTheLastUsageAndTheHatIsAQuirk)
{
    const Descriptor d = load("frtec_raptor_mach2_11c0_5606.rdesc.bin");
    EXPECT_EQ(classify(d), DeviceKind::Joystick);
    expectField(d, 1, usages::x, 0, 16, 0, 2047);
    EXPECT_EQ(d.find(ReportType::Input, 1, usages::y)->logicalMax, 2047);
    EXPECT_EQ(d.find(ReportType::Input, 1, usages::ry)->logicalMax, 2047);
    for (Usage u : {usages::rx, usages::z, usages::rz, usages::slider}) EXPECT_EQ(d.find(ReportType::Input, 1, u)->logicalMax, 1023) << std::hex << u;
    EXPECT_NE(d.find(ReportType::Input, 1, usage(0, 0)), nullptr); // the undefined axis
    int buttonBits = 0, button29 = 0;
    for (const auto& f : d.fields)
        if (f.reportId == 1 && usagePage(f.usage) == 0x09) {
            ++buttonBits;
            button29 += f.usage == usages::button(29) ? 1 : 0;
        }
    EXPECT_EQ(buttonBits, 128);
    EXPECT_EQ(button29, 100); // bits 29..128 all take Button 29
    const Field* hat = d.find(ReportType::Input, 1, usages::hat);
    ASSERT_NE(hat, nullptr);
    EXPECT_EQ(hat->logicalMax, 239);
    EXPECT_EQ(hat->physicalMax, 360);
    EXPECT_GT(quirksFor(0x11C0, 0x5606).hatDegreesPerStep, 1.0);
    EXPECT_EQ(d.report(ReportType::Input, 1)->bytes() + 1, 64);
}

TEST(HidDescriptor, SaitekHasNoReportIds)
{
    const Descriptor d = load("saitek_06a3_0c2d.rdesc.bin");
    EXPECT_FALSE(d.numbered);
    expectField(d, 0, usages::x, 0, 8, 0, 255);
    expectField(d, 0, usages::y, 8, 8, 0, 255);
    expectField(d, 0, usages::z, 16, 8, 0, 255);
    for (int b = 1; b <= 9; ++b) expectField(d, 0, usages::button(b), 24 + b - 1, 1, 0, 1);
    EXPECT_EQ(d.report(ReportType::Input, 0)->bytes(), 5);
    // Unnumbered: the data starts at byte 0.
    DeviceDecoder decoder(d, {});
    DeviceState s;
    const std::uint8_t report[5] = {255, 0, 128, 0b00000101, 0b1};
    ASSERT_TRUE(decoder.apply(report, 5, s));
    EXPECT_DOUBLE_EQ(s.axes[0], 1.0);
    EXPECT_DOUBLE_EQ(s.axes[1], -1.0);
    EXPECT_EQ(s.buttons, 0b100000101u);
}

TEST(HidDescriptor, SpaceNavigatorSignedAxesExponentAndTheRelativeQuirk)
{
    const Descriptor d = load("3dconnexion_spacenavigator_046d_c626.rdesc.bin");
    EXPECT_EQ(classify(d), DeviceKind::SpaceMouse);
    for (auto [id, u] : std::vector<std::pair<int, Usage>>{{1, usages::x}, {1, usages::y}, {1, usages::z},
                                                          {2, usages::rx}, {2, usages::ry}, {2, usages::rz}}) {
        const Field* f = d.find(ReportType::Input, id, u);
        ASSERT_NE(f, nullptr);
        EXPECT_EQ(f->bitSize, 16);
        EXPECT_EQ(f->logicalMin, -350);
        EXPECT_EQ(f->logicalMax, 350);
        EXPECT_EQ(f->physicalMax, 1400);
        EXPECT_EQ(f->unitExponent, -4);
        EXPECT_TRUE(f->relative()); // as the device says: wrong
    }
    EXPECT_NE(d.find(ReportType::Input, 3, usages::button(1)), nullptr);
    EXPECT_NE(d.report(ReportType::Output, 4), nullptr);
    EXPECT_TRUE(quirksFor(0x046D, 0xC626).forceAbsolute);
    // Split reports: translation then rotation; the state holds both. Absolute thanks to the quirk.
    DeviceDecoder decoder(d, quirksFor(0x046D, 0xC626));
    DeviceState s;
    const std::uint8_t translation[7] = {1, 0x5E, 0x01, 0xA2, 0xFE, 0x00, 0x00}; // x 350, y -350, z 0
    const std::uint8_t rotation[7] = {2, 0xAF, 0x00, 0x00, 0x00, 0x00, 0x00};    // rx 175
    ASSERT_TRUE(decoder.apply(translation, 7, s));
    ASSERT_TRUE(decoder.apply(rotation, 7, s));
    ASSERT_TRUE(decoder.apply(translation, 7, s)); // the same again: absolute, so no drift
    EXPECT_DOUBLE_EQ(s.axes[0], 1.0);
    EXPECT_DOUBLE_EQ(s.axes[1], -1.0);
    EXPECT_DOUBLE_EQ(s.axes[3], 0.5);
}

TEST(HidDescriptor, ExtractionSignsOnlyWhenTheMinimumIsNegative)
{
    Field f;
    f.bitOffset = 4;
    f.bitSize = 8;
    f.logicalMin = 0;
    f.logicalMax = 255;
    const std::uint8_t bytes[2] = {0xF0, 0x0F}; // bits 4..11 = 0xFF
    EXPECT_EQ(extractRaw(f, bytes, 2), 255);
    f.logicalMin = -128;
    f.logicalMax = 127;
    EXPECT_EQ(extractRaw(f, bytes, 2), -1);
    EXPECT_EQ(extractRaw(f, bytes, 1), 15); // short payload: the missing high bits read as 0
}

TEST(HidDescriptor, MalformedDescriptorsGiveAClearError)
{
    auto error = [](std::vector<std::uint8_t> bytes) {
        try {
            parseDescriptor(bytes);
        } catch (const DescriptorError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(error({}).find("empty"), std::string::npos);
    EXPECT_NE(error({0x05, 0x01, 0x09}).find("byte 2"), std::string::npos);                   // data cut off
    EXPECT_NE(error({0xA1, 0x01, 0x75, 0x08, 0x95, 0x01, 0x81, 0x02}).find("never closed"), std::string::npos);
    EXPECT_NE(error({0xC0}).find("End Collection"), std::string::npos);
    EXPECT_NE(error({0xB4}).find("Pop"), std::string::npos);
    EXPECT_NE(error({0x96, 0xFF, 0xFF, 0x81, 0x02}).find("Report Count"), std::string::npos);
    EXPECT_NE(error({0x75, 0x08, 0x95, 0x01, 0x85, 0x00, 0x81, 0x02}).find("Report ID"), std::string::npos);
    EXPECT_NE(error(std::vector<std::uint8_t>(5000, 0x00)).find("4096"), std::string::npos);
    // A long item is skipped, not an error.
    EXPECT_EQ(error({0xFE, 0x02, 0x10, 0xAA, 0xBB, 0x75, 0x08, 0x95, 0x01, 0x81, 0x02}), "no error");
}
