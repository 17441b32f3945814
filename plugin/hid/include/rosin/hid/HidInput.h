// The HID input thread: finds a controller (hot-plug: devices come and go while playing), reads
// its reports, decodes and maps them, and hands Events (the bow, note transitions, time-stamped)
// to the audio thread through a lock-free SPSC queue. The device layer is an interface so tests drive it with a fake device;
// HidapiBackend is the real one (hidapi's hidraw backend; descriptors from sysfs).
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rosin/rt/SpscQueue.h"
#include "rosin/hid/Mapping.h"

namespace rosin::hid {

struct DeviceInfo {
    std::string path;          ///< /dev/hidrawN for hidapi's hidraw backend
    std::uint16_t vendor = 0, product = 0;
    std::string name;
};

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
std::unique_ptr<DeviceBackend> makeHidapiBackend();
struct Recording;
/// A hid-recorder capture played back as a plugged-in device (its reports at their recorded
/// times); `loop` plays it again and again, else the device unplugs at the end.
std::unique_ptr<DeviceBackend> makeReplayBackend(Recording recording, bool loop);

class HidInput {
public:
    using Queue = rt::SpscQueue<Event, 1024>;

    explicit HidInput(std::unique_ptr<DeviceBackend> backend);
    ~HidInput();

    /// [message thread] Mapping per device kind; a connected device of that kind follows it at
    /// its next report, without reconnecting.
    void setMapping(const HidMapping& m);
    HidMapping mapping(DeviceKind kind) const;

    /// Replace the device layer (tests: a fake device). Only while stopped; ignored otherwise.
    bool setBackend(std::unique_ptr<DeviceBackend> backend);

    void start();
    void stop();
    bool running() const { return running_.load(); }

    /// [audio thread] Drain it every block: events in the order they happened.
    Queue& queue() { return queue_; }

    /// What the thread is doing, for people: "no controller", "Wacom ... (tablet)", "... unplugged",
    /// "cannot open ...: permission denied (install the udev rule)".
    std::string status() const;
    std::uint64_t reportsRead() const { return reports_.load(); }
    int connections() const { return connections_.load(); }

    double rescanSeconds = 0.5;

private:
    void run();
    void setStatus(const std::string& s);
    bool push(const Event& e);

    std::unique_ptr<DeviceBackend> backend_;
    Queue queue_;
    std::thread thread_;
    std::atomic<bool> running_{false}, stopRequested_{false};
    std::atomic<std::uint64_t> reports_{0};
    std::atomic<int> connections_{0};
    mutable std::mutex mutex_; ///< guards status_ and mappings_ (never the audio thread)
    std::string status_ = "stopped";
    std::vector<HidMapping> mappings_;
    std::atomic<unsigned> mappingGeneration_{0}; ///< bumped by setMapping: the thread picks the change up
};

} // namespace rosin::hid
