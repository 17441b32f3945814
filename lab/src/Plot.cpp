#include "rosin/lab/Plot.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rosin/lab/Error.h"
#include "rosin/lab/Views.h" // niceTicks

namespace rosin::lab {

Canvas::Canvas(int width, int height)
    : width_(width), height_(height), surface_(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height)),
      cr_(cairo_create(surface_))
{
    cairo_set_source_rgb(cr_, 1, 1, 1);
    cairo_paint(cr_);
}

Canvas::~Canvas()
{
    cairo_destroy(cr_);
    cairo_surface_destroy(surface_);
}

void Canvas::text(double x, double y, const std::string& s, double size, Color c, double alignX, double alignY,
                  double angle, bool bold)
{
    cairo_save(cr_);
    cairo_select_font_face(cr_, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr_, size);
    cairo_text_extents_t ext;
    cairo_text_extents(cr_, s.c_str(), &ext);
    cairo_translate(cr_, x, y);
    cairo_rotate(cr_, angle);
    cairo_move_to(cr_, -alignX * ext.x_advance, alignY * ext.height);
    cairo_set_source_rgba(cr_, c.r, c.g, c.b, c.a);
    cairo_show_text(cr_, s.c_str());
    cairo_restore(cr_);
}

void Canvas::save(const std::filesystem::path& file) const
{
    cairo_surface_flush(surface_);
    if (cairo_surface_write_to_png(surface_, file.c_str()) != CAIRO_STATUS_SUCCESS)
        throw LabError(file.string() + ": cannot write PNG");
}

void CairoPainter::fillRect(const Rect& r, Color c)
{
    cairo_t* cr = canvas_.context();
    cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
    cairo_rectangle(cr, r.x, r.y, r.w, r.h);
    cairo_fill(cr);
}

void CairoPainter::strokeRect(const Rect& r, Color c, double width)
{
    cairo_t* cr = canvas_.context();
    cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
    cairo_set_line_width(cr, width);
    cairo_rectangle(cr, r.x, r.y, r.w, r.h);
    cairo_stroke(cr);
}

void CairoPainter::line(double x0, double y0, double x1, double y1, Color c, double width, bool dashed)
{
    cairo_t* cr = canvas_.context();
    cairo_save(cr);
    if (dashed) {
        const double dash[] = {5.0, 4.0};
        cairo_set_dash(cr, dash, 2, 0.0);
    }
    cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
    cairo_set_line_width(cr, width);
    cairo_move_to(cr, x0, y0);
    cairo_line_to(cr, x1, y1);
    cairo_stroke(cr);
    cairo_restore(cr);
}

void CairoPainter::polyline(const std::vector<double>& x, const std::vector<double>& y, Color c, double width)
{
    const std::size_t n = std::min(x.size(), y.size());
    if (n < 2) return;
    cairo_t* cr = canvas_.context();
    cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
    cairo_set_line_width(cr, width);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_move_to(cr, x[0], y[0]);
    for (std::size_t i = 1; i < n; ++i) cairo_line_to(cr, x[i], y[i]);
    cairo_stroke(cr);
}

void CairoPainter::fillCircle(double cx, double cy, double radius, Color c)
{
    cairo_t* cr = canvas_.context();
    cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
    cairo_new_sub_path(cr);
    cairo_arc(cr, cx, cy, radius, 0.0, 2.0 * 3.14159265358979);
    cairo_fill(cr);
}

void CairoPainter::text(const Rect& box, const std::string& s, double size, Color c, Align align, bool bold)
{
    const double alignX = align == Align::Left ? 0.0 : align == Align::Centre ? 0.5 : 1.0;
    const double x = align == Align::Left ? box.x : align == Align::Centre ? box.x + box.w / 2 : box.right();
    canvas_.text(x, box.y + box.h / 2, s, size, c, alignX, 0.35, 0.0, bold);
}

void CairoPainter::pushClip(const Rect& r)
{
    cairo_t* cr = canvas_.context();
    cairo_save(cr);
    cairo_rectangle(cr, r.x, r.y, r.w, r.h);
    cairo_clip(cr);
}

void CairoPainter::popClip() { cairo_restore(canvas_.context()); }

Axes::Axes(Canvas& canvas, double left, double top, double width, double height, double xMin, double xMax, double yMin,
           double yMax, bool logX)
    : canvas_(canvas), left_(left), top_(top), width_(width), height_(height), xMin_(xMin), xMax_(xMax), yMin_(yMin),
      yMax_(yMax), logX_(logX)
{
}

double Axes::px(double x) const
{
    if (logX_) return left_ + width_ * (std::log10(x) - std::log10(xMin_)) / (std::log10(xMax_) - std::log10(xMin_));
    return left_ + width_ * (x - xMin_) / (xMax_ - xMin_);
}

double Axes::py(double y) const { return top_ + height_ * (1.0 - (y - yMin_) / (yMax_ - yMin_)); }

namespace {
std::string label(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", std::abs(v) < 1e-12 ? 0.0 : v);
    return buf;
}
} // namespace

