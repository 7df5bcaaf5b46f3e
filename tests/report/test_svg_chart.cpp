// The report's SVG charts: ticks, equal axes, log axis, thinning, escaping,
// and where a data point lands.
#include <cmath>
#include <random>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(SvgChart, TicksAreOneTwoOrFiveTimesAPowerOfTenAndCoverTheRange) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> exponent(-4.0, 4.0), share(0.01, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    const double lo = (share(rng) - 0.5) * std::pow(10.0, exponent(rng));
    const double hi = lo + share(rng) * std::pow(10.0, exponent(rng));
    const std::vector<double> ticks = nice_ticks(lo, hi, 6);
    ASSERT_GE(ticks.size(), 3u) << lo << " " << hi;
    ASSERT_LE(ticks.size(), 16u) << lo << " " << hi;
    const double step = ticks[1] - ticks[0];
    const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
    EXPECT_TRUE(std::abs(mantissa - 1) < 1e-6 || std::abs(mantissa - 2) < 1e-6 || std::abs(mantissa - 5) < 1e-6) << step;
    EXPECT_GE(ticks.front(), lo - 1e-9 * step);
    EXPECT_LE(ticks.back(), hi + 1e-9 * step);
    EXPECT_LT(ticks.front() - step, lo);  // none missing at either end
    EXPECT_GT(ticks.back() + step, hi);
  }
  EXPECT_TRUE(nice_ticks(1.0, 1.0, 5).empty());
  EXPECT_TRUE(nice_ticks(0.0, NAN, 5).empty());
}

Chart path_chart(bool equal) {
  Chart chart;
  chart.equal_axes = equal;
  chart.series.push_back({"path", "#000", {0.0, 50.0, 100.0}, {0.0, 5.0, 2.0}});
  return chart;
}

TEST(SvgChart, EqualAxesGiveAMetreTheSameLengthOnBothAxesAndKeepEveryPoint) {
  const ChartLayout equal = layout_chart(path_chart(true));
  EXPECT_NEAR(equal.x_scale(), equal.y_scale(), 1e-9 * equal.x_scale());
  EXPECT_LE(equal.x_lo, 0.0);
  EXPECT_GE(equal.x_hi, 100.0);
  EXPECT_LE(equal.y_lo, 0.0);
  EXPECT_GE(equal.y_hi, 5.0);
  const ChartLayout free = layout_chart(path_chart(false));
  EXPECT_GT(free.y_scale(), 5.0 * free.x_scale());  // 100 m by 5 m stretched to fill the box
  EXPECT_NE(render_svg(path_chart(true)).find(" m</text>"), std::string::npos) << "a scale bar";
}

TEST(SvgChart, APointLandsWhereTheLayoutSays) {
  Chart chart;
  chart.series.push_back({"a", "#000", {0.0, 2.0, 10.0}, {0.0, 7.0, 10.0}});
  const ChartLayout l = layout_chart(chart);
  const double u = l.left + (2.0 - l.x_lo) * l.x_scale();
  const double v = l.top + l.height - (7.0 - l.y_lo) * l.y_scale();
  char expected[64];
  std::snprintf(expected, sizeof expected, " %.1f,%.1f ", u, v);
  EXPECT_NE(render_svg(chart).find(expected), std::string::npos) << expected;
}

TEST(SvgChart, LogAxisSpansTheDecadesAndLeavesOutValuesAtOrBelowZero) {
  Chart chart;
  chart.log_y = true;
  chart.series.push_back({"lambda", "#000", {0, 1, 2, 3, 4}, {1.0, 10.0, -5.0, 1e3, 1e4}, true});
  chart.lines.push_back({70.0, "lambda_calib", "#f00"});
  const ChartLayout l = layout_chart(chart);
  EXPECT_LE(l.y_lo, 0.0);
  EXPECT_GE(l.y_hi, 4.0);
  EXPECT_LT(l.y_hi, 5.0);
  const std::string svg = render_svg(chart);
  EXPECT_EQ(count_of(svg, "<circle"), 4u) << "the negative value is not drawn";
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_NE(svg.find(">1000</text>"), std::string::npos) << "decade ticks labelled with their values";
}

TEST(SvgChart, LongSeriesAreThinnedKeepingTheLastPointAndNaNBreaksTheLine) {
  Chart chart;
  Series s{"long", "#000", {}, {}};
  for (int i = 0; i < 100000; ++i) {
    s.x.push_back(i);
    s.y.push_back(std::sin(i * 1e-3));
  }
  s.y[50000] = NAN;
  chart.series.push_back(s);
  const std::string svg = render_svg(chart);
  EXPECT_EQ(count_of(svg, "<polyline"), 2u);
  const std::regex vertex(R"((\d+\.\d),(\d+\.\d) )");
  const auto vertices =
      static_cast<std::size_t>(std::distance(std::sregex_iterator(svg.begin(), svg.end(), vertex), std::sregex_iterator()));
  EXPECT_LE(vertices, kMaxVertices + 2);
  EXPECT_GE(vertices, kMaxVertices / 2);
  const ChartLayout l = layout_chart(chart);
  char last[32];
  std::snprintf(last, sizeof last, "%.1f,", l.left + (99999.0 - l.x_lo) * l.x_scale());
  EXPECT_NE(svg.find(last), std::string::npos) << "the last point is drawn";
}

TEST(SvgChart, TextIsEscaped) {
  Chart chart;
  chart.title = "<script>alert(1)</script> & \"quotes\"";
  chart.series.push_back({"a<b", "red\"", {0, 1}, {0, 1}});
  const std::string svg = render_svg(chart);
  EXPECT_EQ(svg.find("<script"), std::string::npos);
  EXPECT_NE(svg.find("&lt;script&gt;alert(1)&lt;/script&gt; &amp; &quot;quotes&quot;"), std::string::npos);
  EXPECT_NE(svg.find("a&lt;b"), std::string::npos);
  EXPECT_EQ(escape_markup("a&b<c>d\"e"), "a&amp;b&lt;c&gt;d&quot;e");
}

TEST(SvgChart, AnEmptyChartStillRenders) {
  const std::string svg = render_svg(Chart{});
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

}  // namespace
}  // namespace mlidar::report
