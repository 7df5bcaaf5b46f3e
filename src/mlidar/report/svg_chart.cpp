#include "mlidar/report/svg_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace mlidar::report {
namespace {

constexpr double kMarginLeft = 70, kMarginRight = 20, kMarginTop = 44, kMarginBottom = 44;

std::string coordinate(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f", value);
  return buffer;
}

struct Interval {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
  /// Non-empty and wider than zero, padded by `share` of its span on each side.
  Interval padded(double share) const {
    if (empty()) return {0.0, 1.0};
    double span = hi - lo;
    if (span <= 0.0) span = std::max(std::abs(lo) * 0.2, 1e-6);
    const double centre = 0.5 * (lo + hi);
    const double half = 0.5 * span * (1.0 + 2.0 * share);
    return {centre - half, centre + half};
  }
};

double shown_y(const Chart& chart, double y) {
  if (!chart.log_y) return y;
  return y > 0.0 ? std::log10(y) : std::numeric_limits<double>::quiet_NaN();
}

/// Widens one axis so one unit has the same length on both.
void equalise(const ChartLayout& area, Interval& x, Interval& y) {
  const double scale = std::min(area.width / (x.hi - x.lo), area.height / (y.hi - y.lo));
  const double x_half = 0.5 * area.width / scale, y_half = 0.5 * area.height / scale;
  const double x_mid = 0.5 * (x.lo + x.hi), y_mid = 0.5 * (y.lo + y.hi);
  x = {x_mid - x_half, x_mid + x_half};
  y = {y_mid - y_half, y_mid + y_half};
}

struct Mapper {
  const ChartLayout& layout;
  const Chart& chart;
  double u(double x) const { return layout.left + (x - layout.x_lo) * layout.x_scale(); }
  double v(double y) const { return layout.top + layout.height - (shown_y(chart, y) - layout.y_lo) * layout.y_scale(); }
  double v_shown(double shown) const { return layout.top + layout.height - (shown - layout.y_lo) * layout.y_scale(); }
};

std::size_t stride_for(std::size_t count) { return std::max<std::size_t>(1, (count + kMaxVertices - 1) / kMaxVertices); }

/// The indices drawn of a series of `count` points: every stride-th and the last.
std::vector<std::size_t> drawn_indices(std::size_t count) {
  std::vector<std::size_t> out;
  const std::size_t stride = stride_for(count);
  for (std::size_t i = 0; i < count; i += stride) out.push_back(i);
  if (count > 0 && out.back() != count - 1) out.push_back(count - 1);
  return out;
}

void draw_series(const Series& s, const Mapper& map, std::ostringstream& out) {
  const std::size_t n = std::min(s.x.size(), s.y.size());
  if (s.dots) {
    out << "<g fill=\"" << escape_markup(s.colour) << "\">";
    for (const std::size_t i : drawn_indices(n)) {
      const double v = map.v(s.y[i]);
      if (!std::isfinite(s.x[i]) || !std::isfinite(v)) continue;
      out << "<circle cx=\"" << coordinate(map.u(s.x[i])) << "\" cy=\"" << coordinate(v) << "\" r=\"2.5\"/>";
    }
    out << "</g>\n";
    return;
  }
  // A NaN (or, on a log axis, a value <= 0) breaks the line.
  std::string points;
  const auto flush = [&] {
    if (!points.empty())
      out << "<polyline fill=\"none\" stroke=\"" << escape_markup(s.colour) << "\" stroke-width=\"1.5\" points=\"" << points << "\"/>\n";
    points.clear();
  };
  for (const std::size_t i : drawn_indices(n)) {
    const double v = map.v(s.y[i]);
    if (!std::isfinite(s.x[i]) || !std::isfinite(v)) {
      flush();
      continue;
    }
    points += coordinate(map.u(s.x[i])) + "," + coordinate(v) + " ";
  }
  flush();
}

void draw_raster(const Raster& r, const Mapper& map, std::ostringstream& out) {
  if (r.columns <= 0 || r.rows <= 0 || r.colours.size() != static_cast<std::size_t>(r.columns) * static_cast<std::size_t>(r.rows)) return;
  const double height = r.cell * map.layout.y_scale();
  out << "<g shape-rendering=\"crispEdges\">";
  for (int row = 0; row < r.rows; ++row) {
    const double top = map.v(r.y0 + (row + 1) * r.cell);
    for (int c = 0; c < r.columns;) {
      const std::string& colour = r.colours[static_cast<std::size_t>(row) * r.columns + c];
      int end = c + 1;
      while (end < r.columns && r.colours[static_cast<std::size_t>(row) * r.columns + end] == colour) ++end;
      if (!colour.empty())
        out << "<rect x=\"" << coordinate(map.u(r.x0 + c * r.cell)) << "\" y=\"" << coordinate(top) << "\" width=\""
            << coordinate((end - c) * r.cell * map.layout.x_scale() + 0.05) << "\" height=\"" << coordinate(height + 0.05) << "\" fill=\""
            << escape_markup(colour) << "\"/>";
      c = end;
    }
  }
  out << "</g>\n";
}

void draw_band(const Band& b, const Mapper& map, std::ostringstream& out) {
  const std::size_t n = std::min({b.x.size(), b.lo.size(), b.hi.size()});
  const std::vector<std::size_t> drawn = drawn_indices(n);
  std::string points;
  for (const std::size_t i : drawn) points += coordinate(map.u(b.x[i])) + "," + coordinate(map.v(b.hi[i])) + " ";
  for (auto it = drawn.rbegin(); it != drawn.rend(); ++it) points += coordinate(map.u(b.x[*it])) + "," + coordinate(map.v(b.lo[*it])) + " ";
  if (n > 0 && points.find("nan") == std::string::npos && points.find("inf") == std::string::npos)
    out << "<polygon fill=\"" << escape_markup(b.colour) << "\" fill-opacity=\"0.25\" stroke=\"none\" points=\"" << points << "\"/>\n";
}

/// Ticks of a log10 axis over [lo, hi] (exponents), as exponents: the decades when there are
/// at least three, else 1, 2, 5 x 10^k, else linear 1-2-5 ticks of the values.
std::vector<double> log_ticks(double lo, double hi) {
  std::vector<double> decades, steps;
  for (double k = std::floor(lo); k <= std::ceil(hi); k += 1.0) {
    for (const double m : {1.0, 2.0, 5.0}) {
      const double e = k + std::log10(m);
      if (e < lo || e > hi) continue;
      steps.push_back(e);
      if (m == 1.0) decades.push_back(e);
    }
  }
  if (decades.size() > 8) return nice_ticks(std::ceil(lo), std::floor(hi), 8);  // every 2nd or 5th decade
  if (decades.size() >= 3) return decades;
  if (steps.size() >= 3) return steps;
  std::vector<double> out;
  for (const double v : nice_ticks(std::pow(10.0, lo), std::pow(10.0, hi), 4))
    if (v > 0.0) out.push_back(std::log10(v));
  return out;
}

std::string tick_label(const Chart& chart, double shown) {
  if (!chart.log_y) return short_number(shown);
  return short_number(std::pow(10.0, shown));
}

void draw_grid(const Chart& chart, const ChartLayout& l, const Mapper& map, std::ostringstream& out) {
  out << "<g stroke=\"#e3e3e3\" stroke-width=\"1\">";
  const std::vector<double> xs = nice_ticks(l.x_lo, l.x_hi, 6);
  const std::vector<double> ys = chart.log_y ? log_ticks(l.y_lo, l.y_hi) : nice_ticks(l.y_lo, l.y_hi, 5);
  for (const double x : xs)
    out << "<line x1=\"" << coordinate(map.u(x)) << "\" y1=\"" << coordinate(l.top) << "\" x2=\"" << coordinate(map.u(x)) << "\" y2=\""
        << coordinate(l.top + l.height) << "\"/>";
  for (const double y : ys)
    out << "<line x1=\"" << coordinate(l.left) << "\" y1=\"" << coordinate(map.v_shown(y)) << "\" x2=\"" << coordinate(l.left + l.width)
        << "\" y2=\"" << coordinate(map.v_shown(y)) << "\"/>";
  out << "</g>\n<g fill=\"#333\">";
  for (const double x : xs)
    out << "<text x=\"" << coordinate(map.u(x)) << "\" y=\"" << coordinate(l.top + l.height + 15) << "\" text-anchor=\"middle\">"
        << short_number(x) << "</text>";
  for (const double y : ys)
    out << "<text x=\"" << coordinate(l.left - 5) << "\" y=\"" << coordinate(map.v_shown(y) + 4) << "\" text-anchor=\"end\">"
        << tick_label(chart, y) << "</text>";
  out << "</g>\n";
}

void draw_scale_bar(const ChartLayout& l, std::ostringstream& out) {
  const std::vector<double> ticks = nice_ticks(l.x_lo, l.x_hi, 5);
  const double length = ticks.size() >= 2 ? ticks[1] - ticks[0] : (l.x_hi - l.x_lo) / 5.0;
  const double x0 = l.left + 12, y0 = l.top + l.height - 12, x1 = x0 + length * l.x_scale();
  out << "<g stroke=\"#000\" stroke-width=\"2\"><line x1=\"" << coordinate(x0) << "\" y1=\"" << coordinate(y0) << "\" x2=\""
      << coordinate(x1) << "\" y2=\"" << coordinate(y0) << "\"/></g><text x=\"" << coordinate(0.5 * (x0 + x1)) << "\" y=\""
      << coordinate(y0 - 5) << "\" text-anchor=\"middle\">" << short_number(length) << " m</text>\n";
}

void draw_legend(const Chart& chart, std::ostringstream& out) {
  double x = kMarginLeft;
  const auto entry = [&](const std::string& label, const std::string& colour) {
    if (label.empty()) return;
    out << "<rect x=\"" << coordinate(x) << "\" y=\"28\" width=\"12\" height=\"8\" fill=\"" << escape_markup(colour) << "\"/><text x=\""
        << coordinate(x + 16) << "\" y=\"36\">" << escape_markup(label) << "</text>";
    x += 28 + 6.5 * static_cast<double>(label.size());
  };
  for (const Series& s : chart.series) entry(s.label, s.colour);
  for (const ReferenceLine& r : chart.lines) entry(r.label, r.colour);
  out << "\n";
}

}  // namespace

