#include "rosin/lab/Views.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rosin::lab {

std::vector<double> niceTicks(double lo, double hi, int target)
{
    std::vector<double> ticks;
    const double span = hi - lo;
    if (!(span > 0)) return {lo};
    const double raw = span / target, mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag;
    for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (m * mag >= raw) { step = m * mag; break; }
    for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + 1e-9 * span; t += step)
        ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
    return ticks;
}

Color transientColor(int periods)
{
    // Light = short, dark = long (PHYSICS.md 6.6): cream -> amber -> olive -> dark teal.
    static const Color stops[] = {{1.0, 0.98, 0.82}, {0.99, 0.76, 0.3}, {0.62, 0.72, 0.3}, {0.12, 0.36, 0.32}};
    const double x = std::clamp(periods / 25.0, 0.0, 1.0) * 3.0;
    const int i = std::min(2, static_cast<int>(x));
    const double s = x - i;
    const Color a = stops[i], b = stops[i + 1];
    return {a.r + s * (b.r - a.r), a.g + s * (b.g - a.g), a.b + s * (b.b - a.b)};
}

Color regimeColor(Regime r)
{
    switch (r) {
    case Regime::DoubleSlip: return colors::blue;
    case Regime::DoubleFlyback: return colors::cyan;
    case Regime::Irregular: return colors::red;
    case Regime::NoSlip: return colors::black;
    default: return colors::white;
    }
}

// ---------------------------------------------------------------------------------------------
LiveHistory::LiveHistory(double sampleRate, double seconds) : fs_(sampleRate)
{
    ring_.resize(static_cast<std::size_t>(std::max(1.0, sampleRate * seconds)));
}

void LiveHistory::push(const LiveSample& s) noexcept
{
    ring_[head_] = s;
    head_ = (head_ + 1) % ring_.size();
    count_ = std::min(count_ + 1, ring_.size());
    ++total_;
    if (s.noteStart) {
        lastNoteStart_ = total_ - 1;
        sawNoteStart_ = true;
    }
}

void LiveHistory::clear() noexcept
{
    head_ = count_ = 0;
    total_ = lastNoteStart_ = 0;
    sawNoteStart_ = false;
}

const LiveSample& LiveHistory::back(std::size_t age) const noexcept
{
    const std::size_t n = ring_.size();
    return ring_[(head_ + n - 1 - std::min(age, n - 1)) % n];
}

LiveHistory::Scope LiveHistory::scope(double periods) const
{
    Scope s;
    if (count_ < 2) return s;
    const double f0 = std::max(20.0, static_cast<double>(back().frequency));
    s.period = 1.0 / f0;
    const auto window = std::min(count_ - 1, static_cast<std::size_t>(periods * fs_ / f0));
    // The newest slip onset with a whole window after it: each frame starts at the same phase.
    std::size_t start = window; // age of the first sample shown
    for (std::size_t age = window; age + 1 < count_ && age < window + static_cast<std::size_t>(2.0 * fs_ / f0); ++age)
        if (!back(age).stick && back(age + 1).stick) {
            start = age;
            s.triggered = true;
            break;
        }
    for (std::size_t k = 0; k <= window && start >= k; ++k) {
        const LiveSample& x = back(start - k);
        s.time.push_back(static_cast<double>(k) / fs_);
        s.force.push_back(x.bridgeForce);
        s.stick.push_back(x.stick ? 1 : 0);
    }
    return s;
}

