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
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        bool replaced = false;
        for (auto& existing : mappings_)
            if (existing.kind == m.kind) {
                existing = m;
                replaced = true;
            }
        if (!replaced) mappings_.push_back(m);
    }
    mappingGeneration_.fetch_add(1, std::memory_order_release);
}

HidMapping HidInput::mapping(DeviceKind kind) const
{
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& m : mappings_)
        if (m.kind == kind) return m;
    return HidMapping::defaultFor(kind);
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

bool HidInput::push(const Event& e)
{
    // A full queue means the audio thread is not running (no host playback): a bow state is
    // dropped (the next report carries the current one); note transitions are retried briefly.
    for (int attempt = 0; attempt < 3; ++attempt) {
        if (queue_.push(e)) return true;
        if (e.kind == Event::Kind::Bow) return false;
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
        for (const DeviceInfo& candidate : backend_->enumerate()) {
            std::string error;
            auto h = backend_->open(candidate, error);
            if (!h) {
                lastError = "cannot open " + candidate.name + " (" + candidate.path + "): " + error;
                continue;
            }
            const auto bytes = h->descriptor();
            try {
                DeviceDecoder d(parseDescriptor(bytes), quirksFor(candidate.vendor, candidate.product));
                if (d.kind() == DeviceKind::Other) continue; // keyboards, mice: not a bow
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
        unsigned generation = mappingGeneration_.load(std::memory_order_acquire);
        BowMapper mapper(mapping(decoder.kind()));
        DeviceState state;
        std::vector<Event> events;
        auto send = [&] {
            for (const Event& e : events) push(e);
            events.clear();
        };
        setStatus(info.name + " (" + kindName(decoder.kind()) + ")");
        while (!stopRequested_) {
            if (const unsigned g = mappingGeneration_.load(std::memory_order_acquire); g != generation) {
                generation = g; // edited in the window: applies from the next report
                mapper.setMapping(mapping(decoder.kind()));
            }
            const int n = handle->read(buffer.data(), buffer.size(), 10);
            if (n < 0) { // unplugged mid-note: lift the bow and end its notes
                mapper.release(now(), events);
                send();
                gone = info.name;
                setStatus(info.name + " unplugged");
                break;
            }
            if (n == 0) continue;
            ++reports_;
            if (decoder.apply(buffer.data(), static_cast<std::size_t>(n), state)) {
                mapper.update(state, now(), events);
                send();
            }
        }
        if (stopRequested_) {
            mapper.release(now(), events);
            send();
        }
    }
}

} // namespace rosin::hid
