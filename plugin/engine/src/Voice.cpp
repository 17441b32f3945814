#include "rosin/engine/Voice.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rosin::engine {
namespace {
constexpr double silence = 1e-5;      ///< -100 dB: the voice is free
constexpr double harmonicTouch = 3.0; ///< the light finger's resistance, x Z0 [A]
constexpr std::size_t index(Param p) { return static_cast<std::size_t>(p); }
} // namespace

void Voice::prepare(double sampleRate, const std::array<dsp::BowedString<float>, maxStrings>& strings, int stringCount)
{
    stringCount_ = std::clamp(stringCount, 0, maxStrings);
    for (int s = 0; s < stringCount_; ++s) strings_[static_cast<std::size_t>(s)] = strings[static_cast<std::size_t>(s)];
    gesture_.prepare(sampleRate);
    reset();
}

void Voice::reset() noexcept
{
    active_ = keyDown_ = sustained_ = released_ = stolen_ = false;
    for (int s = 0; s < stringCount_; ++s) strings_[static_cast<std::size_t>(s)].reset();
    heldCount_ = 0;
    lastTemperature_ = 0.0f;
}

bool Voice::pushHeld(int note) noexcept
{
    if (heldCount_ < static_cast<int>(held_.size())) held_[static_cast<std::size_t>(heldCount_++)] = note;
    else held_.back() = note;
    return true;
}

bool Voice::holds(int note) const noexcept
{
    for (int i = 0; i < heldCount_; ++i)
        if (held_[static_cast<std::size_t>(i)] == note) return true;
    return false;
}

void Voice::configureFriction(dsp::FrictionModel model, dsp::ContactLaw law, double glassTransition, double ambient, double footprint) noexcept
{
    for (int s = 0; s < stringCount_; ++s) {
        auto& j = strings_[static_cast<std::size_t>(s)].junction();
        j.setModel(model);
        j.setContactLaw(law, 2.0 / 3.0);
        j.setGlassTransition(glassTransition);
        j.setAmbient(ambient);
        j.setFootprintRatio(footprint);
    }
}

int Voice::popHeld(int note) noexcept
{
    int at = -1;
    for (int i = 0; i < heldCount_; ++i)
        if (held_[static_cast<std::size_t>(i)] == note) at = i;
    if (at < 0) return heldCount_ > 0 ? held_[static_cast<std::size_t>(heldCount_ - 1)] : -1;
    for (int i = at; i + 1 < heldCount_; ++i) held_[static_cast<std::size_t>(i)] = held_[static_cast<std::size_t>(i + 1)];
    --heldCount_;
    return heldCount_ > 0 ? held_[static_cast<std::size_t>(heldCount_ - 1)] : -1;
}

void Voice::start(const Start& s, const VoiceContext& ctx) noexcept
{
    const ParamValues& params = *ctx.params;
    if (active_) strings_[static_cast<std::size_t>(string_)].reset(); // a slot reused
    string_ = std::clamp(s.string, 0, std::max(0, stringCount_ - 1));
    harmonic_ = s.harmonic;
    auto& string = strings_[static_cast<std::size_t>(string_)];
    string.reset();
    string.waveguide().setHarmonic(harmonic_, harmonicTouch);
    active_ = keyDown_ = true;
    sustained_ = released_ = stolen_ = false;
    channel_ = s.channel;
    note_ = s.note;
    velocity_ = s.velocity;
    polyPressure_ = -1.0f;
    order_ = s.order;
    held_[0] = s.note;
    heldCount_ = 1;
    pitch_ = glideTarget_ = s.note;
    glideStep_ = 0.0;
    // Velocity is the attack: Guettler's constant bow acceleration from rest, and a force that
    // starts above the nominal and settles (a player "bites" harder for a louder attack). The
    // articulation shapes the stroke; the caller alternates down and up bows per channel.
    gesture_.start(s.articulation, velocity_, s.gesture, s.direction, s.bowPosition);
    speed_ = force_ = aimForce_ = 0.0;
    lift_ = fade_ = 1.0;
    age_ = 0.0;
    vibratoPhase_ = 0.0;
    wasStick_ = true;
    samplesSinceSlip_ = periodsHeard_ = 0;
    heardPeriod_ = correctionCents_ = 0.0;
    beta_ = params[index(Param::BowPosition)];
    untilControl_ = 0;
    gainL_ = s.gainL;
    gainR_ = s.gainR;
    updateControl(ctx);
    untilControl_ = controlInterval;
    beta_ = std::clamp(beta_, dsp::config::minBeta, dsp::config::maxBeta); // start at the target: no glide of the bow point
}

