// lab::Painter on juce::Graphics: the views the lab draws into PNG figures, drawn in the window.
#pragma once
#include <juce_graphics/juce_graphics.h>

#include "rosin/lab/Painter.h"

namespace rosin::ui {

inline juce::Colour toColour(const lab::Color& c)
{
    return juce::Colour::fromFloatRGBA(static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b), static_cast<float>(c.a));
}

class JucePainter : public lab::Painter {
public:
    explicit JucePainter(juce::Graphics& g) : g_(g) {}

    void fillRect(const lab::Rect& r, lab::Color c) override
    {
        g_.setColour(toColour(c));
        g_.fillRect(toRect(r));
    }
    void strokeRect(const lab::Rect& r, lab::Color c, double width) override
    {
        g_.setColour(toColour(c));
        g_.drawRect(toRect(r), static_cast<float>(width));
    }
    void line(double x0, double y0, double x1, double y1, lab::Color c, double width, bool dashed) override
    {
        g_.setColour(toColour(c));
        const juce::Line<float> l(static_cast<float>(x0), static_cast<float>(y0), static_cast<float>(x1), static_cast<float>(y1));
        if (dashed) {
            const float dashes[] = {5.0f, 4.0f};
            g_.drawDashedLine(l, dashes, 2, static_cast<float>(width));
        } else {
            g_.drawLine(l, static_cast<float>(width));
        }
    }
    void polyline(const std::vector<double>& x, const std::vector<double>& y, lab::Color c, double width) override
    {
        const std::size_t n = std::min(x.size(), y.size());
        if (n < 2) return;
        juce::Path path;
        path.preallocateSpace(static_cast<int>(3 * n));
        path.startNewSubPath(static_cast<float>(x[0]), static_cast<float>(y[0]));
        for (std::size_t i = 1; i < n; ++i) path.lineTo(static_cast<float>(x[i]), static_cast<float>(y[i]));
        g_.setColour(toColour(c));
        g_.strokePath(path, juce::PathStrokeType(static_cast<float>(width), juce::PathStrokeType::curved));
    }
    void fillCircle(double cx, double cy, double radius, lab::Color c) override
    {
        g_.setColour(toColour(c));
        g_.fillEllipse(static_cast<float>(cx - radius), static_cast<float>(cy - radius), static_cast<float>(2 * radius),
                       static_cast<float>(2 * radius));
    }
    void text(const lab::Rect& box, const std::string& s, double size, lab::Color c, lab::Align align, bool bold) override
    {
        g_.setColour(toColour(c));
        g_.setFont(juce::Font(static_cast<float>(size), bold ? juce::Font::bold : juce::Font::plain));
        const auto just = align == lab::Align::Left     ? juce::Justification::centredLeft
                          : align == lab::Align::Centre ? juce::Justification::centred
                                                        : juce::Justification::centredRight;
        g_.drawText(juce::String::fromUTF8(s.c_str()), toRect(box), just, true);
    }
    void pushClip(const lab::Rect& r) override
    {
        g_.saveState();
        g_.reduceClipRegion(toRect(r).toNearestInt());
    }
    void popClip() override { g_.restoreState(); }

private:
    static juce::Rectangle<float> toRect(const lab::Rect& r)
    {
        return {static_cast<float>(r.x), static_cast<float>(r.y), static_cast<float>(r.w), static_cast<float>(r.h)};
    }
    juce::Graphics& g_;
};

} // namespace rosin::ui
