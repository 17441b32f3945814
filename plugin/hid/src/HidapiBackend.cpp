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

#include "rosin/hid/HidInput.h"

namespace rosin::hid {
namespace {
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
    ~HidapiHandle() override { hid_close(device_); }

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
    HidapiBackend() { hid_init(); }
    ~HidapiBackend() override { hid_exit(); }

    std::vector<DeviceInfo> enumerate() override
    {
        std::vector<DeviceInfo> out;
        hid_device_info* list = hid_enumerate(0, 0);
        for (auto* d = list; d; d = d->next) {
            DeviceInfo info;
            info.path = d->path ? d->path : "";
            info.vendor = d->vendor_id;
            info.product = d->product_id;
            info.name = narrow(d->manufacturer_string) + " " + narrow(d->product_string);
            out.push_back(info);
        }
        hid_free_enumeration(list);
        return out;
    }

    std::unique_ptr<DeviceHandle> open(const DeviceInfo& info, std::string& error) override
    {
        errno = 0;
        hid_device* d = hid_open_path(info.path.c_str());
        if (!d) {
            error = errno == EACCES || errno == EPERM
                        ? "permission denied: install the udev rule (scripts/udev/70-rosin-hid.rules, see README)"
                        : (errno ? std::strerror(errno) : "hidapi could not open it");
            return nullptr;
        }
        return std::make_unique<HidapiHandle>(d, info.path);
    }
};
} // namespace

std::unique_ptr<DeviceBackend> makeHidapiBackend() { return std::make_unique<HidapiBackend>(); }

} // namespace rosin::hid
