// USB HID report descriptors: parse what real devices serve (report IDs per report type,
// usage pages mixed inside one main item, the last usage repeating, sign only when the logical
// minimum is negative, 4-bit unit exponents, vendor pages, long items) and decode reports.
// The rules are described in docs/manual.md (HID controllers); fixtures are in tests/data/hid/.
#pragma once
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace rosin::hid {

enum class ReportType : std::uint8_t { Input = 0, Output = 1, Feature = 2 };

/// Page in the high 16 bits, usage ID in the low 16 (the 4-byte usage form).
using Usage = std::uint32_t;
constexpr Usage usage(std::uint16_t page, std::uint16_t id) { return (static_cast<Usage>(page) << 16) | id; }
constexpr std::uint16_t usagePage(Usage u) { return static_cast<std::uint16_t>(u >> 16); }
constexpr std::uint16_t usageId(Usage u) { return static_cast<std::uint16_t>(u & 0xFFFF); }

namespace usages {
constexpr Usage pointer = usage(0x01, 0x01), mouse = usage(0x01, 0x02), joystick = usage(0x01, 0x04),
                gamepad = usage(0x01, 0x05), multiAxis = usage(0x01, 0x08);
constexpr Usage x = usage(0x01, 0x30), y = usage(0x01, 0x31), z = usage(0x01, 0x32), rx = usage(0x01, 0x33),
                ry = usage(0x01, 0x34), rz = usage(0x01, 0x35), slider = usage(0x01, 0x36), hat = usage(0x01, 0x39);
constexpr Usage brake = usage(0x02, 0xC5), accelerator = usage(0x02, 0xC4);
constexpr Usage digitizer = usage(0x0D, 0x01), pen = usage(0x0D, 0x02), tipPressure = usage(0x0D, 0x30),
                inRange = usage(0x0D, 0x32), xTilt = usage(0x0D, 0x3D), yTilt = usage(0x0D, 0x3E),
                tipSwitch = usage(0x0D, 0x42), barrelSwitch = usage(0x0D, 0x44), eraser = usage(0x0D, 0x45),
                invert = usage(0x0D, 0x3C), secondaryBarrel = usage(0x0D, 0x5A);
constexpr Usage button(int n) { return usage(0x09, static_cast<std::uint16_t>(n)); }
} // namespace usages

/// One data element of a report (a Main item of Report Count c makes c of these).
struct Field {
    ReportType type = ReportType::Input;
    int reportId = 0;       ///< 0 when the descriptor has no Report ID items
    int bitOffset = 0;      ///< from the first byte after the report ID
    int bitSize = 0;
    Usage usage = 0;        ///< variable fields; for array fields the usage of value logicalMin
    Usage usageMax = 0;     ///< array fields: the last usage an index can name
    std::int64_t logicalMin = 0, logicalMax = 0, physicalMin = 0, physicalMax = 0;
    int unitExponent = 0;
    std::uint32_t unit = 0;
    std::uint32_t flags = 0; ///< Main item data: b0 constant, b1 variable, b2 relative, b6 null state
    Usage application = 0;   ///< usage of the enclosing application collection

    bool constant() const { return flags & 0x01; }
    bool variable() const { return flags & 0x02; }
    bool relative() const { return flags & 0x04; }
    bool nullState() const { return flags & 0x40; }
    /// Signed only when the logical minimum is negative (Linux's reading, CONTROLLERS.md 1.2).
    bool isSigned() const { return logicalMin < 0; }
};

struct ReportInfo {
    ReportType type;
    int id;
    int bits; ///< payload size, without the report ID byte
    int bytes() const { return (bits + 7) / 8; }
};

class DescriptorError : public std::runtime_error {
public:
    DescriptorError(std::size_t offset, const std::string& what)
        : std::runtime_error("report descriptor, byte " + std::to_string(offset) + ": " + what), offset_(offset) {}
    std::size_t offset() const { return offset_; }

private:
    std::size_t offset_;
};

struct Descriptor {
    std::vector<Field> fields;
    std::vector<ReportInfo> reports;
    std::vector<Usage> applications; ///< top-level application collections, in order
    bool numbered = false;            ///< reports carry an ID byte first

    /// The first non-constant field of this report with this usage, or nullptr.
    const Field* find(ReportType type, int reportId, Usage u) const;
    /// The first non-constant input field with this usage in any report, or nullptr.
    const Field* findInput(Usage u) const;
    const ReportInfo* report(ReportType type, int id) const;
};

/// Parses a descriptor (up to 4096 bytes, HID_MAX_DESCRIPTOR_SIZE). Throws DescriptorError
/// naming the byte and the problem for input no device could mean.
Descriptor parseDescriptor(const std::uint8_t* data, std::size_t size);
inline Descriptor parseDescriptor(const std::vector<std::uint8_t>& d) { return parseDescriptor(d.data(), d.size()); }

/// The raw value of a field in a report payload (after the ID byte): bits little-endian,
/// sign-extended when the field is signed. Bits past the end of the payload read as 0.
std::int64_t extractRaw(const Field& f, const std::uint8_t* payload, std::size_t size);

/// Physical value in the field's unit x 10^exponent (the logical range when no physical
/// range is given), as CONTROLLERS.md 1.2 writes it.
double physicalValue(const Field& f, std::int64_t raw);

/// 0..1 across the logical range (clamped); for signed fields -1..1 with 0 at the centre.
double normalisedValue(const Field& f, std::int64_t raw);

/// True when a null-state field holds a value outside its logical range (a released hat).
bool isNull(const Field& f, std::int64_t raw);

} // namespace rosin::hid