void Axes::frame(const std::string& title, const std::string& xLabel, const std::string& yLabel)
{
    cairo_t* cr = canvas_.context();
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1.0);
    cairo_rectangle(cr, left_, top_, width_, height_);
    cairo_stroke(cr);
    const double fs = 12.0;
    if (logX_) {
        for (double d = std::floor(std::log10(xMin_)); d <= std::ceil(std::log10(xMax_)); d += 1.0) {
            const double x = std::pow(10.0, d);
            if (x < xMin_ * 0.999 || x > xMax_ * 1.001) continue;
            cairo_move_to(cr, px(x), top_ + height_);
            cairo_line_to(cr, px(x), top_ + height_ + 5);
            cairo_stroke(cr);
            canvas_.text(px(x), top_ + height_ + 8 + fs, label(x), fs, colors::black, 0.5, 0.0);
        }
    } else {
        for (double x : niceTicks(xMin_, xMax_)) {
            cairo_move_to(cr, px(x), top_ + height_);
            cairo_line_to(cr, px(x), top_ + height_ + 5);
            cairo_stroke(cr);
            canvas_.text(px(x), top_ + height_ + 8 + fs, label(x), fs, colors::black, 0.5, 0.0);
        }
    }
    for (double y : niceTicks(yMin_, yMax_)) {
        cairo_move_to(cr, left_ - 5, py(y));
        cairo_line_to(cr, left_, py(y));
        cairo_stroke(cr);
        canvas_.text(left_ - 8, py(y), label(y), fs, colors::black, 1.0, 0.35);
    }
    canvas_.text(left_ + width_ / 2, top_ - 10, title, 14, colors::black, 0.5, 0.0, 0.0, true);
    canvas_.text(left_ + width_ / 2, top_ + height_ + 40, xLabel, 13, colors::black, 0.5, 0.0);
    canvas_.text(left_ - 52, top_ + height_ / 2, yLabel, 13, colors::black, 0.5, 0.0, -M_PI / 2);
}

void Axes::line(const std::vector<double>& x, const std::vector<double>& y, Color c, double width, bool dashed)
{
    cairo_t* cr = canvas_.context();
    cairo_save(cr);
    cairo_rectangle(cr, left_, top_, width_, height_);
    cairo_clip(cr);
    cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
    cairo_set_line_width(cr, width);
    if (dashed) {
        const double dash[] = {6.0, 4.0};
        cairo_set_dash(cr, dash, 2, 0);
    }
    bool started = false;
    for (std::size_t i = 0; i < x.size() && i < y.size(); ++i) {
        if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || (logX_ && x[i] <= 0)) { started = false; continue; }
        if (!started) cairo_move_to(cr, px(x[i]), py(y[i]));
        else cairo_line_to(cr, px(x[i]), py(y[i]));
        started = true;
    }
    cairo_stroke(cr);
    cairo_restore(cr);
}

void Axes::points(const std::vector<double>& x, const std::vector<double>& y, Color c, double radius)
{
    cairo_t* cr = canvas_.context();
    cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
    for (std::size_t i = 0; i < x.size() && i < y.size(); ++i) {
        cairo_arc(cr, px(x[i]), py(y[i]), radius, 0, 2 * M_PI);
        cairo_fill(cr);
    }
}

void Axes::rect(double x0, double y0, double x1, double y1, Color fill)
{
    cairo_t* cr = canvas_.context();
    cairo_set_source_rgba(cr, fill.r, fill.g, fill.b, fill.a);
    const double a = px(x0), b = px(x1), c = py(y0), d = py(y1);
    cairo_rectangle(cr, std::min(a, b), std::min(c, d), std::abs(b - a), std::abs(d - c));
    cairo_fill(cr);
}

void Axes::hline(double y, Color c, double width, bool dashed) { line({xMin_, xMax_}, {y, y}, c, width, dashed); }

void Axes::legend(const std::vector<std::pair<std::string, Color>>& entries, bool topRight)
{
    cairo_t* cr = canvas_.context();
    const double rowH = 17;
    double textW = 0;
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 11.5);
    for (const auto& e : entries) {
        cairo_text_extents_t ext;
        cairo_text_extents(cr, e.first.c_str(), &ext);
        textW = std::max(textW, ext.x_advance);
    }
    const double boxW = textW + 40;
    const double x = topRight ? left_ + width_ - boxW - 8 : left_ + 8, y = top_ + 8;
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_rectangle(cr, x, y, boxW, rowH * entries.size() + 6);
    cairo_fill(cr);
    for (std::size_t i = 0; i < entries.size(); ++i) {
        const Color c = entries[i].second;
        cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
        cairo_rectangle(cr, x + 6, y + 6 + rowH * i, 18, 10);
        cairo_fill(cr);
        canvas_.text(x + 30, y + 15 + rowH * i, entries[i].first, 11.5);
    }
}

void Axes::legendBelow(const std::vector<std::pair<std::string, Color>>& entries)
{
    cairo_t* cr = canvas_.context();
    double x = left_;
    const double y = top_ + height_ + 52;
    for (const auto& [text, c] : entries) {
        cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
        cairo_rectangle(cr, x, y, 18, 10);
        cairo_fill(cr);
        canvas_.text(x + 24, y + 9, text, 11.5);
        cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
        cairo_set_font_size(cr, 11.5);
        cairo_text_extents_t ext;
        cairo_text_extents(cr, text.c_str(), &ext);
        x += 24 + ext.x_advance + 18;
    }
}

} // namespace rosin::lab
