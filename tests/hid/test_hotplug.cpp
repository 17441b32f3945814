// Controllers that come and go: the HID thread driven through fake devices and a fake USB
// watcher (no device is attached to the test machine), with the reports of a recorded pen.
// Hot-plug wakes the thread at once; an unplug announced by the watcher ends the notes at once;
// a mapping edited while a device plays applies to it; every device's status is honest and
// clears; the udev rule covers exactly the supported products.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "rosin/hid/Devices.h"
#include "rosin/hid/HidInput.h"
#include "rosin/hid/Recording.h"
#include "rosin/presets/Document.h"

namespace fs = std::filesystem;
using namespace rosin::hid;
using namespace std::chrono_literals;

namespace {
const fs::path data = ROSIN_HID_DATA;

/// A device on the fake bus: reports are fed by the test; unplugging can leave read() quiet
/// (returning 0, as if the kernel had not noticed yet) so that only the watcher can tell.
struct FakeDevice {
    DeviceInfo info;
    std::vector<std::uint8_t> descriptor;
    std::string product; ///< its USB product string
    std::atomic<bool> plugged{false}, openable{true}, readFailsWhenGone{false};
    std::mutex mutex;
    std::deque<std::vector<std::uint8_t>> reports;

    void feed(const std::vector<std::uint8_t>& r)
    {
        const std::lock_guard<std::mutex> lock(mutex);
        reports.push_back(r);
    }
};

class FakeHandle : public DeviceHandle {
public:
    explicit FakeHandle(std::shared_ptr<FakeDevice> d) : d_(std::move(d)) {}
    int read(std::uint8_t* buffer, std::size_t size, int timeoutMs) override
    {
        if (!d_->plugged && d_->readFailsWhenGone) return -1;
        {
            const std::lock_guard<std::mutex> lock(d_->mutex);
            if (!d_->reports.empty() && d_->plugged) {
                const auto r = d_->reports.front();
                d_->reports.pop_front();
                const std::size_t n = std::min(size, r.size());
                std::copy_n(r.begin(), n, buffer);
                return static_cast<int>(n);
            }
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(std::min(timeoutMs, 2)));
        return 0;
    }
    std::vector<std::uint8_t> descriptor() override { return d_->descriptor; }

private:
    std::shared_ptr<FakeDevice> d_;
};

struct FakeBus {
    std::mutex mutex;
    std::vector<std::shared_ptr<FakeDevice>> devices;
    std::condition_variable changed;
    std::deque<UsbChange> changes;
    bool hotplug = true;

