// report.html of a slam run, a calibrate auto run and an eval traj run, and the
// page of calibrate planes --html, opened in headless
// Chromium (Debian's `chromium`, installed by scripts/install_deps.sh; the
// test skips with a message when it is absent): no console message, no request
// of the page's own beyond the file itself (Chromium's requests to its own
// Google hosts are its, not the page's), and every figure renders non-blank
// with coloured data in it (each SVG alone on a page, screenshot, decoded).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "apps/cli_runner.hpp"
#include "apps/png_image.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

std::string chromium() {
  const char* env = std::getenv("MLIDAR_CHROMIUM");
  const std::string path = env != nullptr ? env : "/usr/bin/chromium";
  return access(path.c_str(), X_OK) == 0 ? path : std::string{};
}

struct Rendered {
  std::string log;     ///< Chromium's stderr
  std::string netlog;  ///< its --log-net-log JSON
  std::optional<RgbImage> image;
};

Rendered render(const fs::path& page, int width, int height, const fs::path& work) {
  static int count = 0;
  const std::string name = "render" + std::to_string(++count);
  const fs::path png = work / (name + ".png"), net = work / (name + ".json");
  const CliResult result = run_shell(
      quoted(chromium()) +
      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking"
      " --disable-component-update --disable-sync --disable-dev-shm-usage --enable-logging=stderr --v=0 --user-data-dir=" +
      quoted((work / (name + "-profile")).string()) + " --log-net-log=" + quoted(net.string()) + " --window-size=" + std::to_string(width) +
      "," + std::to_string(height) + " --screenshot=" + quoted(png.string()) + " " + quoted("file://" + fs::absolute(page).string()));
  return {result.output, read_text(net), decode_png(read_text(png))};
}

/// URLs in the net log that are neither the page's own file nor Chromium's calls home.
std::vector<std::string> foreign_requests(const std::string& netlog) {
  std::vector<std::string> out;
  const std::regex url("\"url\":\"([a-z]+://[^\"/]*)");
  for (auto it = std::sregex_iterator(netlog.begin(), netlog.end(), url); it != std::sregex_iterator(); ++it) {
    const std::string origin = (*it)[1];
    if (origin.rfind("file://", 0) == 0 || origin.rfind("data:", 0) == 0) continue;
    if (std::regex_search(origin, std::regex(R"(\.(google\.com|googleapis\.com|gvt1\.com|gstatic\.com)$)"))) continue;
    out.push_back(origin);
  }
  return out;
}

void expect_quiet(const Rendered& r, const std::string& what) {
  EXPECT_EQ(r.log.find(":CONSOLE"), std::string::npos) << what << ": a console message\n" << r.log;
  EXPECT_TRUE(foreign_requests(r.netlog).empty()) << what << ": requested " << foreign_requests(r.netlog).front();
  ASSERT_TRUE(r.image.has_value()) << what << ": no screenshot\n" << r.log;
}

struct Ink {
  double grey_std = 0.0;     ///< spread of the grey levels
  std::size_t coloured = 0;  ///< pixels far from grey (data; axes, grid and text are grey)
};

Ink ink_of(const RgbImage& image) {
  double sum = 0.0, sum_sq = 0.0;
  Ink ink;
  for (const auto& p : image.pixels) {
    const double grey = (p[0] + p[1] + p[2]) / 3.0;
    sum += grey;
    sum_sq += grey * grey;
    if (std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) > 60) ++ink.coloured;
  }
  const double n = static_cast<double>(image.pixels.size());
  ink.grey_std = std::sqrt(std::max(0.0, sum_sq / n - (sum / n) * (sum / n)));
  return ink;
}

/// Each <svg ...>...</svg> of the page alone on a page with the report's head, screenshot at its size.
void expect_every_figure_drawn(const std::string& html, const fs::path& work, std::size_t expected_at_least) {
  const std::string head = html.substr(0, html.find("<body>") + 6);
  std::size_t figures = 0;
  const std::string open = "<svg class=\"chart\" viewBox=\"0 0 ";
  for (std::size_t at = html.find(open); at != std::string::npos; at = html.find(open, at + 1)) {
    const std::string svg = html.substr(at, html.find("</svg>", at) + 6 - at);
    std::istringstream size(svg.substr(open.size()));
    int width = 0, height = 0;
    size >> width >> height;
    const std::string title = svg.substr(svg.find("<title>") + 7, svg.find("</title>") - svg.find("<title>") - 7);
    const fs::path page = work / ("figure" + std::to_string(++figures) + ".html");
    std::ofstream(page) << head << "<style>body{margin:0}</style>" << svg << "</body></html>";
    const Rendered r = render(page, width, height, work);
    expect_quiet(r, title);
    if (!r.image) continue;
    const Ink ink = ink_of(*r.image);
    EXPECT_GT(ink.grey_std, 5.0) << title << ": blank";
    EXPECT_GT(ink.coloured, 50u) << title << ": no data drawn";
  }
  EXPECT_GE(figures, expected_at_least);
}