LiveHistory::Trace LiveHistory::temperature(double seconds, int columns) const
{
    Trace t;
    const auto span = std::min(count_, static_cast<std::size_t>(seconds * fs_));
    if (span < 2 || columns < 2) return t;
    const double per = static_cast<double>(span) / columns;
    for (int c = 0; c < columns; ++c) {
        const auto a = static_cast<std::size_t>(c * per), b = std::max(a + 1, static_cast<std::size_t>((c + 1) * per));
        double lo = 1e300, hi = -1e300;
        for (std::size_t k = a; k < b && k < span; ++k) {
            const double v = ambientCelsius + back(span - 1 - k).temperature;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        if (lo > hi) continue;
        t.time.push_back(-static_cast<double>(span - a) / fs_);
        t.low.push_back(lo);
        t.high.push_back(hi);
    }
    return t;
}

LiveHistory::Loop LiveHistory::loop(double periods) const
{
    Loop l;
    if (count_ < 2) return l;
    const double f0 = std::max(20.0, static_cast<double>(back().frequency));
    const auto n = std::min(count_, static_cast<std::size_t>(periods * fs_ / f0));
    for (std::size_t k = n; k-- > 0;) {
        const LiveSample& x = back(k);
        if (!x.bowed || x.force <= 1e-6f) continue;
        l.slide.push_back(static_cast<double>(x.velocity) - x.bowSpeed);
        l.mu.push_back(static_cast<double>(x.friction) / x.force);
    }
    return l;
}

LiveHistory::Gesture LiveHistory::gesture() const
{
    Gesture g;
    if (count_ == 0) return g;
    const LiveSample& now = back();
    g.valid = true;
    g.force = now.force;
    g.speed = now.bowSpeed;
    g.beta = now.beta;
    g.frequency = now.frequency;
    g.string = now.string;
    // The attack's acceleration: the steepest rise of bow speed over 2 ms in the note's first 0.3 s.
    if (sawNoteStart_ && total_ - lastNoteStart_ <= count_) {
        const std::size_t startAge = static_cast<std::size_t>(total_ - 1 - lastNoteStart_);
        const auto step = std::max<std::size_t>(1, static_cast<std::size_t>(0.002 * fs_));
        const auto span = std::min(startAge, static_cast<std::size_t>(0.3 * fs_));
        double best = 0.0;
        for (std::size_t k = 0; k + step <= span; k += step / 2 + 1) {
            const double dv = std::abs(static_cast<double>(back(startAge - k - step).bowSpeed)) -
                              std::abs(static_cast<double>(back(startAge - k).bowSpeed));
            best = std::max(best, dv * fs_ / static_cast<double>(step));
        }
        g.acceleration = best;
    }
    return g;
}

// ---------------------------------------------------------------------------------------------
ViewTheme ViewTheme::dark(double fontSize)
{
    ViewTheme t;
    t.background = {0.09, 0.09, 0.10};
    t.panel = {0.13, 0.13, 0.15};
    t.grid = {1, 1, 1, 0.09};
    t.text = {0.92, 0.90, 0.86};
    t.dim = {0.62, 0.60, 0.57};
    t.trace = {0.98, 0.80, 0.42};
    t.stickShade = {0.30, 0.55, 0.95, 0.16};
    t.slipShade = {0.95, 0.35, 0.25, 0.30};
    t.temperature = {1.0, 0.45, 0.25};
    t.loop = {0.45, 0.85, 0.95};
    t.point = {1.0, 1.0, 1.0};
    t.reference = {0.85, 0.35, 0.85};
    t.fontSize = fontSize;
    return t;
}

ViewTheme ViewTheme::light(double fontSize)
{
    ViewTheme t;
    t.background = colors::white;
    t.panel = {0.985, 0.98, 0.97};
    t.grid = {0, 0, 0, 0.10};
    t.text = colors::black;
    t.dim = {0.35, 0.35, 0.35};
    t.trace = {0.10, 0.10, 0.12};
    t.stickShade = {0.16, 0.33, 0.85, 0.12};
    t.slipShade = {0.85, 0.12, 0.10, 0.22};
    t.temperature = colors::red;
    t.loop = colors::blue;
    t.point = colors::black;
    t.reference = colors::magenta;
    t.fontSize = fontSize;
    return t;
}

namespace {

std::string number(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", std::abs(v) < 1e-12 ? 0.0 : v);
    return buf;
}

std::vector<double> logTicks(double lo, double hi)
{
    std::vector<double> t;
    for (double d = std::floor(std::log10(lo)); d <= std::ceil(std::log10(hi)); d += 1.0)
        for (double m : {1.0, 2.0, 5.0}) {
            const double x = m * std::pow(10.0, d);
            if (x >= lo * 0.999 && x <= hi * 1.001) t.push_back(x);
        }
    return t;
}

/// A panel with a title, grid, ticks and an x label; maps data to pixels inside it.
struct Frame {
    Rect plot;
    double x0, x1, y0, y1;
    bool logX, logY;
    double px(double x) const
    {
        const double u = logX ? (std::log(x) - std::log(x0)) / (std::log(x1) - std::log(x0)) : (x - x0) / (x1 - x0);
        return plot.x + plot.w * u;
    }
    double py(double y) const
    {
        const double u = logY ? (std::log(y) - std::log(y0)) / (std::log(y1) - std::log(y0)) : (y - y0) / (y1 - y0);
        return plot.y + plot.h * (1.0 - u);
    }
};

Frame panel(Painter& p, const Rect& r, const ViewTheme& t, const std::string& title, const std::string& xLabel, double x0,
            double x1, double y0, double y1, bool logX = false, bool logY = false)
{
    const double fs = t.fontSize, small = 0.85 * fs;
    p.fillRect(r, t.panel);
    p.text({r.x + 0.6 * fs, r.y + 0.2 * fs, r.w - 1.2 * fs, 1.5 * fs}, title, fs, t.text, Align::Left, true);
    Frame f{{r.x + 3.8 * fs, r.y + 1.9 * fs, r.w - 4.6 * fs, r.h - 1.9 * fs - 2.9 * fs}, x0, x1, y0, y1, logX, logY};
    if (f.plot.w < 8 || f.plot.h < 8) return f;
    const auto xt = logX ? logTicks(x0, x1) : niceTicks(x0, x1, std::max(2, static_cast<int>(f.plot.w / (6 * fs))));
    const auto yt = logY ? logTicks(y0, y1) : niceTicks(y0, y1, std::max(2, static_cast<int>(f.plot.h / (2.5 * fs))));
    for (double x : xt) {
        p.line(f.px(x), f.plot.y, f.px(x), f.plot.bottom(), t.grid, 1.0);
        p.text({f.px(x) - 3 * fs, f.plot.bottom() + 0.15 * fs, 6 * fs, 1.2 * fs}, number(x), small, t.dim, Align::Centre);
    }
    for (double y : yt) {
        p.line(f.plot.x, f.py(y), f.plot.right(), f.py(y), t.grid, 1.0);
        p.text({r.x, f.py(y) - 0.6 * fs, 3.5 * fs, 1.2 * fs}, number(y), small, t.dim, Align::Right);
    }
    p.strokeRect(f.plot, t.grid.withAlpha(0.35), 1.0);
    p.text({f.plot.x, f.plot.bottom() + 1.35 * fs, f.plot.w, 1.3 * fs}, xLabel, small, t.dim, Align::Centre);
    return f;
}

void emptyNote(Painter& p, const Frame& f, const ViewTheme& t, const std::string& s)
{
    p.text(f.plot, s, t.fontSize, t.dim, Align::Centre);
}

} // namespace

void drawScope(Painter& p, const Rect& r, const ViewTheme& t, const LiveHistory& h)
{
    const LiveHistory::Scope s = h.scope(3.0);
    double peak = 1e-3;
    for (double v : s.force) peak = std::max(peak, std::abs(v));
    const double tEnd = s.time.empty() ? 0.01 : std::max(1e-4, s.time.back());
    const Frame f = panel(p, r, t, "Bridge force (N)   stick / slip", "time (ms)", 0.0, 1e3 * tEnd, -1.15 * peak, 1.15 * peak);
    if (s.time.size() < 2) return emptyNote(p, f, t, "play a note");
    p.pushClip(f.plot);
    // Shade each run of sticking and of slipping across the whole height.
    std::size_t runStart = 0;
    for (std::size_t i = 1; i <= s.time.size(); ++i)
        if (i == s.time.size() || s.stick[i] != s.stick[runStart]) {
            const double xa = f.px(1e3 * s.time[runStart]), xb = f.px(1e3 * s.time[std::min(i, s.time.size() - 1)]);
            p.fillRect({xa, f.plot.y, std::max(1.0, xb - xa), f.plot.h}, s.stick[runStart] ? t.stickShade : t.slipShade);
            runStart = i;
        }
    // At most about two points per pixel column: the trace keeps its peaks (min/max pairs).
    std::vector<double> xs, ys;
    const double perPixel = static_cast<double>(s.time.size()) / std::max(1.0, f.plot.w);
    if (perPixel <= 2.0) {
        for (std::size_t i = 0; i < s.time.size(); ++i) {
            xs.push_back(f.px(1e3 * s.time[i]));
            ys.push_back(f.py(s.force[i]));
        }
    } else {
        for (double c = 0; c < f.plot.w; c += 1.0) {
            const auto a = static_cast<std::size_t>(c * perPixel), b = std::min(s.time.size(), static_cast<std::size_t>((c + 1) * perPixel) + 1);
            double lo = 1e300, hi = -1e300;
            for (std::size_t i = a; i < b; ++i) { lo = std::min(lo, s.force[i]); hi = std::max(hi, s.force[i]); }
            if (lo > hi) continue;
            xs.push_back(f.plot.x + c); ys.push_back(f.py(hi));
            xs.push_back(f.plot.x + c); ys.push_back(f.py(lo));
        }
    }
    p.line(f.plot.x, f.py(0.0), f.plot.right(), f.py(0.0), t.grid.withAlpha(0.3), 1.0);
    p.polyline(xs, ys, t.trace, std::max(1.0, t.fontSize / 8.0));
    p.popClip();
}

void drawTemperature(Painter& p, const Rect& r, const ViewTheme& t, const LiveHistory& h, double seconds)
{
    const LiveHistory::Trace tr = h.temperature(seconds, std::max(16, static_cast<int>(r.w / 2)));
    double lo = h.ambientCelsius, hi = h.ambientCelsius + 2.0;
    for (std::size_t i = 0; i < tr.time.size(); ++i) { lo = std::min(lo, tr.low[i]); hi = std::max(hi, tr.high[i]); }
    const double pad = 0.08 * (hi - lo);
    const Frame f = panel(p, r, t, "Contact temperature (\u00B0C)", "time (s)", -seconds, 0.0, lo - pad, hi + pad);
    if (tr.time.size() < 2) return emptyNote(p, f, t, "no contact yet");
    p.pushClip(f.plot);
    p.line(f.plot.x, f.py(h.ambientCelsius), f.plot.right(), f.py(h.ambientCelsius), t.dim, 1.0, true);
    std::vector<double> xs, ys;
    for (std::size_t i = 0; i < tr.time.size(); ++i) {
        const double x = f.px(tr.time[i]);
        p.line(x, f.py(tr.low[i]), x, f.py(tr.high[i]) - 0.5, t.temperature.withAlpha(0.45), 2.0);
        xs.push_back(x);
        ys.push_back(f.py(0.5 * (tr.low[i] + tr.high[i])));
    }
    p.polyline(xs, ys, t.temperature, std::max(1.0, t.fontSize / 8.0));
    p.popClip();
}

void drawLoop(Painter& p, const Rect& r, const ViewTheme& t, const LiveHistory& h)
{
    const LiveHistory::Loop l = h.loop(2.0);
    double x0 = -0.05, x1 = 0.05, y0 = 0.0, y1 = 0.5;
    for (std::size_t i = 0; i < l.slide.size(); ++i) {
        x0 = std::min(x0, l.slide[i]); x1 = std::max(x1, l.slide[i]);
        y0 = std::min(y0, l.mu[i]); y1 = std::max(y1, l.mu[i]);
    }
    const double px = 0.06 * (x1 - x0), py = 0.08 * (y1 - y0);
    const Frame f = panel(p, r, t, "Friction loop: f / F against v \u2212 v_b", "sliding speed (m/s)", x0 - px, x1 + px, y0 - py, y1 + py);
    if (l.slide.size() < 2) return emptyNote(p, f, t, "bow a note");
    p.pushClip(f.plot);
    // Older samples fainter, so the direction round the loop shows.
    const std::size_t n = l.slide.size(), parts = 4;
    for (std::size_t k = 0; k < parts; ++k) {
        std::vector<double> xs, ys;
        for (std::size_t i = k * n / parts; i < std::min(n, (k + 1) * n / parts + 1); ++i) {
            xs.push_back(f.px(l.slide[i]));
            ys.push_back(f.py(l.mu[i]));
        }
        p.polyline(xs, ys, t.loop.withAlpha(0.3 + 0.7 * static_cast<double>(k + 1) / parts), std::max(1.0, t.fontSize / 8.0));
    }
    p.fillCircle(f.px(l.slide.back()), f.py(l.mu.back()), 0.3 * t.fontSize, t.point);
    p.popClip();
}

void drawPlayability(Painter& p, const Rect& r, const ViewTheme& t, const PlayabilityMap* map, const LiveHistory::Gesture& g,
                     const std::string& status, double muS, double muD)
{
    if (map == nullptr || map->spec.columns.empty() || map->spec.forces.empty()) {
        const Frame f = panel(p, r, t, "Playability", "", 0.0, 1.0, 0.0, 1.0);
        return emptyNote(p, f, t, status.empty() ? "computing..." : status);
    }
    const PlayabilitySpec& s = map->spec;
    const bool schelleng = s.kind == MapKind::Schelleng;
    const auto& X = s.columns;
    const auto& F = s.forces;
    // Cell edges halfway between grid points (geometric on log axes).
    auto edges = [](const std::vector<double>& v, bool log) {
        std::vector<double> e(v.size() + 1);
        for (std::size_t i = 1; i < v.size(); ++i) e[i] = log ? std::sqrt(v[i - 1] * v[i]) : 0.5 * (v[i - 1] + v[i]);
        if (v.size() == 1) { e[0] = log ? v[0] / 1.5 : 0.5 * v[0]; e[1] = log ? v[0] * 1.5 : 1.5 * v[0]; }
        else {
            e[0] = log ? v[0] * v[0] / e[1] : std::max(0.0, 2 * v[0] - e[1]);
            e.back() = log ? v.back() * v.back() / e[v.size() - 1] : 2 * v.back() - e[v.size() - 1];
        }
        return e;
    };
    const auto ex = edges(X, schelleng), ef = edges(F, true);
    char title[200], progress[48] = "";
    if (map->completed() < map->cells.size()) std::snprintf(progress, sizeof progress, "  (computing %zu/%zu)", map->completed(), map->cells.size());
    if (schelleng)
        std::snprintf(title, sizeof title, "Schelleng: force (N) vs \u03B2, %.0f Hz, v_b %.2f m/s%s", map->f0, s.speed, progress);
    else
        std::snprintf(title, sizeof title, "Guettler: force (N) vs attack, %.0f Hz, \u03B2 %.3f%s", map->f0, s.beta, progress);
    const Frame f = panel(p, r, t, title, schelleng ? "bow position \u03B2" : "bow acceleration (m/s\u00B2)", ex.front(),
                          ex.back(), ef.front(), ef.back(), schelleng, true);
    p.pushClip(f.plot);
    for (std::size_t row = 0; row < F.size(); ++row)
        for (std::size_t col = 0; col < X.size(); ++col) {
            if (!map->done[row * X.size() + col]) continue;
            const PlayabilityCell& c = map->at(col, row);
            Color fill = c.success ? (schelleng ? Color{0.55, 0.80, 0.45} : transientColor(c.transientPeriods)) : regimeColor(c.regime);
            if (!c.success && c.regime == Regime::NoSlip) fill = t.dim.withAlpha(0.5);
            const double xa = f.px(ex[col]), xb = f.px(ex[col + 1]), ya = f.py(ef[row + 1]), yb = f.py(ef[row]);
            p.fillRect({xa, ya, xb - xa + 0.5, yb - ya + 0.5}, fill.withAlpha(0.85));
        }
    // Theory as reference lines: Schelleng's maximum force, Guettler's bounds.
    std::vector<double> xs, ys, xs2, ys2;
    dsp::StringParams stoppedString = s.config.string;
    if (s.frequency > 0) stoppedString.length *= stoppedString.fundamental() / s.frequency;
    const GuettlerBounds bounds = guettlerBounds(stoppedString, s.beta, muS, muD);
    for (int i = 0; i <= 40; ++i) {
        const double u = i / 40.0;
        const double x = schelleng ? ex.front() * std::pow(ex.back() / ex.front(), u) : ex.front() + u * (ex.back() - ex.front());
        if (schelleng) {
            xs.push_back(f.px(x));
            ys.push_back(f.py(std::clamp(schellengMaxForce(map->z0, s.speed, x, muS, muD), ef.front() * 0.5, ef.back() * 2)));
        } else if (x > 0) {
            xs.push_back(f.px(x));
            ys.push_back(f.py(std::clamp(bounds.lowerPerAccel * x, ef.front() * 0.5, ef.back() * 2)));
            xs2.push_back(f.px(x));
            ys2.push_back(f.py(std::clamp(bounds.upperPerAccel * x, ef.front() * 0.5, ef.back() * 2)));
        }
    }
    p.polyline(xs, ys, t.reference, 1.5);
    p.polyline(xs2, ys2, t.reference.withAlpha(0.6), 1.5);
    p.popClip();
    // Legend at the right of the title row, when the panel is wide enough for it.
    const double fs = t.fontSize, small = 0.8 * fs;
    const std::vector<std::pair<std::string, Color>> items{
        {"Helmholtz", schelleng ? Color{0.55, 0.80, 0.45} : transientColor(8)}, {"multi-slip", regimeColor(Regime::DoubleSlip)},
        {"raucous", regimeColor(Regime::Irregular)}, {"stuck", t.dim.withAlpha(0.5)}, {schelleng ? "F max" : "bounds", t.reference}};
    double width = 0;
    for (const auto& it : items) width += (it.first.size() * 0.6 + 2.2) * small;
    if (r.w > width + 0.6 * fs * std::char_traits<char>::length(title) + 2 * fs) {
        double x = r.right() - width - 0.6 * fs;
        const double y = r.y + 0.2 * fs;
        for (const auto& it : items) {
            p.fillRect({x, y + 0.45 * fs, 0.8 * small, 0.8 * small}, it.second);
            p.text({x + 1.1 * small, y, it.first.size() * 0.6 * small + small, 1.5 * fs}, it.first, small, t.dim, Align::Left);
            x += (it.first.size() * 0.6 + 2.2) * small;
        }
    }
    p.pushClip(f.plot);
    if (g.valid && g.force > 0) {
        const double gx = schelleng ? std::clamp(g.beta, ex.front(), ex.back()) : std::clamp(g.acceleration, ex.front(), ex.back());
        const double gy = std::clamp(g.force, ef.front(), ef.back());
        p.fillCircle(f.px(gx), f.py(gy), 0.55 * t.fontSize, t.background);
        p.fillCircle(f.px(gx), f.py(gy), 0.38 * t.fontSize, t.point);
    }
    p.popClip();
}

} // namespace rosin::lab
