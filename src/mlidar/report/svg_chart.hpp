#pragma once
// Small self-contained SVG charts for report.html (no library, no network):
// line and dot series, shaded bands (e.g. +-2 sigma), horizontal reference
// lines, a grid at 1-2-5 ticks, labelled axes, a legend, optionally equal
// axis scales with a scale bar (top and side views of a trajectory) or a
// logarithmic y axis (eigenvalues). The SVG is written for inline use in
// HTML5 (no xmlns, nothing fetched).
#include <string>
#include <vector>

namespace mlidar::report {

struct Series {
  std::string label;
  std::string colour;  ///< any CSS colour
  std::vector<double> x, y;
  bool dots = false;  ///< markers instead of a line
};

/// A shaded interval [lo, hi] over x.
struct Band {
  std::string colour;
  std::vector<double> x, lo, hi;
};

struct ReferenceLine {
  double y = 0.0;
  std::string label;
  std::string colour = "#555";
};

/// A grid of coloured cells in data units (a map's top view): cell (c, r)
/// covers [x0 + c cell, x0 + (c + 1) cell) x [y0 + r cell, ...); an empty
/// colour leaves the cell blank. Runs of equal colour along a row are drawn as one rect.
struct Raster {
  double x0 = 0.0, y0 = 0.0, cell = 1.0;
  int columns = 0, rows = 0;
  std::vector<std::string> colours;  ///< rows x columns, row-major, row 0 at y0
};

struct Chart {
  std::string title;
  std::string x_label, y_label;  ///< with units, e.g. "x (m)"
  std::vector<Series> series;
  std::vector<Band> bands;
  std::vector<ReferenceLine> lines;
  Raster raster;            ///< drawn under the series; empty when columns or rows is 0
  bool equal_axes = false;  ///< one unit has the same length on both axes; adds a scale bar
  bool log_y = false;       ///< y on a log10 scale; values <= 0 are left out
  double width = 640, height = 360;
};

/// Where the plotting area lies and how data map into it (for tests and
/// callers that place their own marks).
struct ChartLayout {
  double left, top, width, height;                           ///< the plotting area, SVG units
  double x_lo, x_hi, y_lo, y_hi;                             ///< the data range shown (log10 of y with log_y)
  double x_scale() const { return width / (x_hi - x_lo); }   ///< SVG units per x unit
  double y_scale() const { return height / (y_hi - y_lo); }  ///< SVG units per y unit
};

/// At most this many vertices per series are drawn (evenly thinned, last kept).
inline constexpr std::size_t kMaxVertices = 2000;

ChartLayout layout_chart(const Chart& chart);
std::string render_svg(const Chart& chart);

/// Tick values at 1, 2 or 5 x 10^k covering [lo, hi], about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target);

/// `text` with & < > " escaped for HTML and SVG.
std::string escape_markup(const std::string& text);

/// A short number: 4 significant digits, no trailing zeros.
std::string short_number(double value);

}  // namespace mlidar::report
