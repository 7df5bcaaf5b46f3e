// Issue 15, inputs: input that cannot be used is exit 3 naming the file and
// the field (and writes nothing); unusable scans are reported per LiDAR and
// frame; a base LiDAR without most of its frames fails the job (exit 1);
// numeric options are range-checked at parse time (exit 2); standard input
// and process substitution work as inputs; --threads 1 runs repeat exactly.
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/reliability_support.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

/// Rewrites the t field of a scan: t' = scale * t + shift.
void retime(const fs::path& scan, double scale, double shift) {
  io::CloudFile cloud = io::read_cloud(scan);
  io::FieldColumn& t = *cloud.table.find("t");
  for (std::size_t i = 0; i < cloud.table.num_points; ++i) {
    double v = t.value(i) * scale + shift;
    std::memcpy(t.data.data() + 8 * i, &v, 8);
  }
  io::write_cloud(scan, cloud);
}

/// A scan of `points` points, all at the origin + 5 m, rings `ring` (an empty cloud for 0 points).
void replace_scan(const fs::path& scan, std::size_t points, std::uint16_t ring) {
  Scan s;
  for (std::size_t i = 0; i < points; ++i) {
    s.points.emplace_back(5.0F, 0.01F * static_cast<float>(i), 0.0F);
    s.ring.push_back(ring);
  }
  io::CloudFile cloud;
  cloud.table = io::from_scan(s);
  io::write_cloud(scan, cloud);
}

struct BadInput {
  std::string name;
  std::function<void(const fs::path& data)> spoil;
  std::string file;   ///< relative to the dataset: the message must name it
  std::string field;  ///< ... and this
};

void PrintTo(const BadInput& bad, std::ostream* out) { *out << bad.name; }

class CliBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(CliBadInput, IsExitThreeNamingFileAndFieldAndWritesNothing) {
  const BadInput& bad = GetParam();
  const fs::path dir = scratch_dir();
  const fs::path data = copy_of_small_dataset(dir / "data");
  bad.spoil(data);
  const auto before = folder_checksums(data);
  const fs::path previous = dir / "previous";  // an earlier run folder, which a failed run must leave as it was
  fs::create_directories(previous);
  write_text(previous / "run.json", R"({"tool": "mlidar", "command": "odometry"})");
  write_text(previous / "trajectory.tum", "0 0 0 0 0 0 0 1\n");
  const auto previous_before = folder_checksums(previous);
  for (const std::string command : {"odometry", "slam --calibrate fixed", "calibrate auto"}) {
    for (const fs::path& out : {dir / "run", previous}) {
      const CliResult r = run_cli(command + " --dataset " + quoted(data.string()) + " --out " + quoted(out.string()));
      EXPECT_EQ(r.exit_code, 3) << command << ": " << r.output;
      EXPECT_NE(r.output.find((data / bad.file).string()), std::string::npos) << command << ": " << r.output;
      EXPECT_NE(r.output.find(bad.field), std::string::npos) << command << ": " << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "run"));
    EXPECT_TRUE(entries_containing(dir, ".mlidar-stage-").empty());
  }
  // `doctor` finds it before a run, with the same message (exit 1: a run would fail).
  const CliResult doctor = run_cli("doctor " + quoted(data.string()));
  EXPECT_EQ(doctor.exit_code, 1) << doctor.output;
  EXPECT_NE(doctor.output.find("failure"), std::string::npos) << doctor.output;
  EXPECT_NE(doctor.output.find((data / bad.file).string()), std::string::npos) << doctor.output;
  EXPECT_NE(doctor.output.find(bad.field), std::string::npos) << doctor.output;
  EXPECT_EQ(folder_checksums(data), before);
  EXPECT_EQ(folder_checksums(previous), previous_before);
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

void edit_yaml(const fs::path& data, const std::string& from, const std::string& to) {
  write_text(data / "dataset.yaml", replaced(read_text(data / "dataset.yaml"), from, to));
}

