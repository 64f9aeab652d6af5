#include "pipeline/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>

#include "survey/fnv_hash.h"

namespace zebrageo {
namespace {

constexpr int kMarginLeft = 70;
// Smallest right margin; it grows to fit the legend (RightMargin).
constexpr int kMarginRight = 90;
// Width of a character of the 11 px sans-serif text, generously: the
// legend must not be clipped by the SVG's right edge.
constexpr double kCharWidthPx = 6.6;
constexpr int kMarginTop = 44;
constexpr int kMarginBottom = 48;

std::string Number(double value, int decimals = 2) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  // A tick at -1e-17 is zero, not "-0".
  const std::string text = buffer;
  if (text.find_first_not_of("-0.") == std::string::npos && text[0] == '-') {
    return text.substr(1);
  }
  return text;
}

// "Nice" tick spacing (1, 2, 5 x 10^k) giving about `count` ticks.
double TickStep(double span, int count) {
  if (!(span > 0.0)) return 1.0;
  const double raw = span / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double factor : {1.0, 2.0, 5.0, 10.0}) {
    if (factor * power >= raw) return factor * power;
  }
  return 10.0 * power;
}

int DecimalsFor(double step) {
  return std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
}

struct Range {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (!std::isfinite(v)) return;
    min = std::min(min, v);
    max = std::max(max, v);
  }
  bool Valid() const { return min <= max; }
  void Pad() {
    if (!Valid()) {
      min = 0.0;
      max = 1.0;
    }
    if (max - min < 1e-9) {
      min -= 0.5;
      max += 0.5;
    }
    const double pad = 0.04 * (max - min);
    min -= pad;
    max += pad;
  }
};

}  // namespace

std::string ColourScale(double t) {
  // Piecewise-linear through five viridis anchors.
  static const double kAnchors[5][3] = {{68, 1, 84},
                                        {59, 82, 139},
                                        {33, 145, 140},
                                        {94, 201, 98},
                                        {253, 231, 37}};
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 4.0;
  const int i = std::min(3, static_cast<int>(t));
  const double f = t - i;
  char buffer[16];
  std::snprintf(
      buffer, sizeof(buffer), "#%02x%02x%02x",
      static_cast<int>(kAnchors[i][0] * (1 - f) + kAnchors[i + 1][0] * f),
      static_cast<int>(kAnchors[i][1] * (1 - f) + kAnchors[i + 1][1] * f),
      static_cast<int>(kAnchors[i][2] * (1 - f) + kAnchors[i + 1][2] * f));
  return buffer;
}

std::string EscapeHtml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

SvgPlot::SvgPlot(std::string title, std::string x_label, std::string y_label,
                 int width_px, int height_px)
    : title_(std::move(title)),
      x_label_(std::move(x_label)),
      y_label_(std::move(y_label)),
      width_px_(width_px),
      height_px_(height_px) {}

void SvgPlot::AddSeries(PlotSeries series) {
  series_.push_back(std::move(series));
}

void SvgPlot::AddArrow(const PlotArrow& arrow) { arrows_.push_back(arrow); }

void SvgPlot::SetColourScale(double min_value, double max_value,
                             std::string label) {
  has_colour_scale_ = true;
  colour_min_ = min_value;
  colour_max_ = max_value > min_value ? max_value : min_value + 1e-9;
  colour_label_ = std::move(label);
}

int SvgPlot::RightMargin() const {
  double legend_px = 0.0;
  for (const PlotSeries& s : series_) {
    if (!s.label.empty()) {
      legend_px = std::max(legend_px, 14.0 + kCharWidthPx * s.label.size());
    }
  }
  if (has_colour_scale_) {
    legend_px = std::max(legend_px, kCharWidthPx * colour_label_.size());
  }
  return std::max(kMarginRight, static_cast<int>(std::ceil(legend_px)) + 16);
}

// The plot area in pixels and the data ranges it shows: data (x, y) maps
// to pixels (X(x), Y(y)), y up.
struct SvgPlot::Area {
  Range xr, yr;
  double plot_w = 0.0;
  double plot_h = 0.0;

  double X(double v) const {
    return kMarginLeft + (v - xr.min) / (xr.max - xr.min) * plot_w;
  }
  double Y(double v) const {
    return kMarginTop + (yr.max - v) / (yr.max - yr.min) * plot_h;
  }
};

