// From a HID device to the bow: device profiles (tablet, gamepad, 3D mouse, joystick), the
// normalised device state, editable curves, calibration, and the mapper that turns the state
// into bow force (N), bow speed (m/s, signed: its sign is the bow direction), bow position
// (beta), string selection and note triggers. No JUCE; runs on the HID thread.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rosin/hid/Descriptor.h"
#include "rosin/presets/Document.h"

namespace rosin::hid {

enum class DeviceKind { Tablet, Gamepad, SpaceMouse, Joystick, Other };
const char* kindName(DeviceKind k);
DeviceKind parseKind(const std::string& name); ///< throws std::runtime_error on an unknown name
DeviceKind classify(const Descriptor& d);

/// Known descriptor errors (CONTROLLERS.md 1.2): hidraw gives the unfixed reports.
struct Quirks {
    bool forceAbsolute = false;   ///< axes flagged Relative that carry absolute data (SpaceNavigator)
    double hatDegreesPerStep = 0; ///< a hat whose logical range does not match its physical one
};
Quirks quirksFor(std::uint16_t vendor, std::uint16_t product);

/// Everything the mapping reads, normalised. Split reports (3D mouse) hold their last values.
struct DeviceState {
    bool tip = false, inRange = false;
    double pressure = 0.0, x = 0.5, y = 0.5, tiltX = 0.0, tiltY = 0.0; ///< tablet: 0..1, tilt -1..1
    /// Generic desktop X, Y, Z, Rx, Ry, Rz, Slider: -1..1 (sticks centred, signed axes as sent).
    std::array<double, 7> axes{};
    double triggerL = 0.0, triggerR = 0.0; ///< 0..1
    std::uint64_t buttons = 0;             ///< bit n-1 = button n
    int hat = -1;                          ///< 0..7 clockwise from up, -1 released
};

/// Decodes one device's input reports into a DeviceState.
class DeviceDecoder {
public:
    DeviceDecoder() = default;
    /// `kind` other than Other overrides what the descriptor suggests (the device table, or the
    /// USB product string, knows better where a descriptor is ambiguous).
    DeviceDecoder(Descriptor descriptor, Quirks quirks, DeviceKind kind = DeviceKind::Other);
    /// One report as hidraw delivers it. False (state untouched) when the report is unknown or short.
    bool apply(const std::uint8_t* report, std::size_t size, DeviceState& state) const;
    const Descriptor& descriptor() const { return descriptor_; }
    DeviceKind kind() const { return kind_; }

private:
    Descriptor descriptor_;
    Quirks quirks_;
    DeviceKind kind_ = DeviceKind::Other;
};

enum class Source {
    None, Pressure, X, Y, TiltX, TiltY, AxisX, AxisY, AxisZ, AxisRx, AxisRy, AxisRz, Slider, TriggerL, TriggerR
};
const char* sourceName(Source s);
Source parseSource(const std::string& name); ///< throws std::runtime_error on an unknown name
double read(const DeviceState& s, Source src);

/// in -> out: normalise over [inMin, inMax], dead zone, invert, power curve, then [outMin, outMax].
struct Curve {
    double inMin = 0.0, inMax = 1.0, outMin = 0.0, outMax = 1.0;
    double exponent = 1.0; ///< > 1 is soft at the start (a light touch stays light)
    double deadzone = 0.0; ///< fraction of the input range treated as 0
    bool invert = false;
    double operator()(double x) const;
};

/// How a device plays the bow. Outputs are the parameter layer's normalised controls, the same
/// a MIDI controller sends: force 0..1 and position 0..1 (0.5 = the instrument's nominal bow
/// force and position), speed -1..1 (0.5 = the nominal bow speed; the sign is the direction).
/// The instrument maps them to newtons, m/s and beta in one place, with its per-string scaling.
struct HidMapping {
    std::string name = "tablet";
    DeviceKind kind = DeviceKind::Tablet;
    Source force = Source::Pressure;
    Curve forceCurve{0.0, 1.0, 0.0, 1.0, 1.5};       ///< 0.5 = nominal force
    Source speed = Source::X;
    bool speedFromMotion = true;                     ///< speed = d(source)/dt x speedScale (tablets)
    double speedScale = 0.75;                        ///< normalised speed per (full range)/s
    Curve speedCurve{-1.0, 1.0, -1.0, 1.0, 1.0, 0.08}; ///< direct sources (sticks)
    double speedSmoothing = 0.03;                    ///< s (the derivative of ~100-1000 Hz reports)
    Source position = Source::Y;
    Curve positionCurve{0.0, 1.0, 0.0, 1.0};         ///< 0.5 = nominal position
    Source stringSelect = Source::TiltX;
    Curve stringCurve{-0.6, 0.6, 0.0, 1.0};          ///< 0..1 split evenly over the strings
    int strings = 4;
    bool requireTip = true;                          ///< tablets: the bow is on the string while the pen touches
    int tipNote = 50;                                ///< note played while the pen touches (-1: none, keyboard plays)
    std::array<int, 8> buttonNotes{-1, -1, -1, -1, -1, -1, -1, -1}; ///< button n+1 holds this note
    double bowChangeThreshold = 0.05;                ///< normalised speed: a sign change beyond this is a bow change

