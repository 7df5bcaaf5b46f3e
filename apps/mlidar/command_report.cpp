// `mlidar report RUN [--out FILE] [--dataset DATASET]`: (re)renders a run
// folder's report.html (src/mlidar/report/run_report.hpp).
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <system_error>

#include "apps/mlidar/commands.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/report/run_report.hpp"

namespace mlidar::cli {
namespace {

struct ReportOptions {
  std::filesystem::path run;
  std::filesystem::path out;
  std::filesystem::path dataset;
};

/// An existing --out is replaced only when it is a report mlidar wrote.
void check_report_out(const std::filesystem::path& out) {
  io::check_output_file(out, "--out");
  std::error_code error;
  if (!std::filesystem::exists(out, error)) return;
  const std::string text = io::read_file_text(out);
  if (text.find("<meta name=\"generator\" content=\"mlidar report\">") == std::string::npos)
    throw UsageError("--out " + out.string() + " exists and is not a report mlidar wrote; give a new file name");
}

int run_report(const ReportOptions& options) {
  const report::RunData run = report::load_run(options.run, {{}, options.dataset, {}});  // exit 3 when RUN is no run folder
  const std::filesystem::path out = options.out.empty() ? options.run / "report.html" : options.out;
  check_report_out(out);
  const std::string html = report::render_report_html(run);
  io::write_atomically(out, [&](std::ostream& stream) { stream << html; });
  for (const std::string& note : run.notes) std::cerr << "note: " << note << '\n';
  std::cout << "wrote " << out.string() << '\n';
  return 0;
}

}  // namespace

Command register_report(CLI::App& app) {
  auto options = std::make_shared<ReportOptions>();
  CLI::App* sub = app.add_subcommand("report", "Render a run folder's report.html again (summary, trajectory, calibration, timing)");
  sub->add_option("run", options->run, "Run folder written by an mlidar job (--out)")->required();
  sub->add_option("--out", options->out, "Write the page here instead of RUN/report.html (a new file, or a report mlidar wrote)");
  sub->add_option("--dataset", options->dataset,
                  "Dataset whose groundtruth/ the report compares with (default: the --dataset the job was given, when it is still there)");
  return {sub, [options] { return run_report(*options); }};
}

}  // namespace mlidar::cli
