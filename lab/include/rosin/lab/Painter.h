// The drawing surface the lab's figures and the plugin's editor share: a few primitives in
// pixels. lab/ implements it on cairo (PNG files), ui/ on juce::Graphics (the window), so a
// view is drawn by the same code in both places.
#pragma once
#include <string>
#include <vector>

namespace rosin::lab {

struct Color {
    double r = 0, g = 0, b = 0, a = 1;
    Color withAlpha(double alpha) const { return {r, g, b, alpha}; }
};

namespace colors {
inline constexpr Color black{0, 0, 0}, white{1, 1, 1}, grey{0.55, 0.55, 0.55}, red{0.85, 0.12, 0.1},
    blue{0.16, 0.33, 0.85}, cyan{0.15, 0.78, 0.9}, green{0.1, 0.6, 0.25}, orange{0.95, 0.55, 0.1}, purple{0.5, 0.2, 0.7},
    magenta{0.85, 0.1, 0.65};
}

struct Rect {
    double x = 0, y = 0, w = 0, h = 0;
    double right() const { return x + w; }
    double bottom() const { return y + h; }
    Rect reduced(double d) const { return {x + d, y + d, w - 2 * d, h - 2 * d}; }
};

enum class Align { Left, Centre, Right };

class Painter {
public:
    virtual ~Painter() = default;
    virtual void fillRect(const Rect& r, Color c) = 0;
    virtual void strokeRect(const Rect& r, Color c, double width) = 0;
    virtual void line(double x0, double y0, double x1, double y1, Color c, double width, bool dashed = false) = 0;
    /// Connected points in pixels (x and y of equal length).
    virtual void polyline(const std::vector<double>& x, const std::vector<double>& y, Color c, double width) = 0;
    virtual void fillCircle(double cx, double cy, double radius, Color c) = 0;
    /// One line of text, vertically centred in `box`, aligned horizontally; `size` in pixels.
    virtual void text(const Rect& box, const std::string& s, double size, Color c, Align align, bool bold = false) = 0;
    /// Later drawing stays inside r until popClip().
    virtual void pushClip(const Rect& r) = 0;
    virtual void popClip() = 0;
};

} // namespace rosin::lab
