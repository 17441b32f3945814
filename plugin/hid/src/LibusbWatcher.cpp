// libusb's hot-plug API (1.0.16+): callbacks run inside libusb_handle_events on our event
// thread and only queue the change; the HID thread takes them with wait(). Strings are read
// with libusb_open + GET_DESCRIPTOR(string), a standard device request that needs no interface
// claim, so the kernel's HID driver keeps the device (CONTROLLERS notes: never detach usbhid).
#include <libusb-1.0/libusb.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

#include "rosin/hid/UsbWatcher.h"

namespace rosin::hid {
namespace {
std::string stringDescriptor(libusb_device_handle* h, std::uint8_t index)
{
    if (index == 0) return {};
    unsigned char text[256] = {};
    const int n = libusb_get_string_descriptor_ascii(h, index, text, sizeof text);
    return n > 0 ? std::string(reinterpret_cast<char*>(text), static_cast<std::size_t>(n)) : std::string{};
}

UsbDevice describe(libusb_device* dev, bool readStrings)
{
    UsbDevice d;
    d.busNumber = libusb_get_bus_number(dev);
    d.address = libusb_get_device_address(dev);
    libusb_device_descriptor desc{};
    if (libusb_get_device_descriptor(dev, &desc) != 0) return d;
    d.vendor = desc.idVendor;
    d.product = desc.idProduct;
    libusb_device_handle* h = nullptr;
    if (readStrings && libusb_open(dev, &h) == 0) {
        d.manufacturer = stringDescriptor(h, desc.iManufacturer);
        d.productName = stringDescriptor(h, desc.iProduct);
        d.serial = stringDescriptor(h, desc.iSerialNumber);
        libusb_close(h);
    }
    return d;
}

class LibusbWatcher : public UsbWatcher {
public:
    explicit LibusbWatcher(int pollMs) : pollMs_(pollMs)
    {
        if (libusb_init(&context_) != 0) {
            context_ = nullptr;
            return;
        }
        hotplug_ = libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) != 0;
        if (hotplug_) {
            const int events = LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT;
            if (libusb_hotplug_register_callback(context_, events, LIBUSB_HOTPLUG_NO_FLAGS, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
                                                 LIBUSB_HOTPLUG_MATCH_ANY, &LibusbWatcher::onChange, this, &callback_) != LIBUSB_SUCCESS)
                hotplug_ = false;
        }
        if (hotplug_)
            events_ = std::thread([this] {
                while (!quit_.load()) {
                    timeval tv{0, 100000};
                    libusb_handle_events_timeout_completed(context_, &tv, nullptr);
                }
            });
        else
            known_ = attached();
    }

    ~LibusbWatcher() override
    {
        if (!context_) return;
        quit_ = true;
        if (hotplug_) {
            libusb_hotplug_deregister_callback(context_, callback_); // wakes the event thread
            if (events_.joinable()) events_.join();
        }
        libusb_exit(context_);
    }

    bool hotplug() const override { return hotplug_; }

    std::vector<UsbChange> wait(int timeoutMs) override
    {
        if (!context_) {
            std::this_thread::sleep_for(std::chrono::milliseconds(timeoutMs));
            return {};
        }
        if (!hotplug_) return poll(timeoutMs);
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait_for(lock, std::chrono::milliseconds(timeoutMs), [&] { return !pending_.empty(); });
        std::vector<UsbChange> out(pending_.begin(), pending_.end());
        pending_.clear();
        lock.unlock();
        // Strings are read here, on the caller's thread, not inside libusb's callback.
        for (auto& c : out)
            if (c.arrived) c.device = withStrings(c.device);
        return out;
    }