SvgPlot::Area SvgPlot::AreaFor(int margin_right) const {
  Area area;
  Range& xr = area.xr;
  Range& yr = area.yr;
  for (const PlotSeries& s : series_) {
    for (double v : s.x) xr.Add(v);
    for (double v : s.y) yr.Add(v);
  }
  for (const PlotArrow& a : arrows_) {
    xr.Add(a.x);
    xr.Add(a.x + a.dx);
    yr.Add(a.y);
    yr.Add(a.y + a.dy);
  }
  xr.Pad();
  yr.Pad();
  area.plot_w = width_px_ - kMarginLeft - margin_right;
  area.plot_h = height_px_ - kMarginTop - kMarginBottom;
  const double plot_w = area.plot_w;
  const double plot_h = area.plot_h;
  if (equal_aspect_) {
    // Grow the smaller span so one metre is as long on both axes.
    const double sx = (xr.max - xr.min) / plot_w;
    const double sy = (yr.max - yr.min) / plot_h;
    const double s = std::max(sx, sy);
    const double cx = 0.5 * (xr.min + xr.max), cy = 0.5 * (yr.min + yr.max);
    xr.min = cx - 0.5 * s * plot_w;
    xr.max = cx + 0.5 * s * plot_w;
    yr.min = cy - 0.5 * s * plot_h;
    yr.max = cy + 0.5 * s * plot_h;
  }
  return area;
}

void SvgPlot::WriteAxes(const Area& area, std::ostream& svg) const {
  const Range& xr = area.xr;
  const Range& yr = area.yr;
  const double plot_w = area.plot_w;
  const double plot_h = area.plot_h;
  svg << "<rect x='" << kMarginLeft << "' y='" << kMarginTop << "' width='"
      << plot_w << "' height='" << plot_h << "' fill='none' stroke='#333'/>\n";
  const double x_step = TickStep(xr.max - xr.min, 8);
  for (double v = std::ceil(xr.min / x_step) * x_step; v <= xr.max;
       v += x_step) {
    svg << "<line x1='" << area.X(v) << "' y1='" << kMarginTop << "' x2='"
        << area.X(v) << "' y2='" << kMarginTop + plot_h << "' stroke='#eee'/>"
        << "<text x='" << area.X(v) << "' y='" << kMarginTop + plot_h + 14
        << "' text-anchor='middle'>" << Number(v, DecimalsFor(x_step))
        << "</text>\n";
  }
  const double y_step = TickStep(yr.max - yr.min, 6);
  for (double v = std::ceil(yr.min / y_step) * y_step; v <= yr.max;
       v += y_step) {
    svg << "<line x1='" << kMarginLeft << "' y1='" << area.Y(v) << "' x2='"
        << kMarginLeft + plot_w << "' y2='" << area.Y(v) << "' stroke='#eee'/>"
        << "<text x='" << kMarginLeft - 4 << "' y='" << area.Y(v) + 4
        << "' text-anchor='end'>" << Number(v, DecimalsFor(y_step))
        << "</text>\n";
  }
  svg << "<text x='" << kMarginLeft + plot_w / 2 << "' y='" << height_px_ - 8
      << "' text-anchor='middle'>" << EscapeHtml(x_label_) << "</text>\n";
  svg << "<text transform='translate(14," << kMarginTop + plot_h / 2
      << ") rotate(-90)' text-anchor='middle'>" << EscapeHtml(y_label_)
      << "</text>\n";
}

void SvgPlot::WriteData(const Area& area, std::ostream& svg) const {
  // An id is global to the HTML page: one shared id made every plot clip
  // to the first plot's area (issue 47). The id is a hash of the data, so
  // the page stays the same from run to run; two plots with the same id
  // have the same data and the same clip rectangle.
  std::ostringstream data;
  WriteMarks(area, data);
  const std::string marks = data.str();
  const std::string id =
      "clip-" + Hex16(Fnv1a(title_ + "|" + std::to_string(area.plot_w) + "|" +
                            std::to_string(area.plot_h) + "|" + marks));
  svg << "<clipPath id='" << id << "'><rect x='" << kMarginLeft << "' y='"
      << kMarginTop << "' width='" << area.plot_w << "' height='" << area.plot_h
      << "'/></clipPath><g clip-path='url(#" << id << ")'>\n"
      << marks << "</g>\n";
}

void SvgPlot::WriteMarks(const Area& area, std::ostream& svg) const {
  for (const PlotSeries& s : series_) {
    const size_t n = std::min(s.x.size(), s.y.size());
    if (s.markers) {
      for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        std::string colour = s.colour;
        if (i < s.colour_values.size()) {
          colour = ColourScale((s.colour_values[i] - colour_min_) /
                               (colour_max_ - colour_min_));
        }
        svg << "<circle cx='" << Number(area.X(s.x[i]), 1) << "' cy='"
            << Number(area.Y(s.y[i]), 1) << "' r='" << s.marker_radius_px
            << "' fill='" << colour << "'";
        if (i < s.point_ids.size()) {
          svg << " data-id='" << EscapeHtml(s.point_ids[i]) << "'><title>"
              << EscapeHtml(s.point_ids[i]) << "</title></circle>";
        } else {
          svg << "/>";
        }
      }
      svg << "\n";
      continue;
    }
    svg << "<polyline fill='none' stroke='" << s.colour
        << "' stroke-width='1.5' points='";
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      svg << Number(area.X(s.x[i]), 1) << "," << Number(area.Y(s.y[i]), 1)
          << " ";
    }
    svg << "'/>\n";
  }
  for (const PlotArrow& a : arrows_) {
    const double x0 = area.X(a.x), y0 = area.Y(a.y), x1 = area.X(a.x + a.dx),
                 y1 = area.Y(a.y + a.dy);
    const double angle = std::atan2(y1 - y0, x1 - x0);
    svg << "<line x1='" << Number(x0, 1) << "' y1='" << Number(y0, 1)
        << "' x2='" << Number(x1, 1) << "' y2='" << Number(y1, 1)
        << "' stroke='" << a.colour << "' stroke-width='1.2'/>";
    for (double side : {-0.5, 0.5}) {
      svg << "<line x1='" << Number(x1, 1) << "' y1='" << Number(y1, 1)
          << "' x2='" << Number(x1 - 5 * std::cos(angle + side), 1) << "' y2='"
          << Number(y1 - 5 * std::sin(angle + side), 1) << "' stroke='"
          << a.colour << "' stroke-width='1.2'/>";
    }
    svg << "\n";
  }
}

