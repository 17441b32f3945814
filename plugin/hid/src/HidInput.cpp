#include "rosin/hid/HidInput.h"

#include <chrono>
#include <fstream>

namespace rosin::hid {
namespace {
double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
} // namespace

HidInput::HidInput(std::unique_ptr<DeviceBackend> backend) : backend_(std::move(backend))
{
    for (DeviceKind k : {DeviceKind::Tablet, DeviceKind::Gamepad, DeviceKind::SpaceMouse, DeviceKind::Joystick})
        mappings_.push_back(HidMapping::defaultFor(k));
}

HidInput::~HidInput() { stop(); }

void HidInput::setMapping(const HidMapping& m)
{
    const std::lock_guard<std::mutex> lock(mutex_);
    for (auto& existing : mappings_)
        if (existing.kind == m.kind) { existing = m; return; }
    mappings_.push_back(m);
}

HidMapping HidInput::mapping(DeviceKind kind) const
{
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& m : mappings_)
        if (m.kind == kind) return m;
    return HidMapping::defaultFor(kind);
}

void HidInput::setFilter(std::uint16_t vendor, std::uint16_t product)
{
    const std::lock_guard<std::mutex> lock(mutex_);
    filterVendor_ = vendor;
    filterProduct_ = product;
}

bool HidInput::setBackend(std::unique_ptr<DeviceBackend> backend)
{
    if (running_.load() || !backend) return false;
    backend_ = std::move(backend);
    return true;
}

void HidInput::start()
{
    if (running_.exchange(true)) return;
    stopRequested_ = false;
    thread_ = std::thread([this] { run(); });
}

void HidInput::stop()
{
    stopRequested_ = true;
    if (thread_.joinable()) thread_.join();
    running_ = false;
    setStatus("stopped");
}

std::string HidInput::status() const
{
    const std::lock_guard<std::mutex> lock(mutex_);
    return status_;
}

void HidInput::setStatus(const std::string& s)
{
    const std::lock_guard<std::mutex> lock(mutex_);
    status_ = s;
}

bool HidInput::push(const BowCommand& c)
{
    // A full queue means the audio thread is not running (no host playback): drop, the next
    // report carries the current state anyway. Note triggers are retried briefly.
    for (int attempt = 0; attempt < 3; ++attempt) {
        if (queue_.push(c)) return true;
        if (c.noteOn < 0 && c.noteOff < 0) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return false;
}

void HidInput::run()
{
    setStatus("no controller");
    std::vector<std::uint8_t> buffer(4096);
    std::string lastError, gone;
    while (!stopRequested_) {
        // Find a device we can play.
        std::unique_ptr<DeviceHandle> handle;
        DeviceInfo info;
        DeviceDecoder decoder;
        std::uint16_t fv = 0, fp = 0;
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            fv = filterVendor_;
            fp = filterProduct_;
        }
        for (const DeviceInfo& candidate : backend_->enumerate()) {
            if (fv != 0 && (candidate.vendor != fv || (fp != 0 && candidate.product != fp))) continue;
            std::string error;
            auto h = backend_->open(candidate, error);
            if (!h) {
                lastError = "cannot open " + candidate.name + " (" + candidate.path + "): " + error;
                continue;
            }
            const auto bytes = h->descriptor();
            try {
                DeviceDecoder d(parseDescriptor(bytes), quirksFor(candidate.vendor, candidate.product));
                if (d.kind() == DeviceKind::Other && fv == 0) continue; // keyboards, mice: not a bow
                decoder = std::move(d);
            } catch (const std::exception& e) {
                lastError = candidate.name + ": " + e.what();
                continue;
            }
            handle = std::move(h);
            info = candidate;
            break;
        }
        if (!handle) {
            setStatus(!lastError.empty() ? lastError : gone.empty() ? "no controller" : gone + " unplugged, waiting for a controller");
            const double until = now() + rescanSeconds;
            while (!stopRequested_ && now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(20));
            continue;
        }
        ++connections_;
        lastError.clear();
        gone.clear();
        BowMapper mapper(mapping(decoder.kind()));
        DeviceState state;
        setStatus(info.name + " (" + kindName(decoder.kind()) + ")");
        while (!stopRequested_) {
            const int n = handle->read(buffer.data(), buffer.size(), 10);
            if (n < 0) { // unplugged mid-note: lift the bow and end its notes
                push(mapper.release(now()));
                gone = info.name;
                setStatus(info.name + " unplugged");
                break;
            }
            if (n == 0) continue;
            ++reports_;
            if (decoder.apply(buffer.data(), static_cast<std::size_t>(n), state)) push(mapper.update(state, now()));
        }
        if (stopRequested_) push(mapper.release(now()));
    }
}

} // namespace rosin::hid
