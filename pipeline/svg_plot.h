// Minimal SVG charts for the self-contained HTML report: line and scatter
// plots with axes and ticks, colour-mapped points, arrows and histograms.
// No network, no JavaScript: the SVG is inlined in report.html.
#ifndef ZEBRAGEO_PIPELINE_SVG_PLOT_H_
#define ZEBRAGEO_PIPELINE_SVG_PLOT_H_

#include <iosfwd>
#include <string>
#include <vector>

namespace zebrageo {

struct PlotSeries {
  std::string label;
  std::string colour = "#1f77b4";  // any CSS colour
  std::vector<double> x;
  std::vector<double> y;
  bool markers = false;  // points instead of a polyline
  double marker_radius_px = 2.5;
  // Per-point values mapped to a colour scale (markers only); empty: plain.
  std::vector<double> colour_values;
  // Per-point names (markers only): a tooltip, and the marker's data-id
  // attribute (the render test finds each crossing's marker by it).
  std::vector<std::string> point_ids;
};

struct PlotArrow {
  double x = 0, y = 0, dx = 0, dy = 0;  // in data units (after `scale`)
  std::string colour = "#d62728";
};

class SvgPlot {
 public:
  SvgPlot(std::string title, std::string x_label, std::string y_label,
          int width_px = 720, int height_px = 320);

  void AddSeries(PlotSeries series);
  void AddArrow(const PlotArrow& arrow);
  // Keep x and y on the same scale (maps).
  void SetEqualAspect(bool equal) { equal_aspect_ = equal; }
  // Colour scale legend for colour_values, e.g. "correction (m)".
  void SetColourScale(double min_value, double max_value, std::string label);
  // Text drawn under the title (units, notes).
  void SetNote(std::string note) { note_ = std::move(note); }
  // The SVG's data-plot attribute (tests and style sheets find it by it).
  void SetName(std::string name) { name_ = std::move(name); }

  std::string Render() const;

 private:
  // The plot area in pixels and the data ranges it shows.
  struct Area;
  // Right margin wide enough for the legend and the colour scale's label.
  int RightMargin() const;
  // The ranges of the data (kept to scale when equal_aspect_) in the plot
  // area left by margin_right.
  Area AreaFor(int margin_right) const;
  // The frame, grid lines, ticks and axis labels.
  void WriteAxes(const Area& area, std::ostream& svg) const;
  // The series and arrows, clipped to the plot area (a clip path of an id
  // unique to the plot).
  void WriteData(const Area& area, std::ostream& svg) const;
  // The series and arrows themselves.
  void WriteMarks(const Area& area, std::ostream& svg) const;
  // The named series and the colour scale, right of the plot area.
  void WriteLegend(int margin_right, std::ostream& svg) const;
  std::string title_, x_label_, y_label_, note_, name_;
  int width_px_, height_px_;
  std::vector<PlotSeries> series_;
  std::vector<PlotArrow> arrows_;
  bool equal_aspect_ = false;
  bool has_colour_scale_ = false;
  double colour_min_ = 0.0, colour_max_ = 1.0;
  std::string colour_label_;
};

// A histogram of `values` with `bins` bins as an SVG bar chart.
std::string RenderHistogram(const std::string& title,
                            const std::string& x_label,
                            const std::vector<double>& values, int bins,
                            const std::string& colour = "#1f77b4",
                            const std::string& y_label = "count");

// Viridis-like colour for t in [0, 1].
std::string ColourScale(double t);

// Escapes &, <, >, " for HTML/SVG text.
std::string EscapeHtml(const std::string& text);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_SVG_PLOT_H_
