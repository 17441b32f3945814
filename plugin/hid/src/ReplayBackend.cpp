// A recorded device played back as if it were plugged in: the reports of a hid-recorder capture
// at their recorded times, from the moment it is opened. For demonstrations without a device,
// the validation pass (ROSIN_HID_REPLAY) and tests.
#include <chrono>
#include <thread>

#include "rosin/hid/HidInput.h"
#include "rosin/hid/Recording.h"

namespace rosin::hid {
namespace {
class ReplayHandle : public DeviceHandle {
public:
    ReplayHandle(const Recording& r, bool loop) : recording_(r), loop_(loop), start_(std::chrono::steady_clock::now()) {}

    int read(std::uint8_t* buffer, std::size_t size, int timeoutMs) override
    {
        if (next_ >= recording_.reports.size()) {
            if (!loop_ || recording_.reports.empty()) return -1; // the capture ended: unplugged
            next_ = 0;
            start_ = std::chrono::steady_clock::now();
        }
        const RecordedReport& r = recording_.reports[next_];
        const auto due = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(r.seconds));
        const auto limit = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeoutMs);
        if (due > limit) {
            std::this_thread::sleep_until(limit);
            return 0;
        }
        std::this_thread::sleep_until(due);
        ++next_;
        const std::size_t n = std::min(size, r.bytes.size());
        std::copy_n(r.bytes.begin(), n, buffer);
        return static_cast<int>(n);
    }
    std::vector<std::uint8_t> descriptor() override { return recording_.descriptor; }

private:
    const Recording& recording_;
    bool loop_;
    std::chrono::steady_clock::time_point start_;
    std::size_t next_ = 0;
};

class ReplayBackend : public DeviceBackend {
public:
    ReplayBackend(Recording r, bool loop) : recording_(std::move(r)), loop_(loop) {}
    std::vector<DeviceInfo> enumerate() override
    {
        if (played_ && !loop_) return {}; // played once and unplugged
        return {{"replay:" + recording_.name, recording_.vendor, recording_.product, recording_.name + " (recorded)"}};
    }
    std::unique_ptr<DeviceHandle> open(const DeviceInfo&, std::string&) override
    {
        played_ = true;
        return std::make_unique<ReplayHandle>(recording_, loop_);
    }

private:
    Recording recording_;
    bool loop_;
    bool played_ = false;
};
} // namespace

std::unique_ptr<DeviceBackend> makeReplayBackend(Recording recording, bool loop)
{
    return std::make_unique<ReplayBackend>(std::move(recording), loop);
}

} // namespace rosin::hid
