#include "mlidar/eval/svg_plot.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace mlidar::eval {
namespace {

constexpr std::size_t kMaxVertices = 4000;

struct Box {  // a rectangle in SVG user units
  double left, top, width, height;
};

struct Range {  // data interval mapped onto a box side
  double lo, hi;
  double span() const { return std::max(hi - lo, 1e-9); }
};

Range range_of(const std::vector<double>& values) {
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  return {*lo, *hi};
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

/// <polyline> through (xs[i], ys[i]) mapped into `box`, y up.
std::string polyline(const std::vector<double>& xs, const std::vector<double>& ys, Range x_range, Range y_range, const Box& box,
                     const char* colour) {
  const std::size_t stride = std::max<std::size_t>(1, (xs.size() + kMaxVertices - 1) / kMaxVertices);
  std::ostringstream out;
  out << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.5\" points=\"";
  for (std::size_t i = 0; i < xs.size(); i += stride) {
    const double u = box.left + (xs[i] - x_range.lo) / x_range.span() * box.width;
    const double v = box.top + box.height - (ys[i] - y_range.lo) / y_range.span() * box.height;
    out << number(u) << ',' << number(v) << ' ';
  }
  out << "\"/>\n";
  return out.str();
}

std::string frame(const Box& box, const std::string& title, Range x_range, Range y_range, const std::string& x_label,
                  const std::string& y_label) {
  std::ostringstream out;
  out << "<rect x=\"" << box.left << "\" y=\"" << box.top << "\" width=\"" << box.width << "\" height=\"" << box.height
      << "\" fill=\"none\" stroke=\"#444\"/>\n";
  out << "<text x=\"" << box.left << "\" y=\"" << box.top - 8 << "\">" << title << "</text>\n";
  out << "<text x=\"" << box.left << "\" y=\"" << box.top + box.height + 16 << "\">" << number(x_range.lo) << "</text>\n";
  out << "<text x=\"" << box.left + box.width << "\" y=\"" << box.top + box.height + 16 << "\" text-anchor=\"end\">" << number(x_range.hi)
      << ' ' << x_label << "</text>\n";
  out << "<text x=\"" << box.left - 4 << "\" y=\"" << box.top + box.height << "\" text-anchor=\"end\">" << number(y_range.lo)
      << "</text>\n";
  out << "<text x=\"" << box.left - 4 << "\" y=\"" << box.top + 10 << "\" text-anchor=\"end\">" << number(y_range.hi) << ' ' << y_label
      << "</text>\n";
  return out.str();
}

/// Widens the shorter side so one metre has the same length on both axes of a square box.
void make_equal_scale(Range& x, Range& y) {
  const double half = 0.5 * std::max(x.span(), y.span()) * 1.05;
  const double cx = 0.5 * (x.lo + x.hi);
  const double cy = 0.5 * (y.lo + y.hi);
  x = {cx - half, cx + half};
  y = {cy - half, cy + half};
}

}  // namespace

std::string trajectory_plot_svg(const std::vector<SE3>& gt, const std::vector<SE3>& est, const std::vector<double>& stamps,
                                const std::vector<double>& ate_m) {
  const std::size_t n = std::min({gt.size(), est.size(), stamps.size(), ate_m.size()});
  std::vector<double> gt_x(n), gt_y(n), est_x(n), est_y(n), times(n), errors(ate_m.begin(), ate_m.begin() + static_cast<std::ptrdiff_t>(n));
  for (std::size_t i = 0; i < n; ++i) {
    gt_x[i] = gt[i].translation().x();
    gt_y[i] = gt[i].translation().y();
    est_x[i] = est[i].translation().x();
    est_y[i] = est[i].translation().y();
    times[i] = stamps[i] - stamps.front();
  }
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 1000 500\" width=\"1000\" height=\"500\" "
         "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"1000\" height=\"500\" fill=\"white\"/>\n";
  if (n > 0) {
    const Box top_view{60, 40, 400, 400};
    std::vector<double> all_x = gt_x;
    std::vector<double> all_y = gt_y;
    all_x.insert(all_x.end(), est_x.begin(), est_x.end());
    all_y.insert(all_y.end(), est_y.begin(), est_y.end());
    Range x_range = range_of(all_x);
    Range y_range = range_of(all_y);
    make_equal_scale(x_range, y_range);
    svg << frame(top_view, "top view (x, y)", x_range, y_range, "m", "m");
    svg << polyline(gt_x, gt_y, x_range, y_range, top_view, "#1f77b4");
    svg << polyline(est_x, est_y, x_range, y_range, top_view, "#d62728");

    const Box error_plot{560, 40, 400, 400};
    const Range t_range = range_of(times);
    const Range e_range{0.0, std::max(range_of(errors).hi, 1e-9)};
    svg << frame(error_plot, "ATE translation error over time", t_range, e_range, "s", "m");
    svg << polyline(times, errors, t_range, e_range, error_plot, "#2ca02c");
  }
  svg << "<text x=\"60\" y=\"480\" fill=\"#1f77b4\">ground truth</text>\n"
         "<text x=\"180\" y=\"480\" fill=\"#d62728\">estimate (aligned)</text>\n</svg>\n";
  return svg.str();
}

}  // namespace mlidar::eval