std::string escape_markup(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
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

std::string short_number(double value) {
  if (std::abs(value) < 1e-12) value = 0.0;  // no "-0" or "1e-17" at a tick on zero
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 1) return ticks;
  const double raw = (hi - lo) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double normalised = raw / magnitude;
  const double step = (normalised < 1.5 ? 1.0 : normalised < 3.5 ? 2.0 : normalised < 7.5 ? 5.0 : 10.0) * magnitude;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1.0) ticks.push_back(k * step);
  return ticks;
}

ChartLayout layout_chart(const Chart& chart) {
  ChartLayout layout{kMarginLeft, kMarginTop, chart.width - kMarginLeft - kMarginRight, chart.height - kMarginTop - kMarginBottom, 0, 1,
                     0,           1};
  Interval x, y;
  for (const Series& s : chart.series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(shown_y(chart, s.y[i]))) continue;
      x.add(s.x[i]);
      y.add(shown_y(chart, s.y[i]));
    }
  }
  for (const Band& b : chart.bands) {
    for (const double v : b.x) x.add(v);
    for (const double v : b.lo) y.add(shown_y(chart, v));
    for (const double v : b.hi) y.add(shown_y(chart, v));
  }
  for (const ReferenceLine& r : chart.lines) y.add(shown_y(chart, r.y));
  if (chart.raster.columns > 0 && chart.raster.rows > 0) {
    x.add(chart.raster.x0);
    x.add(chart.raster.x0 + chart.raster.columns * chart.raster.cell);
    y.add(chart.raster.y0);
    y.add(chart.raster.y0 + chart.raster.rows * chart.raster.cell);
  }
  x = x.padded(chart.equal_axes ? 0.05 : 0.0);
  y = y.padded(0.05);
  if (chart.equal_axes) equalise(layout, x, y);
  layout.x_lo = x.lo;
  layout.x_hi = x.hi;
  layout.y_lo = y.lo;
  layout.y_hi = y.hi;
  return layout;
}