    UsbDevice usb(const FakeDevice& d) const
    {
        return {d.info.vendor, d.info.product, d.info.usbBus, d.info.usbAddress, "Maker", d.product, "SN1"};
    }
    void plug(const std::shared_ptr<FakeDevice>& d, bool in)
    {
        d->plugged = in;
        const std::lock_guard<std::mutex> lock(mutex);
        if (in) devices.push_back(d);
        else devices.erase(std::remove(devices.begin(), devices.end(), d), devices.end());
        if (d->info.bus == Bus::Usb) changes.push_back({in, usb(*d)});
        changed.notify_all();
    }
};

class FakeBackend : public DeviceBackend {
public:
    explicit FakeBackend(std::shared_ptr<FakeBus> bus) : bus_(std::move(bus)) {}
    std::vector<DeviceInfo> enumerate() override
    {
        const std::lock_guard<std::mutex> lock(bus_->mutex);
        std::vector<DeviceInfo> out;
        for (const auto& d : bus_->devices) out.push_back(d->info);
        return out;
    }
    std::unique_ptr<DeviceHandle> open(const DeviceInfo& info, std::string& error) override
    {
        const std::lock_guard<std::mutex> lock(bus_->mutex);
        for (const auto& d : bus_->devices)
            if (d->info.path == info.path) {
                if (!d->openable) {
                    error = "permission denied: the udev rule is missing";
                    return nullptr;
                }
                return std::make_unique<FakeHandle>(d);
            }
        error = "gone";
        return nullptr;
    }

private:
    std::shared_ptr<FakeBus> bus_;
};

class FakeWatcher : public UsbWatcher {
public:
    explicit FakeWatcher(std::shared_ptr<FakeBus> bus) : bus_(std::move(bus)) {}
    bool hotplug() const override { return bus_->hotplug; }
    std::vector<UsbChange> wait(int timeoutMs) override
    {
        std::unique_lock<std::mutex> lock(bus_->mutex);
        bus_->changed.wait_for(lock, std::chrono::milliseconds(timeoutMs), [&] { return !bus_->changes.empty(); });
        std::vector<UsbChange> out(bus_->changes.begin(), bus_->changes.end());
        bus_->changes.clear();
        return out;
    }
    std::vector<UsbDevice> attached() override
    {
        const std::lock_guard<std::mutex> lock(bus_->mutex);
        std::vector<UsbDevice> out;
        for (const auto& d : bus_->devices) out.push_back(bus_->usb(*d));
        return out;
    }

private:
    std::shared_ptr<FakeBus> bus_;
};

std::shared_ptr<FakeDevice> recordedPen(const Recording& r, int address)
{
    auto d = std::make_shared<FakeDevice>();
    d->info = {"/dev/hidraw" + std::to_string(address), r.vendor, r.product, "hidapi name", Bus::Usb, 3, static_cast<std::uint8_t>(address)};
    d->descriptor = r.descriptor;
    d->product = "Tablet H640P";
    return d;
}

/// The recording's reports split at the pen's touches: the first touch starts stroke 1, ...
struct Strokes {
    std::vector<std::size_t> down, up; ///< report indices where the tip touches / leaves
};
Strokes strokesOf(const Recording& r)
{
    const DeviceDecoder decoder(parseDescriptor(r.descriptor), quirksFor(r.vendor, r.product));
    DeviceState s;
    Strokes out;
    bool tip = false;
    for (std::size_t i = 0; i < r.reports.size(); ++i) {
        decoder.apply(r.reports[i].bytes.data(), r.reports[i].bytes.size(), s);
        if (s.tip && !tip) out.down.push_back(i);
        if (!s.tip && tip) out.up.push_back(i);
        tip = s.tip;
    }
    return out;
}

/// Events until `until` returns true or the time runs out.
template <class Until>
std::vector<Event> collect(HidInput& in, std::chrono::milliseconds limit, Until until)
{
    std::vector<Event> got;
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
        Event e;
        while (in.queue().pop(e)) got.push_back(e);
        if (until(got)) break;
        std::this_thread::sleep_for(1ms);
    }
    return got;
}

bool has(const std::vector<Event>& events, Event::Kind kind, int note = -2)
{
    return std::any_of(events.begin(), events.end(), [&](const Event& e) { return e.kind == kind && (note == -2 || e.note == note); });
}

template <class Pred>
bool eventually(Pred p, std::chrono::milliseconds limit)
{
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
        if (p()) return true;
        std::this_thread::sleep_for(1ms);
    }
    return p();
}
} // namespace

