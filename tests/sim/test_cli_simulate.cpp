// `mlidar simulate`: exit codes and messages, no partial output.
#include <fstream>

#include <gtest/gtest.h>

#include "apps/cli_runner.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/run_folder.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

TEST(CliSimulate, WritesADatasetReplacesItsOwnAndRefusesOtherFolders) {
  const fs::path dir = scratch_dir();
  const fs::path out = dir / "ds";
  const std::string base = "simulate drive --rig single-vlp16 --scene room --trajectory handheld --frames 2 --seed 3 --out ";
  auto result = run_cli(base + quoted(out.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(io::read_dataset_yaml(out).lidars.size(), 1u);
  EXPECT_TRUE(fs::exists(out / "scans/lidar/000001.pcd"));
  EXPECT_EQ(io::run_folder_command(out), "simulate drive");
  // An earlier simulate output is replaced whole: a file added to it does not survive.
  { std::ofstream(out / "scans/lidar/000002.pcd") << "stale"; }
  result = run_cli(base + quoted(out.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_FALSE(fs::exists(out / "scans/lidar/000002.pcd"));
  // A folder that is not an mlidar output is refused (exit 2, untouched) unless --overwrite.
  const fs::path mine = dir / "mine";
  fs::create_directories(mine);
  { std::ofstream(mine / "notes.txt") << "keep me"; }
  result = run_cli(base + quoted(mine.string()));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("is not an mlidar run folder"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("--overwrite"), std::string::npos) << result.output;
  EXPECT_TRUE(fs::exists(mine / "notes.txt"));
  EXPECT_FALSE(fs::exists(mine / "dataset.yaml"));
  result = run_cli(base + quoted(mine.string()) + " --overwrite");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_FALSE(fs::exists(mine / "notes.txt"));
  EXPECT_TRUE(fs::exists(mine / "dataset.yaml"));
  for (const auto& entry : fs::directory_iterator(dir))  // no staging folder left beside them
    EXPECT_EQ(entry.path().filename().string().find(".mlidar-stage-"), std::string::npos) << entry.path();
}

TEST(CliSimulate, BadInputExitCodes) {
  const fs::path dir = scratch_dir();
  const std::string out = " --out " + quoted((dir / "x").string());
  EXPECT_EQ(run_cli("simulate drive --rig tractor" + out).exit_code, 2);
  EXPECT_EQ(run_cli("simulate drive --scene moon" + out).exit_code, 2);
  EXPECT_EQ(run_cli("simulate drive --trajectory flying" + out).exit_code, 2);
  EXPECT_EQ(run_cli("simulate drive --frames 0" + out).exit_code, 2);
  EXPECT_EQ(run_cli("simulate corner --angles 60" + out).exit_code, 2);
  const fs::path rig = dir / "rig.yaml";
  { std::ofstream(rig) << "lidars: [{name: a, model: VLP-16, colour: red}]\n"; }
  const auto bad_rig = run_cli("simulate drive --rig " + quoted(rig.string()) + out);
  EXPECT_EQ(bad_rig.exit_code, 3);
  EXPECT_NE(bad_rig.output.find("colour"), std::string::npos) << bad_rig.output;
  EXPECT_FALSE(fs::exists(dir / "x"));
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir)) entries += entry.path().filename() != "rig.yaml";
  EXPECT_EQ(entries, 0u);
}

}  // namespace
}  // namespace mlidar::test