void Voice::release() noexcept
{
    keyDown_ = sustained_ = false;
    released_ = true;
    gesture_.release();
}

void Voice::steal() noexcept
{
    release();
    stolen_ = true;
}

void Voice::glideTo(int note, double seconds, double sampleRate) noexcept
{
    note_ = note;
    glideTarget_ = note;
    glideStep_ = seconds > 0.0 ? std::abs(glideTarget_ - pitch_) * controlInterval / (seconds * sampleRate) : 1e9;
    polyPressure_ = -1.0f;
}

void Voice::updateControl(const VoiceContext& ctx) noexcept
{
    const ParamValues& params = *ctx.params;
    const Performance::Channel c = ctx.performance->effective(channel_);
    direct_ = c.hand.holds;
    engaged_ = c.hand.engaged;
    // The one mapping from normalised controls to the model's units (Controls.h).
    const float force01 = polyPressure_ >= 0.0f ? polyPressure_ : c.hand.holds && c.hand.force >= 0.0f ? c.hand.force : c.force;
    const float speed = c.hand.holds ? c.hand.speed : (c.speed >= 0.0f ? c.speed : 0.5f);
    const float position01 = c.hand.holds && c.hand.position >= 0.0f ? c.hand.position : c.position;
    const BowTarget t = mapBow(params, (*ctx.stringScale)[static_cast<std::size_t>(string_)], force01, speed, position01);
    targetForce_ = c.hand.holds && !c.hand.engaged ? 0.0 : t.force;
    targetSpeed_ = t.speed;
    // The bow point glides to its target; once there it stops moving (the waveguide redesigns its
    // taps whenever beta changes, so an endless creep of 1e-9 would cost that every control tick).
    beta_ += (t.beta - beta_) * ctx.betaSmoothing;
    if (std::abs(t.beta - beta_) < 1e-6 * t.beta) beta_ = t.beta;
    volume_ = c.volume;
    liftStep_ = 1.0 / (ctx.sampleRate * std::max(0.005, static_cast<double>(params[index(Param::ReleaseTime)])));

    // Pitch: glide (portamento), bend (channel plus zone master), vibrato, intonation.
    if (pitch_ != glideTarget_) {
        const double d = glideTarget_ - pitch_;
        pitch_ = std::abs(d) <= glideStep_ ? glideTarget_ : pitch_ + std::copysign(glideStep_, d);
    }
    age_ += controlInterval / ctx.sampleRate;
    const double onset = std::clamp((age_ - params[index(Param::VibratoDelay)]) / 0.3, 0.0, 1.0);
    const double vibratoAmount = std::max(static_cast<double>(c.vibrato), params[index(Param::VibratoAuto)] * onset);
    double vibrato = 0.0;
    if (vibratoAmount > 0.0) {
        vibrato = params[index(Param::VibratoDepth)] / 100.0 * vibratoAmount * std::sin(vibratoPhase_);
        vibratoPhase_ += 2.0 * std::numbers::pi * params[index(Param::VibratoRate)] * controlInterval / ctx.sampleRate;
        if (vibratoPhase_ > 2.0 * std::numbers::pi) vibratoPhase_ -= 2.0 * std::numbers::pi;
    } else {
        vibratoPhase_ = 0.0;
    }
    auto noteFrequency = [&](double midi) { return ctx.tuningA4 * std::exp2((midi - 69.0) / 12.0); };
    targetPeriod_ = ctx.sampleRate / noteFrequency(pitch_ + c.bend);
    if (gesture_.plucked()) beta_ = 0.25; // plucked over the end of the fingerboard, struck likewise
    frequency_ = noteFrequency(pitch_ + c.bend + vibrato + params[index(Param::Intonation)] * correctionCents_ / 100.0);
    // Re-stopping redesigns the loss filters: skip moves below 0.02 cent (the ear's correction
    // creeps by less than that between periods once it has settled).
    auto& waveguide = strings_[static_cast<std::size_t>(string_)].waveguide();
    const double stopped = harmonic_ > 0 ? frequency_ / harmonic_ : frequency_; // a harmonic: the string under it
    if (std::abs(stopped - waveguide.fundamental()) > 1e-5 * stopped) waveguide.setFundamental(stopped);
}

