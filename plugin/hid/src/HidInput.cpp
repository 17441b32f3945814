#include "rosin/hid/HidInput.h"

#include <algorithm>
#include <chrono>
#include <set>

namespace rosin::hid {
namespace {
double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool contains(const std::string& text, const char* word)
{
    std::string lower = text;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return lower.find(word) != std::string::npos;
}

/// What a product string says the device is, where its descriptor alone does not.
DeviceKind kindFromName(const std::string& name)
{
    if (contains(name, "spacemouse") || contains(name, "spacenavigator") || contains(name, "spacepilot")) return DeviceKind::SpaceMouse;
    if (contains(name, "tablet") || contains(name, "pen")) return DeviceKind::Tablet;
    if (contains(name, "joystick") || contains(name, "throttle") || contains(name, "flight")) return DeviceKind::Joystick;
    if (contains(name, "gamepad") || contains(name, "controller")) return DeviceKind::Gamepad;
    return DeviceKind::Other;
}

bool sameUsb(const DeviceInfo& info, const UsbDevice& u)
{
    if (info.bus != Bus::Usb) return false;
    if (info.usbBus != 0 || info.usbAddress != 0) return info.usbBus == u.busNumber && info.usbAddress == u.address;
    return info.vendor == u.vendor && info.product == u.product; // address unknown (fakes, containers)
}
} // namespace

const char* stateName(DeviceStatus::State s)
{
    switch (s) {
    case DeviceStatus::State::Connected: return "connected";
    case DeviceStatus::State::Available: return "available";
    case DeviceStatus::State::NoPermission: return "no permission";
    case DeviceStatus::State::Unsupported: return "unsupported";
    case DeviceStatus::State::NotABow: return "not a controller";
    case DeviceStatus::State::Failed: return "failed";
    }
    return "?";
}

HidInput::HidInput(std::unique_ptr<DeviceBackend> backend, std::unique_ptr<UsbWatcher> watcher)
    : backend_(std::move(backend)), watcher_(std::move(watcher))
{
    hotplug_ = watching();
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

bool HidInput::setBackend(std::unique_ptr<DeviceBackend> backend, std::unique_ptr<UsbWatcher> watcher)
{
    if (running_.load() || !backend) return false;
    backend_ = std::move(backend);
    watcher_ = std::move(watcher);
    watcherFactory = nullptr; // the watcher belongs to the device layer it came with
    hotplug_ = watching();
    return true;
}

void HidInput::start()
{
    if (running_.exchange(true)) return;
    stopRequested_ = false;
    if (!watcher_ && watcherFactory) {
        watcher_ = watcherFactory();
        madeWatcher_ = true;
    }
    hotplug_ = watching();
    thread_ = std::thread([this] { run(); });
}

void HidInput::stop()
{
    stopRequested_ = true;
    if (thread_.joinable()) thread_.join();
    if (madeWatcher_) {
        watcher_.reset();
        madeWatcher_ = false;
    }
    hotplug_ = watching();
    running_ = false;
    setStatus("stopped");
}

std::string HidInput::status() const
{
    const std::lock_guard<std::mutex> lock(mutex_);
    return status_;
}

std::vector<DeviceStatus> HidInput::devices() const
{
    const std::lock_guard<std::mutex> lock(mutex_);
    return devices_;
}

bool HidInput::watching() const { return watcher_ && watcher_->hotplug(); }

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

bool HidInput::waitForDevices(double seconds)
{
    const double until = now() + seconds;
    while (!stopRequested_ && now() < until) {
        if (!watching()) { // polling: the next scan enumerates again
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            continue;
        }
        const int ms = std::clamp(static_cast<int>((until - now()) * 1000.0), 1, 50);
        for (const UsbChange& c : watcher_->wait(ms))
            if (c.arrived) return true;
    }
    return false;
}

bool HidInput::departed(const DeviceInfo& info)
{
    if (!watching()) return false; // without hot-plug, a failed read tells
    bool left = false;
    for (const UsbChange& c : watcher_->wait(0))
        if (!c.arrived && sameUsb(info, c.device)) left = true;
    return left;
}

void HidInput::run()
{
    setStatus("no controller");
    std::vector<std::uint8_t> buffer(4096);
    std::string gone;
    while (!stopRequested_) {
        // One scan: every device gets a fresh status; nothing from an earlier scan survives.
        // hidraw first, then USB: a device that arrives between the two waits for the next scan
        // instead of being listed without its USB name strings.
        std::vector<DeviceInfo> found = backend_->enumerate();
        const std::vector<UsbDevice> usb = watcher_ ? watcher_->attached() : std::vector<UsbDevice>{};
        // The devices Rosin knows first; hidapi lists a device once per top-level collection.
        std::stable_partition(found.begin(), found.end(), [](const DeviceInfo& d) { return findSupported(d.vendor, d.product, d.bus) != nullptr; });
        std::set<std::string> paths;
        std::vector<DeviceStatus> seen;
        std::unique_ptr<DeviceHandle> handle;
        DeviceInfo info;
        DeviceDecoder decoder;
        for (const DeviceInfo& candidate : found) {
            if (!paths.insert(candidate.path).second) continue;
            const SupportedDevice* known = findSupported(candidate.vendor, candidate.product, candidate.bus);
            DeviceStatus st;
            st.vendor = candidate.vendor;
            st.product = candidate.product;
            st.bus = candidate.bus;
            st.name = known ? known->name : candidate.name;
            std::string strings;
            for (const UsbDevice& u : usb)
                if (sameUsb(candidate, u) && !u.productName.empty()) {
                    strings = u.manufacturer.empty() ? u.productName : u.manufacturer + " " + u.productName;
                    st.name = strings + (u.serial.empty() ? "" : " (" + u.serial + ")");
                }
            if (handle) { // one controller plays; the others wait their turn
                st.state = known ? DeviceStatus::State::Available : DeviceStatus::State::Unsupported;
                if (known) st.kind = kindName(known->kind);
                else st.detail = "no profile";
                seen.push_back(st);
                continue;
            }
            std::string error;
            auto h = backend_->open(candidate, error);
            if (!h) {
                const bool permission = error.rfind("permission denied", 0) == 0;
                if (known) {
                    st.state = permission ? DeviceStatus::State::NoPermission : DeviceStatus::State::Failed;
                    st.kind = kindName(known->kind);
                    st.detail = permission ? udevLine(*known) : error;
                } else {
                    // Keyboards, mice and receivers are root-only and stay so: not our business.
                    st.state = DeviceStatus::State::Unsupported;
                    st.detail = permission ? "no profile (and root-only)" : "no profile";
                }
                seen.push_back(st);
                continue;
            }
            try {
                const DeviceKind kind = known ? known->kind : kindFromName(strings.empty() ? candidate.name : strings);
                DeviceDecoder d(parseDescriptor(h->descriptor()), quirksFor(candidate.vendor, candidate.product), kind);
                if (d.kind() == DeviceKind::Other) {
                    st.state = DeviceStatus::State::NotABow;
                    seen.push_back(st);
                    continue;
                }
                decoder = std::move(d);
            } catch (const std::exception& e) {
                st.state = DeviceStatus::State::Failed;
                st.detail = e.what();
                seen.push_back(st);
                continue;
            }
            st.state = DeviceStatus::State::Connected;
            st.kind = kindName(decoder.kind());
            seen.push_back(st);
            handle = std::move(h);
            info = candidate;
            info.name = st.name;
        }
        // The line and the list change together: whoever reads one sees the other of the same scan.
        std::string summary;
        if (handle) {
            summary = info.name + " (" + kindName(decoder.kind()) + ")";
        } else {
            const auto blocked = std::find_if(seen.begin(), seen.end(), [](const DeviceStatus& s) {
                return s.state == DeviceStatus::State::NoPermission || s.state == DeviceStatus::State::Failed;
            });
            if (blocked != seen.end())
                summary = blocked->name + ": " + (blocked->state == DeviceStatus::State::NoPermission ? "no permission (add the udev rule)" : blocked->detail);
            else
                summary = gone.empty() ? "no controller" : gone + " unplugged, waiting for a controller";
        }
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            devices_ = seen;
            status_ = summary;
        }
        if (!handle) {
            waitForDevices(watching() ? hotplugRescanSeconds : rescanSeconds);
            continue;
        }
        ++connections_;
        gone.clear();
        unsigned generation = mappingGeneration_.load(std::memory_order_acquire);
        BowMapper mapper(mapping(decoder.kind()));
        DeviceState state;
        std::vector<Event> events;
        auto send = [&] {
            for (const Event& e : events) push(e);
            events.clear();
        };
        auto lost = [&](const char* why) {
            mapper.release(now(), events); // lift the bow and end its notes
            send();
            gone = info.name;
            const std::lock_guard<std::mutex> lock(mutex_);
            status_ = info.name + " " + why;
            devices_.clear();
        };
        while (!stopRequested_) {
            if (const unsigned g = mappingGeneration_.load(std::memory_order_acquire); g != generation) {
                generation = g; // edited in the window: applies from the next report
                mapper.setMapping(mapping(decoder.kind()));
            }
            const int n = handle->read(buffer.data(), buffer.size(), 10);
            if (n < 0 || departed(info)) { // the watcher may tell before a read fails
                lost("unplugged");
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