void SvgPlot::WriteLegend(int margin_right, std::ostream& svg) const {
  int legend_y = kMarginTop + 6;
  for (const PlotSeries& s : series_) {
    if (s.label.empty()) continue;
    const int x = width_px_ - margin_right + 8;
    svg << "<rect x='" << x << "' y='" << legend_y << "' width='10' "
        << "height='10' fill='" << s.colour << "'/><text x='" << x + 14
        << "' y='" << legend_y + 9 << "'>" << EscapeHtml(s.label)
        << "</text>\n";
    legend_y += 16;
  }
  if (has_colour_scale_) {
    const int x = width_px_ - margin_right + 8;
    const int top = legend_y + 10, height = 100;
    for (int i = 0; i < 20; ++i) {
      svg << "<rect x='" << x << "' y='" << top + height - (i + 1) * 5
          << "' width='12' height='5' fill='" << ColourScale(i / 19.0) << "'/>";
    }
    const int decimals = DecimalsFor(TickStep(colour_max_ - colour_min_, 4));
    svg << "<text x='" << x + 16 << "' y='" << top + 8 << "'>"
        << Number(colour_max_, decimals) << "</text><text x='" << x + 16
        << "' y='" << top + height << "'>" << Number(colour_min_, decimals)
        << "</text><text x='" << x << "' y='" << top + height + 16 << "'>"
        << EscapeHtml(colour_label_) << "</text>\n";
  }
}

std::string SvgPlot::Render() const {
  const int margin_right = RightMargin();
  const Area area = AreaFor(margin_right);
  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width_px_
      << "' height='" << height_px_ << "' viewBox='0 0 " << width_px_ << " "
      << height_px_ << "' font-family='sans-serif' font-size='11'";
  if (!name_.empty()) svg << " data-plot='" << EscapeHtml(name_) << "'";
  svg << ">\n";
  svg << "<rect width='100%' height='100%' fill='white'/>\n";
  svg << "<text x='" << width_px_ / 2 << "' y='16' text-anchor='middle' "
      << "font-size='14' font-weight='bold'>" << EscapeHtml(title_)
      << "</text>\n";
  if (!note_.empty()) {
    svg << "<text x='" << width_px_ / 2 << "' y='32' text-anchor='middle' "
        << "fill='#555'>" << EscapeHtml(note_) << "</text>\n";
  }
  WriteAxes(area, svg);
  // Data, clipped to the plot area.
  WriteData(area, svg);
  WriteLegend(margin_right, svg);
  svg << "</svg>\n";
  return svg.str();
}

std::string RenderHistogram(const std::string& title,
                            const std::string& x_label,
                            const std::vector<double>& values, int bins,
                            const std::string& colour,
                            const std::string& y_label) {
  Range range;
  for (double v : values) range.Add(v);
  if (!range.Valid()) {
    range.min = 0.0;
    range.max = 1.0;
  }
  if (range.max - range.min < 1e-9) range.max = range.min + 1e-3;
  bins = std::max(1, bins);
  std::vector<int> counts(bins, 0);
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    const int bin = std::min(
        bins - 1,
        static_cast<int>((v - range.min) / (range.max - range.min) * bins));
    ++counts[bin];
  }
  const double width = (range.max - range.min) / bins;
  SvgPlot plot(title, x_label, y_label, 360, 260);
  plot.SetNote(std::to_string(values.size()) + " values");
  // Bars as closed polylines keep SvgPlot's single data model.
  for (int i = 0; i < bins; ++i) {
    if (counts[i] == 0) continue;
    const double x0 = range.min + i * width, x1 = x0 + width;
    PlotSeries bar;
    bar.colour = colour;
    bar.x = {x0, x0, x1, x1, x0};
    bar.y = {0.0, static_cast<double>(counts[i]),
             static_cast<double>(counts[i]), 0.0, 0.0};
    plot.AddSeries(std::move(bar));
  }
  PlotSeries axis;  // keeps y from 0
  axis.colour = "#333";
  axis.x = {range.min, range.max};
  axis.y = {0.0, 0.0};
  plot.AddSeries(std::move(axis));
  return plot.Render();
}

}  // namespace zebrageo
