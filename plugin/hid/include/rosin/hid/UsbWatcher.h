// USB arrivals and departures, and a device's name strings, through libusb. The HID thread waits
// on it instead of re-enumerating: a controller plugged in mid-session is opened at once, and an
// unplug ends its notes at once. An interface, so that tests drive hot-plug without hardware.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rosin::hid {

struct UsbDevice {
    std::uint16_t vendor = 0, product = 0;
    std::uint8_t busNumber = 0, address = 0;
    /// From the device's string descriptors; empty when they cannot be read (no permission on
    /// the USB node, or the device gave none).
    std::string manufacturer, productName, serial;
};

struct UsbChange {
    bool arrived = true; ///< false: left
    UsbDevice device;
};

class UsbWatcher {
public:
    virtual ~UsbWatcher() = default;
    /// True when the platform tells about arrivals (libusb hot-plug); false: the caller polls.
    virtual bool hotplug() const = 0;
    /// Changes since the last call, waiting up to `timeoutMs` for the first one.
    virtual std::vector<UsbChange> wait(int timeoutMs) = 0;
    /// The USB devices attached now, with their strings where readable.
    virtual std::vector<UsbDevice> attached() = 0;
};

/// libusb: hot-plug callbacks on its own event thread where LIBUSB_CAP_HAS_HOTPLUG, else a
/// device-list comparison every `pollMs`. Never throws; without libusb it reports no devices.
std::unique_ptr<UsbWatcher> makeLibusbWatcher(int pollMs = 500);

/// The USB device behind a hidraw node (/dev/hidrawN -> sysfs busnum/devnum), if it is on USB.
bool usbAddressOf(const std::string& hidrawPath, std::uint8_t& busNumber, std::uint8_t& address);

} // namespace rosin::hid