// Plug in mid-session, play, unplug with the note held. Polling is set to 30 s, so only the
// watcher can make the thread find the pen within the test's 300 ms; the handle never fails its
// reads, so only the watcher can tell that the pen has gone.
TEST(HidHotplug, PlugPlayAndUnplugWithANoteHeld)
{
    const Recording rec = readRecording(data / "huion_h640p_pen_strokes.hid");
    const Strokes strokes = strokesOf(rec);
    ASSERT_GE(strokes.down.size(), 1u);
    auto bus = std::make_shared<FakeBus>();
    HidInput in(std::make_unique<FakeBackend>(bus), std::make_unique<FakeWatcher>(bus));
    in.rescanSeconds = in.hotplugRescanSeconds = 30.0;
    in.start();
    ASSERT_TRUE(eventually([&] { return in.status() == "no controller"; }, 500ms));
    EXPECT_TRUE(in.hotplug());

    auto pen = recordedPen(rec, 7);
    const auto plugged = std::chrono::steady_clock::now();
    bus->plug(pen, true);
    ASSERT_TRUE(eventually([&] { return in.connections() == 1; }, 300ms)) << in.status();
    const double secondsToConnect = std::chrono::duration<double>(std::chrono::steady_clock::now() - plugged).count();
    EXPECT_LT(secondsToConnect, 0.3);
    // Named by its USB strings, with the tablet map.
    EXPECT_EQ(in.status(), "Maker Tablet H640P (SN1) (tablet)");
    const auto devices = in.devices();
    ASSERT_EQ(devices.size(), 1u);
    EXPECT_EQ(devices[0].state, DeviceStatus::State::Connected);

    // Play into the first stroke: the pen touches and holds its note.
    for (std::size_t i = 0; i <= strokes.down[0] + 5; ++i) pen->feed(rec.reports[i].bytes);
    auto events = collect(in, 500ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::NoteOn); });
    ASSERT_TRUE(has(events, Event::Kind::NoteOn, 50));
    EXPECT_FALSE(has(events, Event::Kind::NoteOff));
    const auto bows = std::count_if(events.begin(), events.end(), [](const Event& e) { return e.kind == Event::Kind::Bow; });
    EXPECT_GE(bows, static_cast<long>(strokes.down[0]));

    const auto unplugged = std::chrono::steady_clock::now();
    bus->plug(pen, false);
    events = collect(in, 300ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::Released); });
    const double secondsToRelease = std::chrono::duration<double>(std::chrono::steady_clock::now() - unplugged).count();
    ASSERT_TRUE(has(events, Event::Kind::NoteOff, 50)) << "the held note ends";
    ASSERT_TRUE(has(events, Event::Kind::Released));
    EXPECT_LT(secondsToRelease, 0.3);
    EXPECT_EQ(events.back().kind, Event::Kind::Released);
    EXPECT_TRUE(eventually([&] { return in.status().find("unplugged") != std::string::npos; }, 200ms)) << in.status();

    // Plugged in again: found again at once.
    bus->plug(pen, true);
    EXPECT_TRUE(eventually([&] { return in.connections() == 2; }, 300ms)) << in.status();
    in.stop();
}

// Where the platform has no hot-plug, the thread polls, and a read that fails still ends the notes.
TEST(HidHotplug, WithoutHotplugTheThreadPollsAndAFailedReadEndsTheNotes)
{
    const Recording rec = readRecording(data / "huion_h640p_pen_strokes.hid");
    const Strokes strokes = strokesOf(rec);
    auto bus = std::make_shared<FakeBus>();
    bus->hotplug = false;
    HidInput in(std::make_unique<FakeBackend>(bus), std::make_unique<FakeWatcher>(bus));
    in.rescanSeconds = 0.05;
    in.start();
    EXPECT_FALSE(in.hotplug());
    auto pen = recordedPen(rec, 8);
    pen->readFailsWhenGone = true;
    bus->plug(pen, true);
    ASSERT_TRUE(eventually([&] { return in.connections() == 1; }, 1000ms)) << in.status();
    for (std::size_t i = 0; i <= strokes.down[0] + 2; ++i) pen->feed(rec.reports[i].bytes);
    ASSERT_TRUE(has(collect(in, 500ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::NoteOn); }), Event::Kind::NoteOn, 50));
    {
        // Gone without a word from the watcher: the failed read must tell.
        const std::lock_guard<std::mutex> lock(bus->mutex);
        bus->changes.clear();
        pen->plugged = false;
        bus->devices.clear();
    }
    const auto events = collect(in, 500ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::Released); });
    EXPECT_TRUE(has(events, Event::Kind::NoteOff, 50));
    EXPECT_TRUE(has(events, Event::Kind::Released));
    in.stop();
}

