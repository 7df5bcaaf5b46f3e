// Real data: the three scenes of opencalib_3lidar (one frame each of top,
// left, right; the rig did not change between scenes). No answer key exists,
// so the property is consistency (issue 8): refined from initial_extrinsic.txt
// every scene converges and the three answers for left and for right agree
// within 0.3 deg and 5 cm, and their differences are consistent with the
// reported covariances. From the much worse perturbed_init guesses the
// refinement reaches the same answer or says it did not converge (one scene
// per side here; every scene: bench/pair_refine_scenes perturbed=1).
#include <algorithm>
#include <array>
#include <iostream>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "mlidar/calib/pair_refine.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/opencalib.hpp"
#include "pose_error.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

constexpr double kAgreeDeg = 0.3;   // perturbed guess vs initial guess, same scene
constexpr double kScenesDeg = 0.3;  // across scenes: the criterion (see ThreeScenesAgree)
constexpr double kAgreeM = 0.05;
constexpr double kChi2Six99 = 16.81;  // chi-square, 6 dof, 0.99 quantile
const std::array<std::string, 3> kScenes{"0001", "0002", "0003"};

fs::path scene_dir(const std::string& scene) { return shared_data() / "real" / "opencalib_3lidar" / scene; }

/// device id -> cloud file, from lidar_cloud_path.txt ("device_id: N" then "path: data/SCENE/FILE").
std::map<int, fs::path> device_clouds(const std::string& scene) {
  return io::read_opencalib_cloud_paths(scene_dir(scene) / "lidar_cloud_path.txt");
}

/// The device id whose cloud file name starts with `name` ("left", "right").
int device_of(const std::map<int, fs::path>& clouds, const std::string& name) {
  for (const auto& [id, path] : clouds)
    if (path.filename().string().rfind(name, 0) == 0) return id;
  return -1;
}

std::vector<Eigen::Vector3f> points_of(const fs::path& file) { return io::to_scan(io::read_cloud(file).table, file.string()).points; }

struct SceneClouds {
  std::vector<Eigen::Vector3f> top, left, right;
  int left_id = -1, right_id = -1;
};

const SceneClouds& clouds_of(const std::string& scene) {
  static std::map<std::string, SceneClouds> cache;  // the clouds are read once per test program
  auto [it, inserted] = cache.try_emplace(scene);
  if (inserted) {
    const auto devices = device_clouds(scene);
    it->second.left_id = device_of(devices, "left");
    it->second.right_id = device_of(devices, "right");
    it->second.top = points_of(devices.at(0));
    it->second.left = points_of(devices.at(it->second.left_id));
    it->second.right = points_of(devices.at(it->second.right_id));
  }
  return it->second;
}

SE3 guess_of(const fs::path& init_file, int device) {
  const io::Extrinsics guesses = io::read_opencalib_initial_extrinsics(init_file);
  return guesses.find("device_" + std::to_string(device))->T_base_lidar;
}

calib::PairRefineResult refine(const std::string& scene, const std::string& side, const fs::path& init_file) {
  const SceneClouds& c = clouds_of(scene);
  const bool left = side == "left";
  return calib::refine_pair(c.top, left ? c.left : c.right, guess_of(init_file, left ? c.left_id : c.right_id));
}

void print(const std::string& scene, const std::string& side, const std::string& init, const calib::PairRefineResult& r) {
  const Vec3 rpy = rpy_deg_from_quat(r.T_ref_target.rotation());
  const Vec3& t = r.T_ref_target.translation();
  std::cout << scene << ' ' << side << ' ' << init << ' ' << to_string(r.verdict) << " rpy " << rpy.transpose() << " t " << t.transpose()
            << " rmse " << r.rmse << " overlap " << r.overlap.fraction_b << " omega " << r.overlap.omega() << " sd " << r.rotation_sd_deg
            << " deg " << r.translation_sd_m << " m, start " << r.chosen_start;
  for (const auto& reason : r.reasons) std::cout << " [" << reason << ']';
  std::cout << '\n';
}

/// The refined answer of every scene and side from initial_extrinsic.txt, computed once.
const calib::PairRefineResult& initial_answer(const std::string& scene, const std::string& side) {
  static std::map<std::string, calib::PairRefineResult> cache;
  auto [it, inserted] = cache.try_emplace(scene + side);
  if (inserted) {
    it->second = refine(scene, side, scene_dir(scene) / "initial_extrinsic.txt");
    print(scene, side, "initial", it->second);
  }
  return it->second;
}

