#include "rosin/engine/ControllerMap.h"

namespace rosin::engine {

ControllerMap::ControllerMap() : active_(std::make_unique<ControllerTable>()) {}

void ControllerMap::set(int cc, int param, float min, float max, bool invert)
{
    if (cc < 0 || cc >= numControllers) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    if (param >= 0)
        for (auto& s : edited_.slots)
            if (s.param == param && s.cc != cc) s.param = -1; // the parameter moves to this controller
    edited_.slots[static_cast<std::size_t>(cc)] = {cc, param, min, max, invert};
    publishLocked();
}

void ControllerMap::assign(const std::vector<MappingEntry>& list)
{
    const std::lock_guard<std::mutex> lock(mutex_);
    edited_ = ControllerTable{};
    for (const auto& e : list)
        if (e.cc >= 0 && e.cc < numControllers) edited_.slots[static_cast<std::size_t>(e.cc)] = e;
    publishLocked();
}

void ControllerMap::publishLocked() { handoff_.publish(std::make_unique<ControllerTable>(edited_)); }

MappingEntry ControllerMap::get(int cc) const
{
    const std::lock_guard<std::mutex> lock(mutex_);
    return edited_.get(cc);
}

std::vector<MappingEntry> ControllerMap::entries() const
{
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<MappingEntry> out;
    for (const auto& s : edited_.slots)
        if (s.param >= 0) out.push_back(s);
    return out;
}

const ControllerTable& ControllerMap::acquire() noexcept
{
    if (retiring_ != nullptr && handoff_.retire(retiring_)) retiring_ = nullptr;
    if (retiring_ == nullptr)
        if (ControllerTable* next = handoff_.takePending()) {
            retiring_ = active_.release();
            active_.reset(next);
            if (handoff_.retire(retiring_)) retiring_ = nullptr;
        }
    return *active_;
}

} // namespace rosin::engine