// A mapping edited in the window reaches the pen that is playing, without reconnecting: the next
// touch (the recording's approach and touch, played again) plays the new note.
TEST(HidHotplug, AMappingChangedWhileConnectedAppliesToTheNextReport)
{
    const Recording rec = readRecording(data / "huion_h640p_pen_strokes.hid");
    const Strokes strokes = strokesOf(rec); // the pen touches once and bows four strokes
    ASSERT_GE(strokes.down.size(), 1u);
    ASSERT_GE(strokes.up.size(), 1u);
    auto bus = std::make_shared<FakeBus>();
    HidInput in(std::make_unique<FakeBackend>(bus), std::make_unique<FakeWatcher>(bus));
    in.start();
    auto pen = recordedPen(rec, 9);
    bus->plug(pen, true);
    ASSERT_TRUE(eventually([&] { return in.connections() == 1; }, 500ms));
    for (std::size_t i = 0; i <= strokes.up[0]; ++i) pen->feed(rec.reports[i].bytes);
    auto events = collect(in, 1000ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::NoteOff); });
    ASSERT_TRUE(has(events, Event::Kind::NoteOn, 50));
    ASSERT_TRUE(has(events, Event::Kind::NoteOff, 50));

    HidMapping m = in.mapping(DeviceKind::Tablet);
    m.tipNote = 62;
    in.setMapping(m);
    for (std::size_t i = 0; i <= strokes.down[0] + 2; ++i) pen->feed(rec.reports[i].bytes); // it comes down again
    events = collect(in, 1000ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::NoteOn); });
    EXPECT_TRUE(has(events, Event::Kind::NoteOn, 62));
    EXPECT_FALSE(has(events, Event::Kind::NoteOn, 50));
    EXPECT_EQ(in.connections(), 1) << "the same connection";
    in.stop();
}

// Per device: a supported pen the user may not open says so with the exact udev line; a root-only
// keyboard is "unsupported", not a permission problem; once the rule is in and the pen replugged,
// the error is gone.
TEST(HidHotplug, StatusPerDeviceAndErrorsThatClear)
{
    const Recording rec = readRecording(data / "huion_h640p_pen_strokes.hid");
    auto bus = std::make_shared<FakeBus>();
    HidInput in(std::make_unique<FakeBackend>(bus), std::make_unique<FakeWatcher>(bus));
    in.hotplugRescanSeconds = 30.0;
    auto keyboard = std::make_shared<FakeDevice>();
    keyboard->info = {"/dev/hidraw1", 0x046D, 0xC31C, "Logitech USB Keyboard", Bus::Usb, 3, 2};
    keyboard->openable = false;
    keyboard->product = "USB Keyboard";
    auto pen = recordedPen(rec, 5);
    pen->openable = false;
    bus->plug(keyboard, true);
    bus->plug(pen, true);
    in.start();
    ASSERT_TRUE(eventually([&] { return in.devices().size() == 2; }, 500ms));
    const SupportedDevice* huion = findSupported(rec.vendor, rec.product, Bus::Usb);
    ASSERT_NE(huion, nullptr);
    for (const auto& d : in.devices()) {
        if (d.vendor == 0x046D) {
            EXPECT_EQ(d.state, DeviceStatus::State::Unsupported);
        } else {
            EXPECT_EQ(d.state, DeviceStatus::State::NoPermission);
            EXPECT_EQ(d.detail, udevLine(*huion));
            EXPECT_EQ(d.kind, "tablet");
        }
    }
    EXPECT_NE(in.status().find("no permission"), std::string::npos) << in.status();
    EXPECT_EQ(in.status().find("Keyboard"), std::string::npos) << "a keyboard is not our business";

    // The rule is installed; the pen is plugged in again.
    bus->plug(pen, false);
    pen->openable = true;
    bus->plug(pen, true);
    ASSERT_TRUE(eventually([&] { return in.connections() == 1; }, 500ms)) << in.status();
    EXPECT_EQ(in.status().find("permission"), std::string::npos) << in.status();
    for (const auto& d : in.devices()) EXPECT_NE(d.state, DeviceStatus::State::NoPermission);

    // The keyboard leaves and the pen too: no stale message remains.
    bus->plug(keyboard, false);
    bus->plug(pen, false);
    ASSERT_TRUE(eventually([&] { return in.status().find("unplugged") != std::string::npos; }, 500ms)) << in.status();
    EXPECT_TRUE(eventually([&] { return in.devices().empty(); }, 500ms));
    in.stop();
}