void keep_stamps(const fs::path& data, std::size_t count) {
  std::istringstream in(read_text(data / "times.txt"));
  std::string out, line;
  for (std::size_t i = 0; i < count && std::getline(in, line); ++i) out += line + "\n";
  write_text(data / "times.txt", out);
}

INSTANTIATE_TEST_SUITE_P(
    Datasets, CliBadInput,
    ::testing::Values(BadInput{"empty_times", [](const fs::path& d) { keep_stamps(d, 0); }, "times.txt", "no stamp"},
                      BadInput{"short_times", [](const fs::path& d) { keep_stamps(d, 11); }, "times.txt", "12 clouds for 11 stamps"},
                      BadInput{"no_base", [](const fs::path& d) { edit_yaml(d, "base: left\n", ""); }, "dataset.yaml", "base: missing"},
                      BadInput{"unknown_base", [](const fs::path& d) { edit_yaml(d, "base: left", "base: top"); }, "dataset.yaml",
                               "base: names no LiDAR"},
                      BadInput{"duplicate_key", [](const fs::path& d) { edit_yaml(d, "base: left\n", "base: left\nbase: right\n"); },
                               "dataset.yaml", "base: given twice"},
                      BadInput{"unsorted_angles",
                               [](const fs::path& d) { edit_yaml(d, "vertical_angles_deg: [-15, -13", "vertical_angles_deg: [-13, -15"); },
                               "dataset.yaml", "lidars[0].vertical_angles_deg[1]"},
                      BadInput{"max_below_min", [](const fs::path& d) { edit_yaml(d, "max_range: 100", "max_range: 0.1"); }, "dataset.yaml",
                               "lidars[0].max_range"},
                      BadInput{"negative_times", [](const fs::path& d) { retime(d / "scans/left/000004.pcd", 1.0, -5.0); },
                               "scans/left/000004.pcd", "field t"},
                      BadInput{"times_over_10s", [](const fs::path& d) { retime(d / "scans/right/000006.pcd", 100.0, 0.0); },
                               "scans/right/000006.pcd", "field t"},
                      BadInput{"uint8_times",
                               [](const fs::path& d) {
                                 io::CloudFile cloud = io::read_cloud(d / "scans/left/000003.pcd");
                                 io::FieldColumn& t = *cloud.table.find("t");
                                 t.type = io::ScalarType::kU8;
                                 t.data.assign(cloud.table.num_points, std::byte{1});
                                 io::write_cloud(d / "scans/left/000003.pcd", cloud);
                               },
                               "scans/left/000003.pcd", "cannot hold a per-point time"}),
    [](const auto& info) { return info.param.name; });

