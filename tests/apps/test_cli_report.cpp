// `mlidar report`: re-renders a run folder's report.html (the same bytes for
// the same folder), compares with the dataset given by --dataset, refuses to
// replace a file it did not write, and names a folder that is no run.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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

/// A TUM file of 451 poses 1 m apart (0.1 s) along x; `stretch` scales every step (a 1 % scale drift: 1.01).
void write_line(const fs::path& path, double stretch) {
  std::ofstream out(path);
  out.precision(12);
  for (int i = 0; i <= 450; ++i) out << 0.1 * i << ' ' << stretch * i << " 0 0 0 0 0 1\n";
}

TEST(CliReport, EvalTrajWritesARunFolderWithTheErrorAndTheKittiDriftPerLength) {
  const fs::path dir = scratch_dir();
  fs::create_directories(dir / "est");
  write_line(dir / "gt.tum", 1.0);
  write_line(dir / "est" / "trajectory.tum", 1.01);
  const fs::path run = dir / "eval";
  const std::string command =
      "eval traj --gt " + quoted((dir / "gt.tum").string()) + " --est " + quoted((dir / "est" / "trajectory.tum").string());
  const CliResult result = run_cli(command + " --json " + quoted((dir / "eval.json").string()) + " --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(read_text(run / "eval.json"), read_text(dir / "eval.json"));
  EXPECT_TRUE(fs::exists(run / "run.json"));
  EXPECT_EQ(read_text(run / "groundtruth.tum").empty(), false);
  // Segments of L m end L + 1 m along (devkit), so each drifts 1 % x (L + 1) / L: 1.010 % at 100 m, 1.0025 % at 400 m.
  const auto json = nlohmann::json::parse(read_text(run / "eval.json"));
  ASSERT_EQ(json["kitti"]["by_length"].size(), 4u);  // 100-400 m fit in 450 m
  EXPECT_NEAR(json["kitti"]["by_length"][0]["translation_percent"].get<double>(), 1.01, 1e-6);
  EXPECT_NEAR(json["kitti"]["by_length"][3]["translation_percent"].get<double>(), 1.0025, 1e-6);

  const std::string report = read_text(run / "report.html");
  for (const char* id : {"summary", "evaluation", "trajectory"})
    EXPECT_NE(report.find("<section id=\"" + std::string(id) + "\">"), std::string::npos) << id;
  EXPECT_NE(report.find("<title>KITTI translation drift per segment length</title>"), std::string::npos);
  EXPECT_NE(report.find("<td>100</td><td>"), std::string::npos);
  EXPECT_NE(report.find("<td>1.010</td>"), std::string::npos) << "the 100 m row";
  EXPECT_NE(report.find("<title>Translation error over time (ATE)</title>"), std::string::npos);
  EXPECT_NE(report.find("<li class=\"ok\">ATE RMSE "), std::string::npos);
  EXPECT_EQ(report.find("http"), std::string::npos);
  // `mlidar report` renders it again from the folder alone (run.json's facts added), twice the same bytes.
  ASSERT_EQ(run_cli("report " + quoted(run.string()) + " --out " + quoted((dir / "a.html").string())).exit_code, 0);
  ASSERT_EQ(run_cli("report " + quoted(run.string()) + " --out " + quoted((dir / "b.html").string())).exit_code, 0);
  EXPECT_EQ(read_text(dir / "a.html"), read_text(dir / "b.html"));
  EXPECT_NE(read_text(dir / "a.html").find("<section id=\"evaluation\">"), std::string::npos);

  // A path shorter than 100 m: no KITTI drift, said so; an --out holding the estimate is refused and kept.
  std::ofstream(dir / "short.tum") << "0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n0.3 3 0.1 0 0 0 0 1\n";
  ASSERT_EQ(run_cli("eval traj --gt " + quoted((dir / "short.tum").string()) + " --est " + quoted((dir / "short.tum").string()) +
                    " --out " + quoted((dir / "short").string()))
                .exit_code,
            0);
  EXPECT_NE(read_text(dir / "short" / "report.html").find("no KITTI drift"), std::string::npos);
  const std::string estimate = read_text(dir / "est" / "trajectory.tum");
  const CliResult inside = run_cli(command + " --out " + quoted((dir / "est").string()));
  EXPECT_EQ(inside.exit_code, 2) << inside.output;
  EXPECT_NE(inside.output.find("--out"), std::string::npos) << inside.output;
  EXPECT_EQ(read_text(dir / "est" / "trajectory.tum"), estimate);
  EXPECT_FALSE(fs::exists(dir / "est" / "report.html"));
}

}  // namespace
}  // namespace mlidar::test
