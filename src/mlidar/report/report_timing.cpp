// The timing section of report.html: seconds per frame of each stage
// (metrics.json stages) and the per-frame trace.
#include <sstream>

#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

constexpr const char* kStageColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2"};

std::string milliseconds(const nlohmann::json& summary, const char* key) {
  return fixed(1e3 * number_of(summary.value(key, nlohmann::json())), 2);
}

}  // namespace

std::optional<Section> timing_section(const RunData& run) {
  if (!run.metrics.contains("stages") || !run.metrics["stages"].is_object()) return std::nullopt;
  std::vector<std::vector<std::string>> rows;
  for (const auto& [stage, summary] : run.metrics["stages"].items())
    rows.push_back({escape_markup(stage), milliseconds(summary, "mean"), milliseconds(summary, "p50"), milliseconds(summary, "p95"),
                    milliseconds(summary, "max")});
  if (run.metrics.contains("total_seconds") && run.metrics["total_seconds"].is_object()) {
    const nlohmann::json& total = run.metrics["total_seconds"];
    rows.push_back({"<b>estimator (all but load)</b>", milliseconds(total, "mean"), milliseconds(total, "p50"), milliseconds(total, "p95"),
                    milliseconds(total, "max")});
  }
  std::ostringstream html;
  html << "<p>Wall time per frame (ms).</p>\n" << html_table({"stage", "mean", "p50", "p95", "max"}, rows);
  // The per-frame trace: metrics.json per_frame[].seconds {stage: s}.
  Chart trace;
  trace.title = "Time per frame by stage";
  trace.x_label = "frame";
  trace.y_label = "ms";
  trace.width = 960;
  trace.height = 320;
  if (run.metrics.contains("per_frame") && run.metrics["per_frame"].is_array()) {
    std::size_t colour = 0;
    for (const auto& [stage, unused] : run.metrics["stages"].items()) {
      Series s{stage, kStageColours[colour++ % 7], {}, {}};
      double index = 0.0;
      for (const auto& frame : run.metrics["per_frame"]) {
        const double seconds = frame.contains("seconds") && frame["seconds"].is_object()
                                   ? number_of(frame["seconds"].value(stage, nlohmann::json()))
                                   : std::nan("");
        if (std::isfinite(seconds)) {
          s.x.push_back(index);
          s.y.push_back(1e3 * seconds);
        }
        index += 1.0;
      }
      if (!s.x.empty()) trace.series.push_back(std::move(s));
    }
  }
  if (!trace.series.empty()) html << render_svg(trace);
  return Section{"timing", "Timing", html.str()};
}

}  // namespace mlidar::report