TEST(CliSkippedScans, AnUnusableScanIsReportedAndTheBaseLosingMostFailsTheJob) {
  const fs::path dir = scratch_dir();
  const fs::path data = copy_of_small_dataset(dir / "data");
  replace_scan(data / "scans/right/000005.pcd", 0, 0);  // empty
  replace_scan(data / "scans/left/000007.pcd", 50, 3);  // fine (50 points, ring 3)
  CliResult r = run_cli("odometry --dataset " + quoted(data.string()) + " --out " + quoted((dir / "run").string()));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("right: 1 of 12 frames without a usable scan (frame 5: 1 empty)"), std::string::npos) << r.output;
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(dir / "run" / "metrics.json"));
  ASSERT_EQ(metrics["skipped_scans"].size(), 1U) << metrics["skipped_scans"];
  EXPECT_EQ(metrics["skipped_scans"][0]["frame"], 5);
  EXPECT_EQ(metrics["skipped_scans"][0]["lidar"], "right");
  EXPECT_EQ(metrics["skipped_scans"][0]["reason"], "empty");
  // The base LiDAR with rings beyond its model in 4 of 12 frames (33 % > 20 %): exit 1, said why.
  for (const int k : {1, 2, 3, 4}) replace_scan(data / "scans/left" / ("00000" + std::to_string(k) + ".pcd"), 100, 40);
  for (const std::string command : {"odometry", "slam --calibrate fixed"}) {
    r = run_cli(command + " --dataset " + quoted(data.string()) + " --out " + quoted((dir / "run").string()));
    EXPECT_EQ(r.exit_code, 1) << command << r.output;
    EXPECT_NE(r.output.find("the base LiDAR left has no usable scan in 4 of 12 frames"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("ring values 40-40 beyond the model's 16 rows"), std::string::npos) << r.output;
  }
  r = run_cli("odometry --max-base-gaps 0.5 --dataset " + quoted(data.string()) + " --out " + quoted((dir / "run").string()));
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

// Every LiDAR without a scan in the last two frames: those frames are lost, their poses predictions whose doubt grows
// with each; the note on the last pose says so instead of printing its sigma as an estimate's.
TEST(CliSkippedScans, TheLastPoseOfARunEndingInLostFramesIsCalledAPrediction) {
  const fs::path dir = scratch_dir();
  const fs::path data = copy_of_small_dataset(dir / "data");
  for (const char* lidar : {"left", "right"})
    for (const char* frame : {"000010.pcd", "000011.pcd"}) replace_scan(data / "scans" / lidar / frame, 0, 0);
  for (const std::string command : {"odometry", "slam --calibrate fixed"}) {
    const CliResult r =
        run_cli(command + " --max-base-gaps 0.5 --dataset " + quoted(data.string()) + " --out " + quoted((dir / "run").string()));
    EXPECT_EQ(r.exit_code, 1) << command << r.output;
    EXPECT_NE(r.output.find("2 lost"), std::string::npos) << command << r.output;
    EXPECT_NE(r.output.find(": a prediction, not an estimate (the last 2 frame(s) were lost"), std::string::npos) << command << r.output;
  }
}

// The roof LiDAR of a car at 7.5 m/s without scans for 0.8 s after its first: its velocity was never measured, and
// from the start's pose the registrations fail. After 5 in a row the next frame starts a new local map: warned,
// metrics.json map_restarts, exit 1; the frames after it are registered again.
TEST(CliSkippedScans, FailedRegistrationsInARowStartANewLocalMap) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "sim";
  ASSERT_EQ(
      run_cli("simulate drive --rig rv --scene campus --trajectory vehicle --frames 24 --seed 2 --out " + quoted(sim.string())).exit_code,
      0);
  for (int k = 1; k <= 8; ++k) replace_scan(sim / "scans/top" / ("00000" + std::to_string(k) + ".pcd"), 0, 0);
  const CliResult r =
      run_cli("odometry --lidars top --threads 1 --dataset " + quoted(sim.string()) + " --out " + quoted((dir / "run").string()));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("warning: the local map was started again at frame 14, after 5 failed registrations in a row"), std::string::npos)
      << r.output;
  const nlohmann::json metrics = nlohmann::json::parse(std::ifstream(dir / "run" / "metrics.json"));
  EXPECT_EQ(metrics["map_restarts"], nlohmann::json::array({14})) << metrics["map_restarts"];
  EXPECT_EQ(metrics["lost_frames"], 14);  // 8 without a scan, 5 failed, the restart frame
  for (std::size_t k = 15; k < 24; ++k) EXPECT_FALSE(metrics["per_frame"][k]["lost"].get<bool>()) << "frame " << k;
  EXPECT_TRUE(metrics["per_frame"][14]["map_restarted"].get<bool>());
}

