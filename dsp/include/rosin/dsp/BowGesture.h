// The player's right arm: turns "a note starts / ends" plus the bow the player aims at (force,
// speed, position) into per-sample bow force, signed bow speed and a pluck force, for one
// articulation, on a bow of finite length that has to change direction when it runs out.
// Every articulation is a bow (or finger) trajectory fed to the same string and friction model.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>

namespace rosin::dsp {

enum class Articulation { Detache = 0, Martele, Spiccato, Tremolo, ColLegno, Pizzicato, Harmonic, Count };

struct GestureSettings {
    double bowLength = 0.65;       ///< usable hair (m): a violin bow has about 65 cm
    double bowChangeTime = 0.04;   ///< s from full speed one way to full speed the other
    double acceleration = 6.0;     ///< m/s^2 at full velocity: Guettler's constant acceleration
    double attackBoost = 0.5;      ///< extra initial force at full velocity (fraction), decays over 80 ms
    double releaseTime = 0.08;     ///< s: the bow lifts
    double tremoloRate = 8.0;      ///< strokes per second
    double spiccatoRate = 7.0;     ///< bounces per second
    double spiccatoContact = 0.45; ///< fraction of each bounce the hair is on the string
    double marteleBite = 2.5;      ///< force during the bite, x nominal
    double marteleStroke = 0.12;   ///< s of the fast stroke after the bite
};

/// What the bow player aims at now (nominal x controllers); speed is a magnitude.
struct BowAim {
    double force = 0.6, speed = 0.15, beta = 0.1;
};

struct GestureFrame {
    double force = 0.0;  ///< bow force (N); 0 = bow off the string
    double speed = 0.0;  ///< signed bow speed (m/s): + down bow, - up bow
    double pluck = 0.0;  ///< force (N) pushed into the string this sample (pizzicato, col legno)
};

class BowGesture {
public:
    void prepare(double sampleRate) noexcept
    {
        dt_ = 1.0 / sampleRate;
        // Per-sample smoothing factors, computed once: the audio loop calls no exp.
        settle10ms_ = 1.0 - std::exp(-dt_ / 0.01);
        boostDecay_ = std::exp(-dt_ / 0.08);
    }

    /// A note starts. direction +1 down / -1 up; bowPosition = where on the bow (m from the frog).
    void start(Articulation a, double velocity, const GestureSettings& s, int direction, double bowPosition) noexcept
    {
        articulation_ = a;
        settings_ = s;
        velocity_ = std::clamp(velocity, 0.0, 1.0);
        direction_ = direction >= 0 ? 1 : -1;
        position_ = std::clamp(bowPosition, 0.0, s.bowLength);
        t_ = 0.0;
        speedMag_ = 0.0;
        force_ = 0.0;
        lift_ = 1.0;
        released_ = false;
        changing_ = 0.0;
        boost_ = s.attackBoost * velocity_;
        strokeClock_ = 0.0;
    }

    void release() noexcept { released_ = true; }
    bool released() const noexcept { return released_; }
    /// The bow has left the string (after a release, or a plucked/struck note).
    bool off() const noexcept { return (released_ && lift_ <= 0.0) || plucked(); }
    bool plucked() const noexcept { return articulation_ == Articulation::Pizzicato || articulation_ == Articulation::ColLegno; }
    int direction() const noexcept { return direction_; }
    double bowPosition() const noexcept { return position_; }
    Articulation articulation() const noexcept { return articulation_; }

