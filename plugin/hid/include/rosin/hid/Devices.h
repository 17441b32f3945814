// The controllers Rosin knows by name: vendor and product id, bus, kind (which controller map
// plays it) and descriptor quirks. The table is the single source of the udev rule: one line per
// product, so the rule grants access to these devices and to nothing else of their vendors.
#pragma once
#include <cstdint>
#include <span>
#include <string>

#include "rosin/hid/Mapping.h"

namespace rosin::hid {

enum class Bus { Usb, Bluetooth };

struct SupportedDevice {
    std::uint16_t vendor = 0, product = 0;
    Bus bus = Bus::Usb;
    DeviceKind kind = DeviceKind::Other; ///< the controller map (presets/controllers/<kind>.json)
    const char* name = "";
    Quirks quirks{};
};

std::span<const SupportedDevice> supportedDevices();
/// The table's entry for a product on a bus (a Bluetooth pad may be listed for USB only: then
/// nullptr), else nullptr.
const SupportedDevice* findSupported(std::uint16_t vendor, std::uint16_t product, Bus bus);
const SupportedDevice* findSupported(std::uint16_t vendor, std::uint16_t product); ///< any bus

/// The udev line that lets the seat's user open this product: hidraw by USB vendor/product;
/// Bluetooth by the HID id in the parent's kernel name ("0005:VVVV:PPPP.NNNN", upper case); the
/// USB device node too, so libusb can read its string descriptors.
std::string udevLine(const SupportedDevice& d);
/// The whole rules file, as scripts/udev/70-rosin-hid.rules ships it (`rosin-host hid --udev-rules`).
std::string udevRules();

/// Whether a rule line would tag a device (a small matcher for the attributes the rule uses:
/// SUBSYSTEM, ATTRS{idVendor}, ATTRS{idProduct}, KERNELS with * globs). Comment lines match nothing.
/// `subsystem` is "hidraw" or "usb".
bool udevLineMatches(const std::string& line, std::uint16_t vendor, std::uint16_t product, Bus bus, const std::string& subsystem);

} // namespace rosin::hid