TEST(CliOptions, NumbersOutOfRangeAreExitTwoNamingTheOptionAndWriteNothing) {
  const fs::path dir = scratch_dir();
  const std::string data = quoted(small_dataset().string());
  const std::string out = " --out " + quoted((dir / "run").string());
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"odometry --dataset " + data + " --threads 2147483647" + out, "--threads"},
      {"slam --dataset " + data + " --threads -1" + out, "--threads"},
      {"odometry --scans " + quoted((small_dataset() / "scans/left").string()) + " --period 1e308" + out, "--period"},
      {"odometry --scans " + quoted((small_dataset() / "scans/left").string()) + " --period 0" + out, "--period"},
      {"simulate drive --perturb nan,nan" + out, "--perturb"},
      {"simulate drive --perturb 1,inf" + out, "--perturb"},
      {"simulate drive --frames -3" + out, "--frames"},
      {"calibrate auto --dataset " + data + " --max-base-gaps 1.5" + out, "--max-base-gaps"},
      {"eval traj --gt a.tum --est b.tum --delta 0", "--delta"}};
  for (const auto& [arguments, option] : cases) {
    const CliResult r = run_cli(arguments);
    EXPECT_EQ(r.exit_code, 2) << arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(option), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "run"));
}

TEST(CliConfigFiles, EveryConfigErrorIsExitThreeNamingFileAndKey) {
  const fs::path dir = scratch_dir();
  const std::string data = quoted(small_dataset().string());
  write_text(dir / "planes.yaml", "inlier_distance: 50\n");
  write_text(dir / "mloam.yaml", "window:\n  size: 5\n  size: 6\n");
  write_text(dir / "auto.yaml", "pair_stride: 5\npair_stride: 6\n");
  const std::string corner = quoted((dir / "no.pcd").string());
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"calibrate planes --ref " + corner + " --target " + corner + " --config " + quoted((dir / "planes.yaml").string()) + " --out " +
           quoted((dir / "x.yaml").string()),
       "planes.yaml", "inlier_distance: expected 0 < metres < 10"},
      {"slam --dataset " + data + " --config " + quoted((dir / "mloam.yaml").string()) + " --out " + quoted((dir / "r").string()),
       "mloam.yaml", "window.size: given twice"},
      {"calibrate auto --dataset " + data + " --config " + quoted((dir / "auto.yaml").string()) + " --out " + quoted((dir / "r").string()),
       "auto.yaml", "pair_stride: given twice"}};
  for (const auto& [arguments, file, key] : cases) {
    const CliResult r = run_cli(arguments);
    EXPECT_EQ(r.exit_code, 3) << arguments << "\n" << r.output;
    EXPECT_NE(r.output.find((dir / file).string() + ": " + key), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "r"));
}

