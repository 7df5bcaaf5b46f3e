// Issue 15, outputs: --out is a new folder, an empty one or an earlier mlidar
// run; run folders are staged and swapped, so a signal at the write step or a
// full disk leaves the previous run exactly as it was and no temporary file.
#include <sys/mount.h>

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/reliability_support.hpp"
#include "mlidar/io/run_folder.hpp"

namespace mlidar::test {
namespace {

std::string odometry_into(const fs::path& out, const std::string& extra = "") {
  return "odometry --dataset " + quoted(small_dataset().string()) + " --threads 1 --out " + quoted(out.string()) + extra;
}

TEST(CliOutRules, TheInputAndItsGroundTruthAreNeverAnOutput) {
  const fs::path dir = scratch_dir();
  const fs::path data = copy_of_small_dataset(dir / "data");
  const auto before = folder_checksums(data);
  for (const fs::path& out : {data / "groundtruth", data / "groundtruth" / "run", data, dir}) {
    for (const char* overwrite : {"", " --overwrite"}) {
      const CliResult r =
          run_cli("slam --calibrate fixed --dataset " + quoted(data.string()) + " --out " + quoted(out.string()) + overwrite);
      EXPECT_EQ(r.exit_code, 2) << out << overwrite << r.output;
      EXPECT_NE(r.output.find("--out " + out.string()), std::string::npos) << r.output;
      EXPECT_TRUE(r.output.find("groundtruth/") != std::string::npos || r.output.find("would replace the input") != std::string::npos)
          << r.output;
    }
  }
  EXPECT_EQ(folder_checksums(data), before);
}

TEST(CliOutRules, AFolderOfOtherFilesIsReplacedOnlyWithOverwrite) {
  const fs::path out = scratch_dir() / "mine";
  fs::create_directories(out);
  { std::ofstream(out / "notes.txt") << "keep me"; }
  const auto before = folder_checksums(out);
  CliResult r = run_cli(odometry_into(out));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is not an mlidar run folder"), std::string::npos) << r.output;
  EXPECT_EQ(folder_checksums(out), before);
  r = run_cli(odometry_into(out, " --overwrite"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(out / "notes.txt"));
  EXPECT_EQ(io::run_folder_command(out), "odometry");
  const nlohmann::json run = nlohmann::json::parse(std::ifstream(out / "run.json"));
  EXPECT_EQ(run["tool"], "mlidar");
  EXPECT_EQ(run["arguments"].back(), "--overwrite");
}

TEST(CliOutRules, AnEarlierRunIsReplacedWholeNeverMixed) {
  const fs::path out = scratch_dir() / "run";
  CliResult r =
      run_cli("slam --calibrate fixed --threads 1 --dataset " + quoted(small_dataset().string()) + " --out " + quoted(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(out / "extrinsics.yaml"));
  r = run_cli(odometry_into(out));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(out / "extrinsics.yaml")) << "slam's file left beside odometry's";
  EXPECT_EQ(io::run_folder_command(out), "odometry");
  EXPECT_TRUE(entries_containing(out.parent_path(), ".mlidar-stage-").empty());
}

TEST(CliOutRules, ADatasetIsReplacedOnlyBySimulate) {
  const fs::path dir = scratch_dir();
  const fs::path other = copy_of_small_dataset(dir / "other");
  const auto before = folder_checksums(other);
  const CliResult r = run_cli(odometry_into(other));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is a dataset written by `mlidar simulate drive`"), std::string::npos) << r.output;
  EXPECT_EQ(folder_checksums(other), before);
}

TEST(CliOutRules, AnOutThatCannotBeCreatedIsExitTwoBeforeTheJob) {
  const fs::path dir = scratch_dir();
  { std::ofstream(dir / "a_file") << "x"; }
  for (const fs::path& out : {dir / "a_file", dir / "a_file" / "run", fs::path("/proc/mlidar_cannot_write_here")}) {
    const CliResult r = run_cli(odometry_into(out));
    EXPECT_EQ(r.exit_code, 2) << out << r.output;
    EXPECT_NE(r.output.find("--out"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("frames"), std::string::npos) << "the job ran before the check: " << r.output;
  }
  EXPECT_EQ(std::ifstream(dir / "a_file").get(), 'x');
}

TEST(CliInterrupt, SignalsAtTheRenameLeaveThePreviousRunAndNoTemporaryFile) {
  const fs::path out = scratch_dir() / "run";
  ASSERT_EQ(run_cli(odometry_into(out)).exit_code, 0);
  const auto before = folder_checksums(out);
  for (const auto& [signal, code] : {std::pair{SIGTERM, 143}, std::pair{SIGINT, 130}}) {
    const Interrupted r = interrupt_at_pause({"odometry", "--dataset", small_dataset().string(), "--lidars", "left", "--out", out.string()},
                                             "commit", signal);
    ASSERT_TRUE(r.saw_marker) << r.output;
    EXPECT_EQ(r.exit_code, code) << r.output;
    EXPECT_NE(r.output.find("earlier outputs are unchanged"), std::string::npos) << r.output;
    EXPECT_EQ(folder_checksums(out), before);
    EXPECT_TRUE(entries_containing(out.parent_path(), ".mlidar-stage-").empty());
  }
}

TEST(CliInterrupt, ASignalDuringASingleFileWriteKeepsThePreviousFile) {
  const fs::path dir = scratch_dir();
  const fs::path json = dir / "eval.json";
  { std::ofstream(json) << "previous"; }
  const std::string gt = (small_dataset() / "groundtruth" / "trajectory.tum").string();
  const Interrupted r = interrupt_at_pause({"eval", "traj", "--gt", gt, "--est", gt, "--json", json.string()}, "file", SIGTERM);
  ASSERT_TRUE(r.saw_marker) << r.output;
  EXPECT_EQ(r.exit_code, 143) << r.output;
  std::string content;
  std::getline(std::ifstream(json), content);
  EXPECT_EQ(content, "previous");
  EXPECT_TRUE(entries_containing(dir, ".tmp-").empty());
}

TEST(CliDiskFull, AFullDiskLeavesThePreviousRunExactly) {
  const fs::path disk = scratch_dir() / "disk";
  fs::create_directories(disk);
  if (::geteuid() != 0 || ::mount("tmpfs", disk.c_str(), "tmpfs", 0, "size=2m") != 0)
    GTEST_SKIP() << "needs root to mount a 2 MB tmpfs (a full disk); not run here";
  const fs::path out = disk / "run";
  const CliResult first =
      run_cli("odometry --dataset " + quoted(small_dataset().string()) + " --lidars left --out " + quoted(out.string()));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const auto before = folder_checksums(out);
  {  // fill the disk to within 4 KB
    std::ofstream filler(disk / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    while (filler.write(block.data(), block.size())) filler.flush();
  }
  fs::resize_file(disk / "filler", fs::file_size(disk / "filler") - 4096);
  const CliResult second = run_cli(odometry_into(out));
  EXPECT_EQ(second.exit_code, 2) << second.output;
  EXPECT_NE(second.output.find("write failed"), std::string::npos) << second.output;
  EXPECT_EQ(folder_checksums(out), before);
  EXPECT_TRUE(entries_containing(disk, ".mlidar-stage-").empty());
  ::umount(disk.c_str());
}

}  // namespace
}  // namespace mlidar::test