    /// [audio thread] One sample.
    GestureFrame next(const BowAim& aim) noexcept
    {
        GestureFrame f;
        const double dt = dt_;
        t_ += dt;
        if (released_) lift_ = std::max(0.0, lift_ - dt / std::max(0.005, settings_.releaseTime));
        switch (articulation_) {
        case Articulation::Pizzicato:
        case Articulation::ColLegno: {
            // A finger pulls the string aside (3 ms) and lets go; the stick strikes (1 ms). The
            // pulse's size follows velocity; the bow never holds the string.
            const double width = articulation_ == Articulation::Pizzicato ? 0.003 : 0.001;
            const double peak = (articulation_ == Articulation::Pizzicato ? 1.5 : 0.8) * (0.2 + velocity_);
            if (t_ <= width) f.pluck = peak * std::sin(std::numbers::pi * t_ / width);
            return f;
        }
        case Articulation::Martele: {
            const double bite = 0.03, stroke = settings_.marteleStroke;
            if (t_ < bite) { // pressed into the string, not yet moving
                force_ = aim.force * settings_.marteleBite;
                speedMag_ = 0.0;
            } else if (t_ < bite + stroke) { // released into a fast stroke
                force_ += (0.6 * aim.force - force_) * settle10ms_;
                speedMag_ = std::min(2.5 * aim.speed, speedMag_ + 20.0 * dt);
            } else { // the bow stops on the string
                speedMag_ = std::max(0.0, speedMag_ - 2.5 * aim.speed * dt / 0.03);
            }
            return bowOut(f, force_ * lift_);
        }
        case Articulation::Spiccato: {
            // The bow drops, bounces off and comes back each period; each bounce goes the other way.
            const double period = 1.0 / std::max(1.0, settings_.spiccatoRate);
            const double contact = std::clamp(settings_.spiccatoContact, 0.1, 0.9) * period;
            const double phase = std::fmod(t_, period);
            if (phase < dt && t_ > dt) direction_ = -direction_;
            speedMag_ = aim.speed;
            const double on = phase < contact ? std::sin(std::numbers::pi * phase / contact) : 0.0;
            return bowOut(f, 1.5 * aim.force * on * lift_);
        }
        case Articulation::Tremolo: {
            // Fast strokes: reverse every 1/rate s, the reversal itself a short smooth turn.
            const double stroke = 1.0 / std::max(1.0, settings_.tremoloRate);
            strokeClock_ += dt;
            if (strokeClock_ >= stroke) {
                strokeClock_ -= stroke;
                direction_ = -direction_;
                changing_ = std::min(settings_.bowChangeTime, 0.3 * stroke);
                changeLeft_ = changing_;
            }
            speedMag_ = aim.speed;
            return bowOut(f, aim.force * lift_);
        }
        case Articulation::Detache:
        case Articulation::Harmonic: // bowed like detache; the left hand makes the harmonic
        case Articulation::Count:    // not an articulation: a stray value plays as detache
        default: {
            if (speedMag_ < aim.speed) speedMag_ = std::min(aim.speed, speedMag_ + settings_.acceleration * std::max(0.05, velocity_) * dt);
            else speedMag_ += (aim.speed - speedMag_) * settle10ms_;
            boost_ *= boostDecay_;
            // Harmonics speak with a lighter bow (the touched string has less to hold).
            const double light = articulation_ == Articulation::Harmonic ? 0.5 : 1.0;
            force_ = aim.force * light * (1.0 + boost_);
            // The bow runs out: turn round before the tip or the frog.
            const double margin = speedMag_ * settings_.bowChangeTime * 0.5;
            if (changing_ <= 0.0 && ((direction_ > 0 && position_ >= settings_.bowLength - margin) ||
                                     (direction_ < 0 && position_ <= margin))) {
                direction_ = -direction_;
                changing_ = settings_.bowChangeTime;
                changeLeft_ = changing_;
            }
            return bowOut(f, force_ * lift_);
        }
        }
    }

private:
    GestureFrame& bowOut(GestureFrame& f, double force) noexcept
    {
        double v = direction_ * speedMag_;
        if (changeLeft_ > 0.0 && changing_ > 0.0) { // a bow change: through zero, smoothly
            changeLeft_ -= dt_;
            const double x = std::clamp(1.0 - changeLeft_ / changing_, 0.0, 1.0); // 0 -> 1
            v = direction_ * speedMag_ * -std::cos(std::numbers::pi * x);
            if (changeLeft_ <= 0.0) changing_ = 0.0;
        }
        position_ = std::clamp(position_ + v * dt_, 0.0, settings_.bowLength);
        f.force = force;
        f.speed = v;
        return f;
    }

    GestureSettings settings_;
    Articulation articulation_ = Articulation::Detache;
    double dt_ = 1.0 / 48000.0, settle10ms_ = 1.0 - std::exp(-1.0 / 480.0), boostDecay_ = std::exp(-1.0 / 3840.0), t_ = 0.0, velocity_ = 0.0, position_ = 0.0, speedMag_ = 0.0, force_ = 0.0;
    double lift_ = 1.0, boost_ = 0.0, changing_ = 0.0, changeLeft_ = 0.0, strokeClock_ = 0.0;
    int direction_ = 1;
    bool released_ = false;
};

} // namespace rosin::dsp