std::string render_svg(const Chart& chart) {
  const ChartLayout layout = layout_chart(chart);
  const Mapper map{layout, chart};
  std::ostringstream out;
  out << "<svg class=\"chart\" viewBox=\"0 0 " << chart.width << ' ' << chart.height << "\" width=\"" << chart.width << "\" height=\""
      << chart.height << "\" font-family=\"sans-serif\" font-size=\"11\" role=\"img\">\n<title>" << escape_markup(chart.title)
      << "</title>\n<rect width=\"" << chart.width << "\" height=\"" << chart.height << "\" fill=\"#fff\"/>\n";
  out << "<text x=\"" << kMarginLeft << "\" y=\"16\" font-size=\"13\" font-weight=\"bold\">" << escape_markup(chart.title) << "</text>\n";
  draw_legend(chart, out);
  draw_grid(chart, layout, map, out);
  draw_raster(chart.raster, map, out);
  for (const Band& b : chart.bands) draw_band(b, map, out);
  for (const ReferenceLine& r : chart.lines) {
    const double v = map.v(r.y);
    if (!std::isfinite(v)) continue;
    out << "<line stroke=\"" << escape_markup(r.colour) << "\" stroke-dasharray=\"5,4\" x1=\"" << coordinate(layout.left) << "\" y1=\""
        << coordinate(v) << "\" x2=\"" << coordinate(layout.left + layout.width) << "\" y2=\"" << coordinate(v) << "\"/>\n";
  }
  for (const Series& s : chart.series) draw_series(s, map, out);
  out << "<rect x=\"" << coordinate(layout.left) << "\" y=\"" << coordinate(layout.top) << "\" width=\"" << coordinate(layout.width)
      << "\" height=\"" << coordinate(layout.height) << "\" fill=\"none\" stroke=\"#444\"/>\n";
  if (chart.equal_axes) draw_scale_bar(layout, out);
  out << "<text x=\"" << coordinate(layout.left + 0.5 * layout.width) << "\" y=\"" << coordinate(chart.height - 8)
      << "\" text-anchor=\"middle\">" << escape_markup(chart.x_label) << "</text>\n";
  out << "<text transform=\"translate(14," << coordinate(layout.top + 0.5 * layout.height) << ") rotate(-90)\" text-anchor=\"middle\">"
      << escape_markup(chart.y_label) << "</text>\n</svg>\n";
  return out.str();
}

}  // namespace mlidar::report
