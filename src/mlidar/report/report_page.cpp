// report.html assembled from its sections (run_report.hpp).
#include <cmath>
#include <sstream>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

constexpr const char* kStyle =
    "body{font-family:sans-serif;margin:1.5em auto;max-width:1320px;color:#222;padding:0 1em}"
    "h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}"
    "table{border-collapse:collapse;font-size:.9em;margin:.5em 0}td,th{border:1px solid #ccc;padding:.25em .5em;text-align:left}"
    "th{background:#f2f2f2}td.n{text-align:right;font-variant-numeric:tabular-nums}"
    "ul.verdicts{list-style:none;padding:0}ul.verdicts li{padding:.3em .6em;margin:.2em 0;border-left:.4em solid}"
    "ul.verdicts li.ok{border-color:#2a9d3a;background:#eef8ef}ul.verdicts li.warn{border-color:#d9a400;background:#fdf7e3}"
    "ul.verdicts li.bad{border-color:#c62828;background:#fdeceb}.figures{display:flex;flex-wrap:wrap;gap:.5em}"
    "nav a{margin-right:1em}p.note{color:#555;font-size:.9em}"
    "@media print{nav{display:none}section{break-inside:avoid}}";

}  // namespace

double number_of(const nlohmann::json& value) { return value.is_number() ? value.get<double>() : std::nan(""); }

std::string html_table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::ostringstream out;
  out << "<table><tr>";
  for (const std::string& h : header) out << "<th>" << h << "</th>";
  out << "</tr>\n";
  for (const auto& row : rows) {
    out << "<tr>";
    for (const std::string& cell : row) out << "<td>" << cell << "</td>";
    out << "</tr>\n";
  }
  out << "</table>\n";
  return out.str();
}

namespace {

std::vector<Section> all_sections(const RunData& run) {
  std::vector<Section> sections{summary_section(run)};
  if (auto s = extrinsics_section(run)) sections.push_back(std::move(*s));
  if (auto s = evaluation_section(run)) sections.push_back(std::move(*s));
  if (auto s = trajectory_section(run)) sections.push_back(std::move(*s));
  if (auto s = map_section(run)) sections.push_back(std::move(*s));
  if (auto s = autocalib_stages_section(run)) sections.push_back(std::move(*s));
  for (Section& s : calibration_sections(run)) sections.push_back(std::move(s));
  if (auto s = timing_section(run)) sections.push_back(std::move(*s));
  return sections;
}

}  // namespace

std::string render_page(const std::string& title, const std::vector<Section>& sections) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"generator\" content=\"mlidar report\">"
      << "<title>" << escape_markup(title) << "</title><style>" << kStyle << "</style></head>\n<body>\n<h1>" << escape_markup(title)
      << "</h1>\n<nav>";
  for (const Section& s : sections) out << "<a href=\"#" << s.id << "\">" << escape_markup(s.title) << "</a>";
  out << "</nav>\n";
  for (const Section& s : sections)
    out << "<section id=\"" << s.id << "\"><h2>" << escape_markup(s.title) << "</h2>\n" << s.html << "</section>\n";
  out << "</body></html>\n";
  return out.str();
}

std::string render_report_html(const RunData& run) {
  std::vector<Section> sections;
  try {
    sections = all_sections(run);
  } catch (const nlohmann::json::exception& error) {  // a value of another type than the job writes
    throw InputError((run.folder / "metrics.json").string(), "",
                     std::string("unexpected structure (") + error.what() + "); run the job again with this version to rewrite it");
  }
  return render_page("mlidar " + (run.command.empty() ? std::string("run") : run.command) + ": " + run.title_folder, sections);
}

void write_run_report(const std::filesystem::path& folder, const ReportSource& source) {
  const std::string html = render_report_html(load_run(folder, source));
  io::write_atomically(folder / "report.html", [&](std::ostream& stream) { stream << html; });
}

}  // namespace mlidar::report