void Voice::listen(bool stick) noexcept
{
    // A slip onset each Helmholtz period: the interval between onsets is the sounding period.
    // Bowed strings play flat as the force rises (the corner rounds and is delayed at each
    // capture); a player hears it and moves the finger. Intervals far from the target (a
    // double slip, raucous motion, a glide) are ignored, and the finger moves a little each period.
    ++samplesSinceSlip_;
    if (wasStick_ && !stick && targetPeriod_ > 0.0) {
        // A secondary slip inside the period (a double slip, a ripple that broke free) does
        // not end the period: keep counting to the next onset about one period later.
        const double interval = samplesSinceSlip_;
        if (interval >= 0.85 * targetPeriod_) {
            if (interval < 1.15 * targetPeriod_) {
                heardPeriod_ = periodsHeard_ == 0 ? interval : heardPeriod_ + 0.2 * (interval - heardPeriod_);
                if (++periodsHeard_ > 4) {
                    const double errorCents = 1200.0 * std::log2(heardPeriod_ / targetPeriod_); // > 0: flat
                    correctionCents_ = std::clamp(correctionCents_ + 0.08 * errorCents, -50.0, 100.0);
                }
            }
            samplesSinceSlip_ = 0;
        }
    }
    wasStick_ = stick;
}

int Voice::renderBlock(float* out, std::uint8_t* stick, int m, const VoiceContext& ctx, VoiceTaps* taps) noexcept
{
    // The bow (or the controller's hand) for the whole sub-block first: it does not depend on
    // the string, so the string can then run the sub-block in one call.
    float force[controlInterval], speed[controlInterval], beta[controlInterval];
    double pluck[controlInterval];
    bool off[controlInterval];
    bool plucking = false;
    const float b = static_cast<float>(beta_);
    for (int k = 0; k < m; ++k) {
        pluck[k] = 0.0;
        if (direct_) { // a controller's hand is its own gesture (and may reverse): follow it
            speed_ += (targetSpeed_ - speed_) * ctx.smoothing;
            force_ += (targetForce_ - force_) * ctx.smoothing;
            if (released_) lift_ = std::max(0.0, lift_ - liftStep_);
            off[k] = released_ && lift_ <= 0.0;
        } else {
            aimForce_ += (targetForce_ - aimForce_) * ctx.smoothing;
            const dsp::GestureFrame g = gesture_.next({aimForce_, targetSpeed_, beta_});
            speed_ = g.speed;
            force_ = g.force;
            lift_ = 1.0;
            pluck[k] = g.pluck;
            plucking = plucking || g.pluck != 0.0;
            off[k] = gesture_.off();
        }
        force[k] = static_cast<float>(force_ * lift_);
        speed[k] = static_cast<float>(speed_);
        beta[k] = b;
    }
    auto& string = strings_[static_cast<std::size_t>(string_)];
    const bool framed = taps && taps->view != nullptr;
    if (plucking || framed || perSample_) {
        for (int k = 0; k < m; ++k) {
            dsp::BowFrame<float> frame;
            if (pluck[k] != 0.0) { // the finger or the stick pushes the string; no friction
                string.waveguide().setBeta(beta_);
                string.processForce(static_cast<float>(pluck[k]));
                out[k] = string.waveguide().bridgeForce();
                frame.stick = false;
                frame.temperature = static_cast<float>(string.junction().temperature());
                force[k] = 0.0f;
            } else {
                out[k] = string.processSample(force[k], speed[k], beta[k], &frame);
            }
            stick[k] = frame.stick ? 1 : 0;
            if (framed) {
                ViewFrame& f = taps->view[taps->viewCount++];
                f.bridgeForce = out[k];
                f.velocity = frame.velocity;
                f.bowSpeed = speed[k];
                f.friction = frame.friction;
                f.force = force[k];
                f.temperature = frame.temperature;
                f.beta = b;
                f.frequency = static_cast<float>(frequency_);
                f.stick = stick[k];
                f.string = static_cast<std::uint8_t>(string_);
                f.noteStart = 0;
                f.bowed = pluck[k] != 0.0 ? 0 : 1;
            }
        }
    } else {
        string.processBlock(force, speed, beta, out, m, nullptr, stick);
    }
    lastTemperature_ = static_cast<float>(string.junction().temperature());
    for (int k = 0; k < m; ++k) stick[k] |= static_cast<std::uint8_t>(off[k] ? 2 : 0); // bit 1: the bow has left
    return m;
}

