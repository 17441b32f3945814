#include "rosin/hid/Descriptor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace rosin::hid {
namespace {
constexpr std::size_t maxDescriptorSize = 4096;
constexpr int maxReportBits = 8 * 4096;   // hidraw reports are at most a few kB
constexpr int maxFieldsPerItem = 8192;    // Report Count is 32-bit in the item; no device needs more
constexpr std::size_t maxFields = 65536;

struct Globals {
    std::uint16_t page = 0;
    std::int64_t logicalMin = 0, logicalMax = 0, physicalMin = 0, physicalMax = 0;
    std::uint32_t logicalMaxRaw = 0;

    int unitExponent = 0;
    std::uint32_t unit = 0;
    int reportSize = 0, reportId = 0, reportCount = 0;
};

struct Locals {
    std::vector<Usage> usages;
    Usage usageMin = 0, usageMax = 0;
    bool haveMin = false, haveMax = false;
    void clear() { *this = Locals{}; }
};

std::uint32_t unsignedData(const std::uint8_t* p, int size)
{
    std::uint32_t v = 0;
    for (int i = 0; i < size; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
    return v;
}

std::int64_t signedData(const std::uint8_t* p, int size)
{
    const std::uint32_t v = unsignedData(p, size);
    switch (size) {
    case 1: return static_cast<std::int8_t>(v);
    case 2: return static_cast<std::int16_t>(v);
    case 4: return static_cast<std::int32_t>(v);
    default: return 0;
    }
}

/// A usage item: 4-byte data carries its own page; shorter data takes the page in force now.
Usage localUsage(const std::uint8_t* p, int size, std::uint16_t page)
{
    const std::uint32_t v = unsignedData(p, size);
    return size == 4 ? v : usage(page, static_cast<std::uint16_t>(v));
}
} // namespace

const Field* Descriptor::find(ReportType type, int reportId, Usage u) const
{
    for (const auto& f : fields)
        if (f.type == type && f.reportId == reportId && f.usage == u && !f.constant() && f.variable()) return &f;
    return nullptr;
}

const Field* Descriptor::findInput(Usage u) const
{
    for (const auto& f : fields)
        if (f.type == ReportType::Input && f.usage == u && !f.constant() && f.variable()) return &f;
    return nullptr;
}

const ReportInfo* Descriptor::report(ReportType type, int id) const
{
    for (const auto& r : reports)
        if (r.type == type && r.id == id) return &r;
    return nullptr;
}

Descriptor parseDescriptor(const std::uint8_t* data, std::size_t size)
{
    if (data == nullptr || size == 0) throw DescriptorError(0, "empty descriptor");
    if (size > maxDescriptorSize)
        throw DescriptorError(maxDescriptorSize, "longer than 4096 bytes (HID_MAX_DESCRIPTOR_SIZE)");
    Descriptor d;
    Globals g;
    std::vector<Globals> stack;
    Locals locals;
    std::vector<Usage> collections; // usage of each open collection
    std::vector<bool> applicationLevel;
    Usage application = 0;
    std::map<std::pair<int, int>, int> offsets; // (type, id) -> next bit
    bool sawMain = false;

    std::size_t i = 0;
    while (i < size) {
        const std::size_t at = i;
        const std::uint8_t prefix = data[i++];
        if (prefix == 0xFE) { // long item: size, tag, data. No device uses them; skip safely.
            if (i + 2 > size) throw DescriptorError(at, "long item cut off");
            const std::size_t len = data[i];
            i += 2 + len;
            if (i > size) throw DescriptorError(at, "long item runs past the end");
            continue;
        }
        static constexpr std::array<int, 4> sizes{0, 1, 2, 4};
        const int len = sizes[prefix & 0x03];
        const int type = (prefix >> 2) & 0x03, tag = prefix >> 4;
        if (i + static_cast<std::size_t>(len) > size) throw DescriptorError(at, "item data runs past the end");
        const std::uint8_t* p = data + i;
        i += static_cast<std::size_t>(len);

        if (type == 0) { // Main
            sawMain = true;
            if (tag == 0x8 || tag == 0x9 || tag == 0xB) {
                const ReportType rt = tag == 0x8 ? ReportType::Input : tag == 0x9 ? ReportType::Output : ReportType::Feature;
                if (g.reportCount < 0 || g.reportCount > maxFieldsPerItem)
                    throw DescriptorError(at, "Report Count " + std::to_string(g.reportCount) + " is beyond any device");
                if (g.reportSize < 0 || g.reportSize > 64) // wider values exist only as opaque byte arrays
                    throw DescriptorError(at, "Report Size " + std::to_string(g.reportSize) + " bits is not supported (1-64)");
                int& next = offsets[{static_cast<int>(rt), g.reportId}];
                const std::uint32_t flags = unsignedData(p, len);
                for (int k = 0; k < g.reportCount; ++k) {
                    Field f;
                    f.type = rt;
                    f.reportId = g.reportId;
                    f.bitOffset = next;
                    f.bitSize = g.reportSize;
                    f.flags = flags;
                    f.logicalMin = g.logicalMin;
                    // Linux reads Logical Max unsigned unless the minimum is negative.
                    f.logicalMax = g.logicalMin < 0 ? g.logicalMax : static_cast<std::int64_t>(g.logicalMaxRaw);
                    f.physicalMin = g.physicalMin;
                    f.physicalMax = g.physicalMax;
                    f.unitExponent = g.unitExponent;
                    f.unit = g.unit;
                    f.application = application;
                    const bool isVariable = flags & 0x02;
                    if (!locals.usages.empty()) {
                        // Fields take the queued usages in order; the last one repeats.
                        f.usage = locals.usages[std::min<std::size_t>(static_cast<std::size_t>(k), locals.usages.size() - 1)];
                    } else if (locals.haveMin) {
                        const Usage last = locals.haveMax ? std::max(locals.usageMax, locals.usageMin) : locals.usageMin;
                        f.usage = isVariable ? std::min<Usage>(locals.usageMin + static_cast<Usage>(k), last) : locals.usageMin;
                        f.usageMax = last;
                    }
                    if (!isVariable && f.usageMax == 0) f.usageMax = f.usage;
                    if (d.fields.size() >= maxFields) throw DescriptorError(at, "more than 65536 fields");
                    d.fields.push_back(f);
                    next += g.reportSize;
                    if (next > maxReportBits) throw DescriptorError(at, "report longer than 4096 bytes");
                }
            } else if (tag == 0xA) { // Collection
                const Usage u = locals.usages.empty() ? (locals.haveMin ? locals.usageMin : 0) : locals.usages.front();
                const bool isApplication = unsignedData(p, len) == 0x01;
                if (isApplication && application == 0) {
                    application = u;
                    d.applications.push_back(u);
                }
                collections.push_back(u);
                applicationLevel.push_back(isApplication && application == u);
                if (collections.size() > 64) throw DescriptorError(at, "collections nested more than 64 deep");
            } else if (tag == 0xC) { // End Collection
                if (collections.empty()) throw DescriptorError(at, "End Collection without a Collection");
                if (applicationLevel.back()) {
                    bool inner = false;
                    for (std::size_t c = 0; c + 1 < applicationLevel.size(); ++c) inner = inner || applicationLevel[c];
                    if (!inner) application = 0;
                }
                collections.pop_back();
                applicationLevel.pop_back();
            } else {
                throw DescriptorError(at, "unknown Main item tag " + std::to_string(tag));
            }
            locals.clear();
            continue;
        }
        if (type == 1) { // Global
            switch (tag) {
            case 0x0: g.page = static_cast<std::uint16_t>(unsignedData(p, len)); break;
            case 0x1: g.logicalMin = signedData(p, len); break;
            case 0x2:
                g.logicalMax = signedData(p, len);
                g.logicalMaxRaw = unsignedData(p, len);
                break;
            case 0x3: g.physicalMin = signedData(p, len); break;
            case 0x4: g.physicalMax = signedData(p, len); break;
            case 0x5: { // a 4-bit two's-complement nibble: 0x0C = -4
                const int nibble = static_cast<int>(unsignedData(p, len) & 0x0F);
                g.unitExponent = nibble >= 8 ? nibble - 16 : nibble;
                break;
            }
            case 0x6: g.unit = unsignedData(p, len); break;
            case 0x7: g.reportSize = static_cast<int>(unsignedData(p, len)); break;
            case 0x8:
                g.reportId = static_cast<int>(unsignedData(p, len));
                if (g.reportId <= 0 || g.reportId > 255) throw DescriptorError(at, "Report ID must be 1-255");
                if (!d.numbered && sawMain && !d.fields.empty() && d.fields.front().reportId == 0)
                    throw DescriptorError(at, "Report ID after unnumbered report fields");
                d.numbered = true;
                break;
            case 0x9: {
                const std::uint32_t c = unsignedData(p, len);
                if (c > static_cast<std::uint32_t>(maxFieldsPerItem))
                    throw DescriptorError(at, "Report Count " + std::to_string(c) + " is beyond any device");
                g.reportCount = static_cast<int>(c);
                break;
            }
            case 0xA:
                if (stack.size() >= 32) throw DescriptorError(at, "Push nested more than 32 deep");
                stack.push_back(g);
                break;
            case 0xB:
                if (stack.empty()) throw DescriptorError(at, "Pop without Push");
                g = stack.back();
                stack.pop_back();
                break;
            default: throw DescriptorError(at, "unknown Global item tag " + std::to_string(tag));
            }
            continue;
        }
        if (type == 2) { // Local
            switch (tag) {
            case 0x0:
                if (locals.usages.size() >= 4096) throw DescriptorError(at, "more than 4096 usages on one item");
                locals.usages.push_back(localUsage(p, len, g.page));
                break;
            case 0x1: locals.usageMin = localUsage(p, len, g.page); locals.haveMin = true; break;
            case 0x2: locals.usageMax = localUsage(p, len, g.page); locals.haveMax = true; break;
            default: break; // designators, strings, delimiters: nothing we use
            }
            continue;
        }
        throw DescriptorError(at, "reserved item type 3");
    }
    if (!collections.empty()) throw DescriptorError(size, std::to_string(collections.size()) + " collection(s) never closed");
    for (const auto& [key, bits] : offsets) d.reports.push_back({static_cast<ReportType>(key.first), key.second, bits});
    if (d.fields.empty()) throw DescriptorError(size, "no Input, Output or Feature item");
    return d;
}

std::int64_t extractRaw(const Field& f, const std::uint8_t* payload, std::size_t size)
{
    if (f.bitSize <= 0) return 0;
    std::uint64_t v = 0;
    for (int b = 0; b < f.bitSize; ++b) {
        const std::size_t bit = static_cast<std::size_t>(f.bitOffset + b);
        const std::size_t byte = bit / 8;
        if (byte >= size) break;
        v |= static_cast<std::uint64_t>((payload[byte] >> (bit % 8)) & 1u) << b;
    }
    if (f.isSigned() && f.bitSize < 64 && (v >> (f.bitSize - 1)) & 1u) v |= ~0ull << f.bitSize;
    return static_cast<std::int64_t>(v);
}

double physicalValue(const Field& f, std::int64_t raw)
{
    const double scale = std::pow(10.0, f.unitExponent);
    if (f.physicalMin == 0 && f.physicalMax == 0) return static_cast<double>(raw) * scale;
    if (f.logicalMax == f.logicalMin) return static_cast<double>(f.physicalMin) * scale;
    const double t = static_cast<double>(raw - f.logicalMin) / static_cast<double>(f.logicalMax - f.logicalMin);
    return (static_cast<double>(f.physicalMin) + t * static_cast<double>(f.physicalMax - f.physicalMin)) * scale;
}

double normalisedValue(const Field& f, std::int64_t raw)
{
    if (f.logicalMax <= f.logicalMin) return 0.0;
    const double lo = static_cast<double>(f.logicalMin), hi = static_cast<double>(f.logicalMax);
    const double x = std::clamp(static_cast<double>(raw), lo, hi);
    if (f.isSigned()) return x >= 0.0 ? (hi > 0 ? x / hi : 0.0) : (lo < 0 ? -x / lo : 0.0);
    return (x - lo) / (hi - lo);
}

bool isNull(const Field& f, std::int64_t raw)
{
    return f.nullState() && (raw < f.logicalMin || raw > f.logicalMax);
}

} // namespace rosin::hid
