// The HID input thread: finds a controller, reads its reports, decodes and maps them, and hands
// Events (the bow, note transitions, time-stamped) to the audio thread through a lock-free SPSC
// queue. Devices come and go while playing: a UsbWatcher (libusb hot-plug) wakes the thread when
// one arrives or leaves; without one it polls. The device layer and the watcher are interfaces,
// so tests drive them with fakes; HidapiBackend (hidapi's hidraw backend, descriptors from
// sysfs) and the libusb watcher are the real ones.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rosin/hid/Devices.h"
#include "rosin/hid/Mapping.h"
#include "rosin/hid/UsbWatcher.h"
#include "rosin/rt/SpscQueue.h"

namespace rosin::hid {

struct DeviceInfo {
    std::string path;          ///< /dev/hidrawN for hidapi's hidraw backend
    std::uint16_t vendor = 0, product = 0;
    std::string name;
    Bus bus = Bus::Usb;
    std::uint8_t usbBus = 0, usbAddress = 0; ///< the USB device behind it (0: unknown, or Bluetooth)
};

/// One device as the window shows it.
struct DeviceStatus {
    enum class State { Connected, Available, NoPermission, Unsupported, NotABow, Failed };
    State state = State::Unsupported;
    std::string name;           ///< the USB strings where readable, else the table's or hidapi's name
    std::uint16_t vendor = 0, product = 0;
    Bus bus = Bus::Usb;
    std::string kind;           ///< the controller map that plays it ("tablet"), empty if none
    std::string detail;         ///< the error, or for NoPermission the exact udev line to add
};
const char* stateName(DeviceStatus::State s);

class DeviceHandle {
public:
    virtual ~DeviceHandle() = default;
    /// Up to `size` bytes of one input report; 0 on timeout; < 0 when the device is gone.
    virtual int read(std::uint8_t* buffer, std::size_t size, int timeoutMs) = 0;
    virtual std::vector<std::uint8_t> descriptor() = 0; ///< empty when it cannot be read
};

class DeviceBackend {
public:
    virtual ~DeviceBackend() = default;
    virtual std::vector<DeviceInfo> enumerate() = 0;
    /// nullptr with `error` set (e.g. permission denied: the udev rule is missing).
    virtual std::unique_ptr<DeviceHandle> open(const DeviceInfo& info, std::string& error) = 0;
};

/// hidapi (hidraw). The report descriptor comes from /sys/class/hidraw/hidrawN/device/report_descriptor.
/// hidapi's global state is initialised by the first backend alive in the process and torn down
/// with the last (two plugin instances share it).
std::unique_ptr<DeviceBackend> makeHidapiBackend();
int hidapiUsers(); ///< backends alive now (tests)
struct Recording;
/// A hid-recorder capture played back as a plugged-in device (its reports at their recorded
/// times); `loop` plays it again and again, else the device unplugs at the end.
std::unique_ptr<DeviceBackend> makeReplayBackend(Recording recording, bool loop);

class HidInput {
public:
    using Queue = rt::SpscQueue<Event, 1024>;

    /// `watcher` may be null: the thread then polls every rescanSeconds.
    explicit HidInput(std::unique_ptr<DeviceBackend> backend, std::unique_ptr<UsbWatcher> watcher = nullptr);
    ~HidInput();

    /// [message thread] Mapping per device kind; a connected device of that kind follows it at
    /// its next report, without reconnecting.
    void setMapping(const HidMapping& m);
    HidMapping mapping(DeviceKind kind) const;

    /// Replace the device layer and the watcher (tests: fakes). Only while stopped; ignored otherwise.
    bool setBackend(std::unique_ptr<DeviceBackend> backend, std::unique_ptr<UsbWatcher> watcher = nullptr);

    void start();
    void stop();
    bool running() const { return running_.load(); }

    /// [audio thread] Drain it every block: events in the order they happened.
    Queue& queue() { return queue_; }

    /// What the thread is doing, in one line: "no controller", "Wacom ... (tablet)", "... unplugged",
    /// "Huion H640P: no permission (see the udev rule)".
    std::string status() const;
    /// Every device of the last scan and what became of it. An error belongs to its scan: a
    /// device that went away, or opened later, leaves no message behind.
    std::vector<DeviceStatus> devices() const;
    /// True when arrivals wake the thread (libusb hot-plug); false when it polls. Any thread: the
    /// watcher itself is made and dropped by start() and stop(), which may run elsewhere.
    bool hotplug() const { return hotplug_.load(); }
    std::uint64_t reportsRead() const { return reports_.load(); }
    int connections() const { return connections_.load(); }

    /// Makes the watcher when the input starts (and drops it when it stops), so that an idle
    /// plugin keeps no libusb thread. Ignored when a watcher was given.
    std::function<std::unique_ptr<UsbWatcher>()> watcherFactory;
    double rescanSeconds = 0.5;       ///< polling interval without hot-plug
    double hotplugRescanSeconds = 3.0; ///< with hot-plug: Bluetooth devices, which USB never announces

private:
    void run();
    bool waitForDevices(double seconds); ///< true when something arrived
    bool departed(const DeviceInfo& info); ///< the watcher says this device has left
    bool watching() const;                 ///< the watcher tells arrivals (the owner of watcher_ asks)
    void setStatus(const std::string& s);
    bool push(const Event& e);

    std::unique_ptr<DeviceBackend> backend_;
    std::unique_ptr<UsbWatcher> watcher_;
    bool madeWatcher_ = false;
    std::atomic<bool> hotplug_{false}; ///< watching(), published for other threads
    Queue queue_;
    std::thread thread_;
    std::atomic<bool> running_{false}, stopRequested_{false};
    std::atomic<std::uint64_t> reports_{0};
    std::atomic<int> connections_{0};
    mutable std::mutex mutex_; ///< guards status_ and mappings_ (never the audio thread)
    std::string status_ = "stopped";
    std::vector<DeviceStatus> devices_;
    std::vector<HidMapping> mappings_;
    std::atomic<unsigned> mappingGeneration_{0}; ///< bumped by setMapping: the thread picks the change up
};

} // namespace rosin::hid
