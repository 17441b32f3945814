// hidapi's hidraw backend: enumerate, open by path, read with a timeout. The descriptor is read
// from sysfs, which needs no extra permission beyond the node itself.
#include <fcntl.h>
#include <hidapi/hidapi.h>
#include <linux/hidraw.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>

#include "rosin/hid/HidInput.h"

namespace rosin::hid {
namespace {
// hidapi keeps process-wide state (hid_init/hid_exit): the first backend initialises it and the
// last one tears it down, so closing one plugin instance never pulls it from under another.
// hid_enumerate and hid_open_path touch that state too (hidapi 0.13 calls hid_init inside them),
// so two instances' threads take turns (ThreadSanitizer saw the race). Reads stay concurrent.
std::mutex hidapiMutex;
int hidapiCount = 0;

std::string narrow(const wchar_t* w)
{
    std::string s;
    if (!w) return s;
    for (; *w; ++w) s.push_back(*w < 128 ? static_cast<char>(*w) : '?');
    return s;
}

class HidapiHandle : public DeviceHandle {
public:
    HidapiHandle(hid_device* d, std::string path) : device_(d), path_(std::move(path)) {}
    ~HidapiHandle() override
    {
        const std::lock_guard<std::mutex> lock(hidapiMutex);
        hid_close(device_);
    }

    int read(std::uint8_t* buffer, std::size_t size, int timeoutMs) override
    {
        const int n = hid_read_timeout(device_, buffer, size, timeoutMs);
        return n < 0 ? -1 : n;
    }

    std::vector<std::uint8_t> descriptor() override
    {
        // /dev/hidraw3 -> /sys/class/hidraw/hidraw3/device/report_descriptor
        const std::filesystem::path node(path_);
        std::ifstream in("/sys/class/hidraw/" + node.filename().string() + "/device/report_descriptor", std::ios::binary);
        std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        if (!bytes.empty()) return bytes;
        // No sysfs (some containers): ask the node itself.
        const int fd = ::open(path_.c_str(), O_RDONLY | O_NONBLOCK);
        if (fd < 0) return {};
        int size = 0;
        hidraw_report_descriptor desc{};
        if (ioctl(fd, HIDIOCGRDESCSIZE, &size) == 0 && size > 0 && size <= HID_MAX_DESCRIPTOR_SIZE) {
            desc.size = static_cast<__u32>(size);
            if (ioctl(fd, HIDIOCGRDESC, &desc) == 0) bytes.assign(desc.value, desc.value + size);
        }
        ::close(fd);
        return bytes;
    }

private:
    hid_device* device_;
    std::string path_;
};

class HidapiBackend : public DeviceBackend {
public:
    HidapiBackend()
    {
        const std::lock_guard<std::mutex> lock(hidapiMutex);
        if (hidapiCount++ == 0) hid_init();
    }
    ~HidapiBackend() override
    {
        const std::lock_guard<std::mutex> lock(hidapiMutex);
        if (--hidapiCount == 0) hid_exit();
    }

    std::vector<DeviceInfo> enumerate() override
    {
        std::vector<DeviceInfo> out;
        const std::lock_guard<std::mutex> lock(hidapiMutex);
        hid_device_info* list = hid_enumerate(0, 0);
        for (auto* d = list; d; d = d->next) {
            DeviceInfo info;
            info.path = d->path ? d->path : "";
            info.vendor = d->vendor_id;
            info.product = d->product_id;
            info.name = narrow(d->manufacturer_string) + " " + narrow(d->product_string);
            info.bus = d->bus_type == HID_API_BUS_BLUETOOTH ? Bus::Bluetooth : Bus::Usb;
            if (info.bus == Bus::Usb) usbAddressOf(info.path, info.usbBus, info.usbAddress);
            out.push_back(info);
        }
        hid_free_enumeration(list);
        return out;
    }

    std::unique_ptr<DeviceHandle> open(const DeviceInfo& info, std::string& error) override
    {
        const std::lock_guard<std::mutex> lock(hidapiMutex);
        errno = 0;
        hid_device* d = hid_open_path(info.path.c_str());
        if (!d) {
            error = errno == EACCES || errno == EPERM
                        ? "permission denied: the udev rule is missing (rosin-host hid --udev-rules, see README)"
                        : (errno ? std::strerror(errno) : "hidapi could not open it");
            return nullptr;
        }
        return std::make_unique<HidapiHandle>(d, info.path);
    }
};
} // namespace

std::unique_ptr<DeviceBackend> makeHidapiBackend() { return std::make_unique<HidapiBackend>(); }

int hidapiUsers()
{
    const std::lock_guard<std::mutex> lock(hidapiMutex);
    return hidapiCount;
}

} // namespace rosin::hid