    std::vector<UsbDevice> attached() override
    {
        std::vector<UsbDevice> out;
        if (!context_) return out;
        libusb_device** list = nullptr;
        const ssize_t n = libusb_get_device_list(context_, &list);
        std::map<int, UsbDevice> still;
        for (ssize_t i = 0; i < n; ++i) {
            // Strings are asked for once per device: a scan every few seconds must not send
            // requests to every hub and keyboard on the machine.
            const int key = libusb_get_bus_number(list[i]) << 8 | libusb_get_device_address(list[i]);
            const auto cached = strings_.find(key);
            UsbDevice d = describe(list[i], cached == strings_.end());
            if (cached != strings_.end() && cached->second.vendor == d.vendor && cached->second.product == d.product) d = cached->second;
            still[key] = d;
            out.push_back(d);
        }
        if (n >= 0) libusb_free_device_list(list, 1);
        strings_ = std::move(still);
        return out;
    }

private:
    static int LIBUSB_CALL onChange(libusb_context*, libusb_device* dev, libusb_hotplug_event event, void* self)
    {
        auto* w = static_cast<LibusbWatcher*>(self);
        UsbChange c;
        c.arrived = event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED;
        c.device = describe(dev, false); // no I/O on a device inside the callback
        {
            const std::lock_guard<std::mutex> lock(w->mutex_);
            w->pending_.push_back(c);
        }
        w->cv_.notify_one();
        return 0; // stay registered
    }

    UsbDevice withStrings(const UsbDevice& d)
    {
        libusb_device** list = nullptr;
        const ssize_t n = libusb_get_device_list(context_, &list);
        UsbDevice out = d;
        for (ssize_t i = 0; i < n; ++i)
            if (libusb_get_bus_number(list[i]) == d.busNumber && libusb_get_device_address(list[i]) == d.address) out = describe(list[i], true);
        if (n >= 0) libusb_free_device_list(list, 1);
        return out;
    }

    std::vector<UsbChange> poll(int timeoutMs)
    {
        std::this_thread::sleep_for(std::chrono::milliseconds(std::min(timeoutMs, pollMs_)));
        const auto now = attached();
        auto same = [](const UsbDevice& a, const UsbDevice& b) { return a.busNumber == b.busNumber && a.address == b.address; };
        std::vector<UsbChange> out;
        for (const auto& d : now)
            if (std::none_of(known_.begin(), known_.end(), [&](const UsbDevice& k) { return same(k, d); })) out.push_back({true, d});
        for (const auto& k : known_)
            if (std::none_of(now.begin(), now.end(), [&](const UsbDevice& d) { return same(k, d); })) out.push_back({false, k});
        known_ = now;
        return out;
    }

    libusb_context* context_ = nullptr;
    libusb_hotplug_callback_handle callback_{};
    bool hotplug_ = false;
    int pollMs_;
    std::thread events_;
    std::atomic<bool> quit_{false};
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<UsbChange> pending_;
    std::vector<UsbDevice> known_;
    std::map<int, UsbDevice> strings_; ///< by bus << 8 | address, for the devices attached now
};
} // namespace

std::unique_ptr<UsbWatcher> makeLibusbWatcher(int pollMs) { return std::make_unique<LibusbWatcher>(std::max(50, pollMs)); }

bool usbAddressOf(const std::string& hidrawPath, std::uint8_t& busNumber, std::uint8_t& address)
{
    // /sys/class/hidraw/hidrawN/device -> .../usbB/B-P/B-P:C.I/0003:VVVV:PPPP.NNNN: the USB
    // device is the first ancestor with busnum and devnum.
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path p = fs::canonical("/sys/class/hidraw/" + fs::path(hidrawPath).filename().string() + "/device", ec);
    if (ec) return false;
    for (; !p.empty() && p != p.root_path(); p = p.parent_path()) {
        std::ifstream bus(p / "busnum"), dev(p / "devnum");
        int b = 0, d = 0;
        if (bus >> b && dev >> d) {
            busNumber = static_cast<std::uint8_t>(b);
            address = static_cast<std::uint8_t>(d);
            return true;
        }
    }
    return false;
}

} // namespace rosin::hid