TEST(ReportBrowser, SlamAndCalibrateAutoReportsRenderOfflineWithEveryFigureDrawn) {
  if (chromium().empty()) GTEST_SKIP() << "chromium not found (apt-get install chromium, or set MLIDAR_CHROMIUM)";
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "sim";
  ASSERT_EQ(run_cli("simulate drive --rig rhd --scene campus --trajectory handheld --frames 80 --seed 1 --perturb 5,0.1 --out " +
                    quoted(sim.string()))
                .exit_code,
            0);
  const CliResult slam = run_cli("slam --dataset " + quoted(sim.string()) + " --out " + quoted((dir / "slam").string()));
  ASSERT_EQ(slam.exit_code, 0) << slam.output;
  const CliResult autocalib = run_cli("calibrate auto --dataset " + quoted(sim.string()) + " --out " + quoted((dir / "auto").string()));
  ASSERT_EQ(autocalib.exit_code, 0) << autocalib.output;

  for (const char* run : {"slam", "auto"}) {
    const fs::path page = dir / run / "report.html";
    const Rendered whole = render(page, 1360, 3000, dir);
    expect_quiet(whole, page.string());
    if (whole.image) {
      EXPECT_GT(ink_of(*whole.image).grey_std, 5.0) << page;
    }
  }
  // slam: top and side views, the error over time, the map, lambda_min and the two estimate charts of `right`, timing.
  expect_every_figure_drawn(read_text(dir / "slam" / "report.html"), dir, 8);
}

TEST(ReportBrowser, EvalAndPairCalibrationPagesRenderOfflineWithEveryFigureDrawn) {
  if (chromium().empty()) GTEST_SKIP() << "chromium not found (apt-get install chromium, or set MLIDAR_CHROMIUM)";
  const fs::path dir = scratch_dir();
  // eval traj: a 300 m arc and an estimate drifting in yaw and scale.
  {
    std::ofstream gt(dir / "gt.tum"), est(dir / "est.tum");
    for (int i = 0; i <= 300; ++i) {
      const double a = 0.004 * i, b = 0.0041 * i;
      gt << 0.1 * i << ' ' << 250 * std::sin(a) << ' ' << 250 * (1 - std::cos(a)) << " 0 0 0 " << std::sin(a / 2) << ' ' << std::cos(a / 2)
         << '\n';
      est << 0.1 * i << ' ' << 251 * std::sin(b) << ' ' << 251 * (1 - std::cos(b)) << " 0 0 0 " << std::sin(b / 2) << ' ' << std::cos(b / 2)
          << '\n';
    }
  }
  const CliResult eval = run_cli("eval traj --gt " + quoted((dir / "gt.tum").string()) + " --est " + quoted((dir / "est.tum").string()) +
                                 " --out " + quoted((dir / "eval").string()));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  // calibrate planes --html on a simulated corner.
  ASSERT_EQ(run_cli("simulate corner --angles 90:90 --seed 3 --out " + quoted((dir / "corner").string())).exit_code, 0);
  const CliResult planes = run_cli("calibrate planes --ref " + quoted((dir / "corner" / "scans" / "l1" / "000000.pcd").string()) +
                                   " --target " + quoted((dir / "corner" / "scans" / "l2" / "000000.pcd").string()) + " --out " +
                                   quoted((dir / "planes.yaml").string()) + " --html " + quoted((dir / "planes.html").string()));
  ASSERT_EQ(planes.exit_code, 0) << planes.output;

  for (const fs::path& page : {dir / "eval" / "report.html", dir / "planes.html"}) {
    const Rendered whole = render(page, 1360, 2400, dir);
    expect_quiet(whole, page.string());
    if (whole.image) {
      EXPECT_GT(ink_of(*whole.image).grey_std, 5.0) << page;
    }
  }
  // eval: the two KITTI drift charts, top and side views, the error over time; planes: before/after, top/side.
  expect_every_figure_drawn(read_text(dir / "eval" / "report.html"), dir, 5);
  expect_every_figure_drawn(read_text(dir / "planes.html"), dir, 4);
}

}  // namespace
}  // namespace mlidar::test
