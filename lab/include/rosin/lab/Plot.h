// A small plotting layer on cairo for the lab's PNG figures: axes with units and ticks, lines,
// points, filled cells, colour bars and legends. Every figure is written next to its data.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "rosin/lab/Painter.h"

typedef struct _cairo cairo_t;
typedef struct _cairo_surface cairo_surface_t;

namespace rosin::lab {

class Canvas {
public:
    Canvas(int width, int height);
    ~Canvas();
    Canvas(const Canvas&) = delete;
    Canvas& operator=(const Canvas&) = delete;
    cairo_t* context() const { return cr_; }
    int width() const { return width_; }
    int height() const { return height_; }
    void text(double x, double y, const std::string& s, double size, Color c = colors::black, double alignX = 0.0,
              double alignY = 0.0, double angle = 0.0, bool bold = false);
    /// Writes the PNG. Throws LabError naming the file.
    void save(const std::filesystem::path& file) const;

private:
    int width_, height_;
    cairo_surface_t* surface_;
    cairo_t* cr_;
};

class Axes {
public:
    /// Plot area in pixels (left, top, width, height) and data ranges.
    Axes(Canvas& canvas, double left, double top, double width, double height, double xMin, double xMax, double yMin,
         double yMax, bool logX = false);
    double px(double x) const;
    double py(double y) const;
    void frame(const std::string& title, const std::string& xLabel, const std::string& yLabel);
    void line(const std::vector<double>& x, const std::vector<double>& y, Color c, double width = 1.5, bool dashed = false);
    void points(const std::vector<double>& x, const std::vector<double>& y, Color c, double radius = 2.5);
    void rect(double x0, double y0, double x1, double y1, Color fill);
    void hline(double y, Color c, double width = 1.0, bool dashed = true);
    void legend(const std::vector<std::pair<std::string, Color>>& entries, bool topRight = true);
    /// One row of entries under the x-axis label, clear of the data.
    void legendBelow(const std::vector<std::pair<std::string, Color>>& entries);
    Canvas& canvas() { return canvas_; }
    double left() const { return left_; }
    double top() const { return top_; }
    double width() const { return width_; }
    double height() const { return height_; }

private:
    Canvas& canvas_;
    double left_, top_, width_, height_, xMin_, xMax_, yMin_, yMax_;
    bool logX_;
};

/// The shared Painter on a canvas: the editor's views drawn into PNG figures.
class CairoPainter : public Painter {
public:
    explicit CairoPainter(Canvas& canvas) : canvas_(canvas) {}
    void fillRect(const Rect& r, Color c) override;
    void strokeRect(const Rect& r, Color c, double width) override;
    void line(double x0, double y0, double x1, double y1, Color c, double width, bool dashed) override;
    void polyline(const std::vector<double>& x, const std::vector<double>& y, Color c, double width) override;
    void fillCircle(double cx, double cy, double radius, Color c) override;
    void text(const Rect& box, const std::string& s, double size, Color c, Align align, bool bold) override;
    void pushClip(const Rect& r) override;
    void popClip() override;

private:
    Canvas& canvas_;
};


} // namespace rosin::lab
