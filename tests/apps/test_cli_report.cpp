// `mlidar report`: re-renders a run folder's report.html (the same bytes for
// the same folder), compares with the dataset given by --dataset, refuses to
// replace a file it did not write, and names a folder that is no run.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "apps/cli_runner.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

TEST(CliReport, RendersAgainRefusesForeignFilesAndNamesFoldersThatAreNoRun) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "sim";
  ASSERT_EQ(
      run_cli("simulate drive --rig rhd --scene room --trajectory static --frames 6 --seed 1 --out " + quoted(sim.string())).exit_code, 0);
  const fs::path run = dir / "run";
  EXPECT_EQ(run_cli("calibrate auto --dataset " + quoted(sim.string()) + " --out " + quoted(run.string())).exit_code,
            1);  // static: untrusted
  const std::string written = read_text(run / "report.html");
  ASSERT_NE(written.find("<section id=\"summary\">"), std::string::npos);
  EXPECT_NE(written.find("<li class=\"bad\">right: "), std::string::npos) << "a static rig cannot be calibrated";

  // Again from the folder: run.json's facts are there now; twice gives the same bytes.
  const CliResult again = run_cli("report " + quoted(run.string()));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const std::string rendered = read_text(run / "report.html");
  EXPECT_NE(rendered.find("finished (UTC)"), std::string::npos);
  ASSERT_EQ(run_cli("report " + quoted(run.string()) + " --out " + quoted((dir / "copy.html").string())).exit_code, 0);
  EXPECT_EQ(read_text(dir / "copy.html"), rendered);
  // --out over a report it wrote is fine; over another file it is refused and the file kept.
  EXPECT_EQ(run_cli("report " + quoted(run.string()) + " --out " + quoted((dir / "copy.html").string())).exit_code, 0);
  std::ofstream(dir / "notes.html") << "my notes";
  const CliResult foreign = run_cli("report " + quoted(run.string()) + " --out " + quoted((dir / "notes.html").string()));
  EXPECT_EQ(foreign.exit_code, 2) << foreign.output;
  EXPECT_NE(foreign.output.find("notes.html"), std::string::npos) << foreign.output;
  EXPECT_EQ(read_text(dir / "notes.html"), "my notes");

  // Ground truth from --dataset when the job's is gone.
  fs::rename(sim, dir / "moved");
  const CliResult moved = run_cli("report " + quoted(run.string()) + " --out " + quoted((dir / "no_truth.html").string()));
  EXPECT_EQ(moved.exit_code, 0) << moved.output;
  EXPECT_NE(moved.output.find("no ground truth"), std::string::npos) << moved.output;
  EXPECT_EQ(read_text(dir / "no_truth.html").find("error vs ground truth"), std::string::npos);
  ASSERT_EQ(run_cli("report " + quoted(run.string()) + " --dataset " + quoted((dir / "moved").string()) + " --out " +
                    quoted((dir / "truth.html").string()))
                .exit_code,
            0);
  EXPECT_NE(read_text(dir / "truth.html").find("error vs ground truth"), std::string::npos);

  // Not a run folder: exit 3 naming run.json, nothing written.
  fs::create_directories(dir / "plain");
  const CliResult plain = run_cli("report " + quoted((dir / "plain").string()));
  EXPECT_EQ(plain.exit_code, 3) << plain.output;
  EXPECT_NE(plain.output.find("run.json"), std::string::npos) << plain.output;
  EXPECT_FALSE(fs::exists(dir / "plain" / "report.html"));
  EXPECT_EQ(run_cli("report " + quoted((dir / "nothing").string())).exit_code, 3);
}

}  // namespace
}  // namespace mlidar::test