TEST(CliInputs, StandardInputAndProcessSubstitutionAreReadOnce) {
  const std::string gt = quoted((small_dataset() / "groundtruth" / "trajectory.tum").string());
  const std::string scan = quoted((small_dataset() / "scans/left/000000.pcd").string());
  CliResult r = run_shell("cat " + scan + " | " + mlidar_bin() + " info -");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fields    x:float32 y:float32 z:float32 intensity:float32 ring:uint16 t:float64"), std::string::npos)
      << r.output;
  r = run_shell("bash -c " + quoted(mlidar_bin() + " eval traj --gt <(cat " + gt + ") --est <(cat " + gt + ")"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("12"), std::string::npos) << r.output;
  r = run_shell("cat " + gt + " | " + mlidar_bin() + " eval traj --gt - --est " + gt);
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

/// metrics.json without the keys that hold times.
nlohmann::json without_timing(nlohmann::json json) {
  for (const char* key : {"stages", "total_seconds"}) json.erase(key);
  for (auto& frame : json["per_frame"]) frame.erase("seconds");
  return json;
}

TEST(CliDeterminism, RunsAreByteIdenticalExceptTimingWhateverTheThreads) {
  // The parallel reductions sum fixed chunks (tbb::parallel_deterministic_reduce): 1 and 2 threads give the same bytes.
  const fs::path dir = scratch_dir();
  for (const auto& [run, threads] : {std::pair{"a", "1"}, std::pair{"b", "1"}, std::pair{"c", "2"}})
    ASSERT_EQ(run_cli(std::string("slam --calibrate fixed --threads ") + threads + " --dataset " + quoted(small_dataset().string()) +
                      " --out " + quoted((dir / run).string()))
                  .exit_code,
              0);
  const auto metrics = [&](const char* run) { return without_timing(nlohmann::json::parse(std::ifstream(dir / run / "metrics.json"))); };
  for (const char* other : {"b", "c"}) {
    for (const char* file : {"trajectory.tum", "trajectory.kitti", "map.ply", "extrinsics.yaml"})
      EXPECT_EQ(read_text(dir / "a" / file), read_text(dir / other / file)) << file << " of run " << other;
    EXPECT_EQ(metrics("a"), metrics(other)) << other;
  }
}

/// The finding line of `check` (and LiDAR) in doctor's output, or empty.
std::string finding(const std::string& output, const std::string& check) {
  const std::size_t at = output.find("  " + check + ": ");
  if (at == std::string::npos) return {};
  const std::size_t start = output.rfind('\n', at) == std::string::npos ? 0 : output.rfind('\n', at) + 1;
  return output.substr(start, output.find('\n', at) - start);
}

TEST(CliDoctor, SaysWhetherTheMotionIsEnoughForHandEye) {
  // The base's own odometry: a rig that stands still does not turn; a ground vehicle turns about its z only.
  const fs::path dir = scratch_dir();
  ASSERT_EQ(
      run_cli("simulate drive --rig rhd --scene room --trajectory static --frames 8 --seed 1 --out " + quoted((dir / "static").string()))
          .exit_code,
      0);
  const CliResult still = run_cli("doctor " + quoted((dir / "static").string()));
  EXPECT_EQ(still.exit_code, 0) << "a warning, not a failure: odometry needs no turns\n" << still.output;
  const std::string still_motion = finding(still.output, "motion left");
  EXPECT_EQ(still_motion.rfind("warning", 0), 0u) << still.output;
  EXPECT_NE(still_motion.find("needs turns"), std::string::npos) << still.output;
  EXPECT_NE(still_motion.find("--calibrate refine or fixed"), std::string::npos) << still.output;

  ASSERT_EQ(run_cli("simulate drive --rig single-vlp16 --scene campus --trajectory vehicle --frames 60 --seed 1 --out " +
                    quoted((dir / "vehicle").string()))
                .exit_code,
            0);
  const CliResult vehicle = run_cli("doctor " + quoted((dir / "vehicle").string()));
  EXPECT_EQ(vehicle.exit_code, 0) << vehicle.output;
  const std::string planar = finding(vehicle.output, "motion lidar");
  EXPECT_EQ(planar.rfind("warning", 0), 0u) << vehicle.output;
  EXPECT_NE(planar.find("every turn is about the base's z (up-down) (planar motion)"), std::string::npos) << vehicle.output;
}

TEST(CliDoctor, NamesWhatWouldMisleadARunWithItsFixAndExitsOneOnlyForFailures) {
  const fs::path dir = scratch_dir();
  CliResult clean = run_cli("doctor " + quoted(small_dataset().string()) + " --json " + quoted((dir / "clean.json").string()));
  EXPECT_EQ(clean.exit_code, 0) << clean.output;
  EXPECT_EQ(clean.output.find("warning"), std::string::npos) << clean.output;
  EXPECT_NE(finding(clean.output, "overlap right").rfind("ok", 0), std::string::npos) << clean.output;
  EXPECT_NE(finding(clean.output, "motion left").find("enough for hand-eye"), std::string::npos) << clean.output;  // handheld
  const nlohmann::json json = nlohmann::json::parse(std::ifstream(dir / "clean.json"));
  EXPECT_FALSE(json["failed"].get<bool>());
  EXPECT_GE(json["findings"].size(), 8u);

  const fs::path data = copy_of_small_dataset(dir / "data");
  replace_scan(data / "scans/right/000005.pcd", 0, 0);   // empty: skipped by the jobs
  replace_scan(data / "scans/right/000007.pcd", 50, 3);  // no per-point time
  Scan mixed;                                            // half its points on a ring beyond the VLP-16's 16, no per-point time either
  for (int i = 0; i < 60; ++i) {
    mixed.points.emplace_back(5.0F, 0.01F * static_cast<float>(i), 0.0F);
    mixed.ring.push_back(i % 2 == 0 ? 3 : 20);
  }
  io::write_cloud(data / "scans/right/000008.pcd",
                  io::CloudFile{io::CloudFormat::kPcd, "binary", {0, 0, 0, 1, 0, 0, 0}, io::from_scan(mixed)});
  edit_yaml(data, "translation: [0, -0.477, -0.22]", "translation: [0, -477, -220]");  // millimetres
  std::istringstream in(read_text(data / "times.txt"));                                // a 1 s hole before frame 9
  std::string stamps, line;
  for (int k = 0; std::getline(in, line); ++k) {
    char text[64];
    std::snprintf(text, sizeof text, "%.9f", std::stod(line) + (k >= 9 ? 1.0 : 0.0));
    stamps += std::string(text) + "\n";
  }
  write_text(data / "times.txt", stamps);
  const CliResult r = run_cli("doctor " + quoted(data.string()));
  EXPECT_EQ(r.exit_code, 0) << "warnings only\n" << r.output;
  EXPECT_NE(finding(r.output, "stamps").find("1 gap(s)"), std::string::npos) << r.output;
  EXPECT_NE(finding(r.output, "stamps").find("frame(s) 9"), std::string::npos) << r.output;
  EXPECT_NE(finding(r.output, "scans right").find("frame 5"), std::string::npos) << r.output;
  EXPECT_NE(finding(r.output, "time right").find("2 of 11 scans without per-point times"), std::string::npos) << r.output;
  EXPECT_NE(finding(r.output, "rings right").find("ring values reach 20 for a model of 16 rows"), std::string::npos) << r.output;
  EXPECT_NE(finding(r.output, "extrinsics right").find("check the units"), std::string::npos) << r.output;
  EXPECT_NE(finding(r.output, "overlap right").rfind("warning", 0), std::string::npos) << r.output;

  // No model (no vertical angles in dataset.yaml): the rows come from the ring field.
  const fs::path no_model = copy_of_small_dataset(dir / "no_model");
  const std::string angles = "    vertical_angles_deg: [-15, -13, -11, -9, -7, -5, -3, -1, 1, 3, 5, 7, 9, 11, 13, 15]\n";
  edit_yaml(no_model, angles, "");
  edit_yaml(no_model, angles, "");
  const CliResult unmodelled = run_cli("doctor " + quoted(no_model.string()));
  EXPECT_EQ(unmodelled.exit_code, 0) << unmodelled.output;
  EXPECT_NE(finding(unmodelled.output, "rings right").find("no model: 16 rings from the ring field"), std::string::npos)
      << unmodelled.output;

  // The base losing most of its scans: a failure, exit 1.
  for (int k = 0; k < 6; ++k) replace_scan(data / "scans/left" / ("00000" + std::to_string(k) + ".pcd"), 0, 0);
  const CliResult base = run_cli("doctor " + quoted(data.string()));
  EXPECT_EQ(base.exit_code, 1) << base.output;
  EXPECT_NE(finding(base.output, "scans left").find("the base LiDAR lacks a usable scan in 6 of 12 frames"), std::string::npos)
      << base.output;
  EXPECT_EQ(run_cli("doctor " + quoted((dir / "nothing").string())).exit_code, 2) << "no such input: usage";
}

}  // namespace
}  // namespace mlidar::test