// Two plugin instances: each has its own input and queue; hidapi's process-wide state lives while
// either does, and closing one leaves the other working.
TEST(HidHotplug, TwoInstancesShareHidapiAndKeepTheirOwnDevices)
{
    const int before = hidapiUsers();
    {
        HidInput first(makeHidapiBackend()), second(makeHidapiBackend());
        EXPECT_EQ(hidapiUsers(), before + 2);
        first.start();
        second.start();
        std::this_thread::sleep_for(50ms);
        {
            HidInput third(makeHidapiBackend());
            third.start();
            std::this_thread::sleep_for(30ms);
        } // closed while the others scan: hidapi stays up for them
        EXPECT_EQ(hidapiUsers(), before + 2);
        std::this_thread::sleep_for(30ms);
        EXPECT_TRUE(first.running() && second.running());
    }
    EXPECT_EQ(hidapiUsers(), before);

    // And on fake buses, each instance plays only its own pen.
    const Recording rec = readRecording(data / "huion_h640p_pen_strokes.hid");
    const Strokes strokes = strokesOf(rec);
    auto busA = std::make_shared<FakeBus>(), busB = std::make_shared<FakeBus>();
    HidInput a(std::make_unique<FakeBackend>(busA), std::make_unique<FakeWatcher>(busA));
    HidInput b(std::make_unique<FakeBackend>(busB), std::make_unique<FakeWatcher>(busB));
    HidMapping m = a.mapping(DeviceKind::Tablet);
    m.tipNote = 55;
    b.setMapping(m);
    a.start();
    b.start();
    auto penA = recordedPen(rec, 10), penB = recordedPen(rec, 11);
    busA->plug(penA, true);
    busB->plug(penB, true);
    ASSERT_TRUE(eventually([&] { return a.connections() == 1 && b.connections() == 1; }, 500ms));
    for (std::size_t i = 0; i <= strokes.down[0] + 2; ++i) {
        penA->feed(rec.reports[i].bytes);
        penB->feed(rec.reports[i].bytes);
    }
    const auto ea = collect(a, 500ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::NoteOn); });
    const auto eb = collect(b, 500ms, [](const std::vector<Event>& e) { return has(e, Event::Kind::NoteOn); });
    EXPECT_TRUE(has(ea, Event::Kind::NoteOn, 50));
    EXPECT_TRUE(has(eb, Event::Kind::NoteOn, 55));
    a.stop();
    EXPECT_TRUE(b.running());
    b.stop();
}