    static HidMapping defaultFor(DeviceKind kind);
    std::string toJson() const; ///< rosin-hid/2
    /// From JSON: rosin-hid/2, or rosin-hid/1 (physical units, converted with the instruments'
    /// default nominal bow: 1.1 N, 0.15 m/s, beta 0.0899). Throws presets::PresetError naming
    /// `where` and the field.
    static HidMapping fromJson(const std::string& text, const std::string& where);
    static HidMapping fromDocument(const presets::Document& document);
};

/// What the HID thread sends to the audio thread, in order, through the SPSC queue: the bow
/// after each report, then every note that started or ended in it; Released when the device
/// is gone or the input stops (after a NoteOff for every note it held).
struct Event {
    enum class Kind : std::uint8_t { Bow, NoteOn, NoteOff, Released };
    Kind kind = Kind::Bow;
    double seconds = 0.0;            ///< steady-clock time of the report (the audio thread's frame offset)
    float force = 0.0f, speed = 0.0f, position = 0.5f; ///< normalised (HidMapping)
    std::int8_t string = -1;         ///< the string chosen, -1 none
    std::int8_t note = -1;           ///< NoteOn / NoteOff
    bool engaged = false;            ///< the bow is on the string
    bool bowChange = false;          ///< the direction flipped at this report
};

class BowMapper {
public:
    explicit BowMapper(HidMapping mapping = {}) : mapping_(std::move(mapping)) {}
    const HidMapping& mapping() const { return mapping_; }
    /// A new mapping takes effect at the next report; notes held stay held.
    void setMapping(const HidMapping& m) { mapping_ = m; }
    void reset();
    /// Appends the events of this state at this time (seconds, monotonic): a Bow event, then the
    /// note transitions, however many the report holds.
    void update(const DeviceState& s, double seconds, std::vector<Event>& out);
    /// The device is gone or the input stops: a NoteOff for every held note, then Released.
    void release(double seconds, std::vector<Event>& out);
    int heldNotes() const { return static_cast<int>(held_.size()); }

private:
    void noteOn(int note, double seconds, std::vector<Event>& out);
    void noteOff(int note, double seconds, std::vector<Event>& out);

    HidMapping mapping_;
    bool haveLast_ = false, wasEngaged_ = false;
    double lastTime_ = 0.0, lastCoord_ = 0.0, speed_ = 0.0;
    int direction_ = 0, heldTipNote_ = -1;
    std::uint64_t lastButtons_ = 0;
    std::vector<int> held_; ///< notes this device holds now
};

} // namespace rosin::hid