struct Spread {
  double deg = 0.0;
  double m = 0.0;
};

Spread max_pairwise(const std::vector<SE3>& poses) {
  Spread spread;
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      spread.deg = std::max(spread.deg, rotation_error_deg(poses[i], poses[j]));
      spread.m = std::max(spread.m, (poses[i].translation() - poses[j].translation()).norm());
    }
  return spread;
}

class RealPairRefine : public ::testing::TestWithParam<std::string> {};

// Issue 8's criterion is 0.3 deg / 5 cm. Measured (Release, symmetric answer):
// left 0.285 deg / 3.1 cm, right 0.279 deg / 3.1 cm: met, with a thin margin
// (target->reference alone gave left 0.44 deg; docs/benchmarks.md has the
// diagnostics). The difference of two scenes' answers must fit
// their summed covariance (NEES below the chi-square 99% bound): the reported
// covariance carries the per-scene systematic term, the ICP's alone does not.
Vec6 difference(const SE3& a, const SE3& b) {
  Vec6 d;
  d << a.translation() - b.translation(), so3_log(a.rotation() * b.rotation().inverse());
  return d;
}
TEST_P(RealPairRefine, ThreeScenesAgree) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const std::string side = GetParam();
  std::vector<SE3> answers;
  for (const std::string& scene : kScenes) {
    const calib::PairRefineResult& r = initial_answer(scene, side);
    EXPECT_NE(r.verdict, calib::PairVerdict::kNotConverged) << scene << ' ' << side;
    answers.push_back(r.T_ref_target);
  }
  for (std::size_t i = 0; i < kScenes.size(); ++i)
    for (std::size_t j = i + 1; j < kScenes.size(); ++j) {
      const calib::PairRefineResult& a = initial_answer(kScenes[i], side);
      const calib::PairRefineResult& b = initial_answer(kScenes[j], side);
      const Vec6 d = difference(a.T_ref_target, b.T_ref_target);
      const double nees = d.dot((a.covariance + b.covariance).ldlt().solve(d));
      const double nees_icp = d.dot((a.covariance_icp + b.covariance_icp).ldlt().solve(d));
      std::cout << side << ' ' << kScenes[i] << '-' << kScenes[j] << " NEES of the difference " << nees << " (ICP covariance alone "
                << nees_icp << ")\n";
      EXPECT_LT(nees, kChi2Six99) << side << ' ' << kScenes[i] << '-' << kScenes[j];
    }
  const Spread spread = max_pairwise(answers);
  std::cout << side << " max pairwise difference " << spread.deg << " deg, " << spread.m << " m\n";
  EXPECT_LT(spread.deg, kScenesDeg);
  EXPECT_LT(spread.m, kAgreeM);
}

TEST_P(RealPairRefine, PerturbedGuessesReachTheSameAnswerOrSayNot) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const std::string side = GetParam();
  // One scene per side keeps the test short: the worst guess of each side (left
  // 0002: roll -63 deg; right 0001: roll 54, yaw 37 deg off). Every scene and
  // side: bench/pair_refine_scenes perturbed=1.
  for (const std::string& scene : {side == "left" ? std::string("0002") : std::string("0001")}) {
    const fs::path perturbed = shared_data() / "real" / "opencalib_3lidar" / "perturbed_init" / (scene + ".txt");
    const calib::PairRefineResult r = refine(scene, side, perturbed);
    print(scene, side, "perturbed", r);
    if (r.verdict == calib::PairVerdict::kNotConverged) {
      EXPECT_FALSE(r.reasons.empty());  // said so clearly: allowed
      continue;
    }
    const SE3& answer = initial_answer(scene, side).T_ref_target;
    EXPECT_LT(rotation_error_deg(r.T_ref_target, answer), kAgreeDeg) << scene << ' ' << side;
    EXPECT_LT((r.T_ref_target.translation() - answer.translation()).norm(), kAgreeM) << scene << ' ' << side;
  }
}

INSTANTIATE_TEST_SUITE_P(LeftRight, RealPairRefine, ::testing::Values("left", "right"));

}  // namespace
}  // namespace mlidar::test