// The rule file is the table: every shipped controller map has supported products, every
// supported product has its line (on its bus), and no line opens a device without a profile.
TEST(HidUdev, EveryProfileHasItsLineAndNoOtherDeviceMatches)
{
    std::ifstream in(fs::path(ROSIN_SOURCE_DIR) / "scripts/udev/70-rosin-hid.rules");
    ASSERT_TRUE(in) << "the shipped rules file";
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), udevRules()) << "regenerate it: rosin-host hid --udev-rules > scripts/udev/70-rosin-hid.rules";
    std::vector<std::string> lines;
    for (std::string line; std::getline(text, line);) lines.push_back(line);
    auto matching = [&](std::uint16_t v, std::uint16_t p, Bus bus, const std::string& subsystem) {
        return std::count_if(lines.begin(), lines.end(), [&](const std::string& l) { return udevLineMatches(l, v, p, bus, subsystem); });
    };

    for (const auto& entry : fs::directory_iterator(fs::path(ROSIN_PRESETS) / "controllers")) {
        std::ifstream file(entry.path());
        const std::string json{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
        const auto mapping = HidMapping::fromDocument(rosin::presets::Document::parse(json, entry.path().string()));
        const auto products = std::count_if(supportedDevices().begin(), supportedDevices().end(), [&](const SupportedDevice& d) {
            return d.kind == mapping.kind && matching(d.vendor, d.product, d.bus, "hidraw") > 0;
        });
        EXPECT_GT(products, 0) << entry.path().filename() << " has no supported product with a udev line";
    }
    for (const auto& d : supportedDevices()) {
        EXPECT_EQ(matching(d.vendor, d.product, d.bus, "hidraw"), 1) << d.name;
        if (d.bus == Bus::Usb) {
            EXPECT_EQ(matching(d.vendor, d.product, d.bus, "usb"), 1) << d.name << " (USB strings)";
        }
    }
    // Devices of the same vendors with no profile: a receiver, keyboards, another tablet, a newer
    // pad; and a supported pad on a bus it is not listed for.
    const struct {
        std::uint16_t v, p;
        Bus bus;
    } others[] = {{0x046D, 0xC52B, Bus::Usb}, {0x046D, 0xC31C, Bus::Usb}, {0x045E, 0x07A5, Bus::Usb}, {0x056A, 0x0357, Bus::Usb},
                  {0x054C, 0x0CE6, Bus::Usb},  {0x054C, 0x0CE6, Bus::Bluetooth}, {0x045E, 0x02FD, Bus::Usb}, {0x256C, 0x006E, Bus::Usb},
                  {0x046D, 0xC626, Bus::Bluetooth}};
    for (const auto& o : others)
        for (const char* subsystem : {"hidraw", "usb"})
            EXPECT_EQ(matching(o.v, o.p, o.bus, subsystem), 0) << std::hex << o.v << ":" << o.p << " on " << subsystem;
    // The matcher itself: a vendor-wide line (the old rule) matches the keyboard, the Bluetooth
    // form matches only its own product.
    EXPECT_TRUE(udevLineMatches(R"(SUBSYSTEM=="hidraw", ATTRS{idVendor}=="046d", TAG+="uaccess")", 0x046D, 0xC31C, Bus::Usb, "hidraw"));
    EXPECT_FALSE(udevLineMatches(R"(SUBSYSTEM=="hidraw", ATTRS{idVendor}=="045e", TAG+="uaccess")", 0x045E, 0x02FD, Bus::Bluetooth, "hidraw"));
    EXPECT_TRUE(udevLineMatches(R"(SUBSYSTEM=="hidraw", KERNELS=="0005:045E:02FD.*", TAG+="uaccess")", 0x045E, 0x02FD, Bus::Bluetooth, "hidraw"));
}

// The window asks whether hot-plug is on while the loader thread starts and stops the input, and
// with it makes and drops the watcher (a race on the watcher under ThreadSanitizer before the
// answer was published on its own).
TEST(HidHotplug, AskingForHotplugWhileTheInputStartsAndStops)
{
    auto bus = std::make_shared<FakeBus>();
    HidInput in(std::make_unique<FakeBackend>(bus));
    in.watcherFactory = [bus] { return std::make_unique<FakeWatcher>(bus); };
    EXPECT_FALSE(in.hotplug()) << "no watcher until the input starts";
    std::atomic<bool> done{false};
    std::atomic<int> on{0}, asked{0};
    std::thread window([&] {
        while (!done) {
            on += in.hotplug() ? 1 : 0;
            ++asked;
            (void)in.status();
        }
    });
    for (int i = 0; i < 20; ++i) {
        in.start();
        EXPECT_TRUE(in.hotplug());
        std::this_thread::sleep_for(2ms);
        in.stop();
        EXPECT_FALSE(in.hotplug()) << "the made watcher is dropped on stop";
    }
    done = true;
    window.join();
    EXPECT_GT(asked.load(), 20);
    EXPECT_GT(on.load(), 0);
}

// The real libusb watcher on this machine: it starts, says whether hot-plug is there, lists the
// attached devices (none may be attached: then the list is empty) and stops without hanging.
TEST(HidHotplug, TheLibusbWatcherStartsAndStops)
{
    auto w = makeLibusbWatcher(100);
    const auto t0 = std::chrono::steady_clock::now();
    const auto changes = w->wait(150);
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_GE(waited, 0.05); // it waited rather than spinning
    for (const auto& c : changes) EXPECT_NE(c.device.vendor | c.device.product, 0);
    for (const auto& d : w->attached()) EXPECT_NE(d.busNumber, 0);
    w.reset();
}