void Voice::processBlock(float* busL, float* busR, int n, const VoiceContext& ctx, VoiceTaps* taps) noexcept
{
    if (!active_) return;
    float out[controlInterval];
    std::uint8_t stick[controlInterval];
    const float gl = gainL_ * volume_ * volume_, gr = gainR_ * volume_ * volume_;
    for (int i = 0; i < n && active_;) {
        if (untilControl_ <= 0) {
            updateControl(ctx);
            untilControl_ = controlInterval;
        }
        const int m = std::min(untilControl_, n - i);
        renderBlock(out, stick, m, ctx, taps);
        untilControl_ -= m;
        // A voice that went non-finite is reset and freed; the others play on.
        float sum = 0.0f;
        for (int k = 0; k < m; ++k) sum += out[k];
        if (!std::isfinite(sum)) {
            reset();
            return;
        }
        if (taps && taps->bridge)
            for (int k = 0; k < m && taps->count < taps->capacity; ++k, ++taps->count) {
                taps->bridge[taps->count] = out[k];
                if (taps->stick) taps->stick[taps->count] = stick[k] & 1;
            }
        if (!released_) { // held: no fade, the common case
            for (int k = 0; k < m; ++k) {
                listen((stick[k] & 1) != 0);
                busL[i + k] += gl * out[k];
                busR[i + k] += gr * out[k];
            }
        } else {
            for (int k = 0; k < m; ++k) {
                const bool bowOff = (stick[k] & 2) != 0;
                listen((stick[k] & 1) != 0);
                if (stolen_) fade_ *= ctx.stealCoefficient;
                else if (bowOff) fade_ *= ctx.ringCoefficient;
                const float y = static_cast<float>(out[k] * fade_);
                busL[i + k] += gl * y;
                busR[i + k] += gr * y;
                if ((stolen_ || bowOff) && fade_ < silence) {
                    active_ = false;
                    strings_[static_cast<std::size_t>(string_)].reset();
                    break;
                }
            }
        }
        i += m;
    }
}

VoiceInfo Voice::info() const noexcept
{
    VoiceInfo info;
    info.active = active_;
    if (!active_) return info;
    info.channel = channel_;
    info.note = note_;
    info.stringIndex = string_;
    info.keyDown = keyDown_;
    info.released = released_;
    info.frequency = frequency_;
    info.correctionCents = correctionCents_;
    info.force = force_ * lift_;
    info.bowDirection = speed_ > 0.0 ? 1 : speed_ < 0.0 ? -1 : 0;
    info.bowPosition = gesture_.bowPosition();
    info.speed = speed_;
    info.beta = beta_;
    info.temperature = lastTemperature_;
    return info;
}

} // namespace rosin::engine
