// Extrinsics YAML (round trip, one test per rejection) and the OpenCalib readers.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "format_test_util.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/opencalib.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {
using test::expect_input_error;

Extrinsics random_extrinsics(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Extrinsics extrinsics;
  extrinsics.base = "base_link";
  for (const char* name : {"top", "front left", "rear"}) {
    Vec6 xi;
    for (int k = 0; k < 6; ++k) xi(k) = normal(rng);
    Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::NullaryExpr([&] { return 0.01 * normal(rng); });
    const Mat6 covariance = a * a.transpose();  // symmetric positive semi-definite by construction
    extrinsics.lidars.push_back({name, SE3::exp(xi), std::string(name) == "rear" ? std::optional<Mat6>{} : covariance});
  }
  return extrinsics;
}

TEST(ExtrinsicsRoundTrip, WithinTolerance1e12) {
  const Extrinsics extrinsics = random_extrinsics(11);
  const auto path = test::scratch_dir() / "extrinsics.yaml";
  write_extrinsics(path, extrinsics);
  const Extrinsics back = read_extrinsics(path);
  EXPECT_EQ(back.base, "base_link");
  ASSERT_EQ(back.lidars.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& a = extrinsics.lidars[i];
    const auto& b = back.lidars[i];
    EXPECT_EQ(b.name, a.name);
    EXPECT_LT((a.T_base_lidar.translation() - b.T_base_lidar.translation()).norm(), 1e-12);
    EXPECT_LT(a.T_base_lidar.rotation().angularDistance(b.T_base_lidar.rotation()), 1e-12);
    ASSERT_EQ(a.covariance.has_value(), b.covariance.has_value());
    if (a.covariance) {
      EXPECT_EQ(*a.covariance, *b.covariance);
    }
  }
  EXPECT_EQ(back.find("front left"), &back.lidars[1]);
  EXPECT_EQ(back.find("nobody"), nullptr);
}

std::string doc(const std::string& top_fields) { return "base: base\nlidars:\n  top:\n" + top_fields; }
const std::string kT = "    translation: [1, 2, 3]\n";
const std::string kQ = "    quaternion_wxyz: [1, 0, 0, 0]\n";

std::string covariance_yaml(const Mat6& c) {
  std::string text = "    covariance: [";
  for (int k = 0; k < 36; ++k) text += (k ? ", " : "") + std::to_string(c(k / 6, k % 6));
  return text + "]\n";
}

TEST(ExtrinsicsRejects, UnknownKeysAtEveryLevel) {
  expect_input_error([] { parse_extrinsics(doc(kT + kQ) + "extra: 1\n", "e.yaml"); }, {"e.yaml", "extra", "unknown key"});
  expect_input_error([] { parse_extrinsics(doc(kT + kQ + "    rotation: [1]\n"), "e.yaml"); },
                     {"e.yaml", "lidars.top.rotation", "unknown key"});
}

TEST(ExtrinsicsRejects, MissingTranslationOrQuaternion) {
  expect_input_error([] { parse_extrinsics(doc(kQ), "e.yaml"); }, {"e.yaml", "lidars.top.translation", "missing"});
  expect_input_error([] { parse_extrinsics(doc(kT), "e.yaml"); }, {"e.yaml", "lidars.top.quaternion_wxyz", "missing"});
}

TEST(ExtrinsicsRejects, WrongLengthsAndNonNumbers) {
  expect_input_error([] { parse_extrinsics(doc("    translation: [1, 2]\n" + kQ), "e.yaml"); },
                     {"e.yaml", "lidars.top.translation", "3 numbers, found 2"});
  expect_input_error([] { parse_extrinsics(doc(kT + "    quaternion_wxyz: [1, 0, 0]\n"), "e.yaml"); },
                     {"e.yaml", "lidars.top.quaternion_wxyz", "4 numbers"});
  expect_input_error([] { parse_extrinsics(doc("    translation: [1, a, 3]\n" + kQ), "e.yaml"); },
                     {"e.yaml", "lidars.top.translation[1]", "'a'"});
}

TEST(ExtrinsicsRejects, NonFinite) {
  expect_input_error([] { parse_extrinsics(doc("    translation: [1, nan, 3]\n" + kQ), "e.yaml"); },
                     {"e.yaml", "lidars.top.translation[1]", "finite"});
}

TEST(ExtrinsicsRejects, NonUnitQuaternion) {
  expect_input_error([] { parse_extrinsics(doc(kT + "    quaternion_wxyz: [1.00001, 0, 0, 0]\n"), "e.yaml"); },
                     {"e.yaml", "lidars.top.quaternion_wxyz", "norm"});
  EXPECT_NO_THROW(parse_extrinsics(doc(kT + "    quaternion_wxyz: [1.0000001, 0, 0, 0]\n"), "e.yaml"));
}

TEST(ExtrinsicsRejects, CovarianceWrongSizeAsymmetricOrIndefinite) {
  expect_input_error([] { parse_extrinsics(doc(kT + kQ + "    covariance: [1, 2]\n"), "e.yaml"); },
                     {"e.yaml", "lidars.top.covariance", "36 numbers"});
  Mat6 asymmetric = Mat6::Identity();
  asymmetric(0, 1) = 0.1;
  expect_input_error([&] { parse_extrinsics(doc(kT + kQ + covariance_yaml(asymmetric)), "e.yaml"); },
                     {"e.yaml", "lidars.top.covariance", "not symmetric"});
  Mat6 indefinite = Mat6::Identity();
  indefinite(2, 2) = -0.5;
  expect_input_error([&] { parse_extrinsics(doc(kT + kQ + covariance_yaml(indefinite)), "e.yaml"); },
                     {"e.yaml", "lidars.top.covariance", "positive semi-definite"});
}

TEST(ExtrinsicsRejects, DuplicateAndEmptyLidars) {
  const std::string twice = doc(kT + kQ) + "  top:\n" + kT + kQ;
  expect_input_error([&] { parse_extrinsics(twice, "e.yaml"); }, {"e.yaml", "lidars.top", "given twice"});
  expect_input_error([] { parse_extrinsics("base: b\nlidars: {}\n", "e.yaml"); }, {"e.yaml", "lidars", "non-empty"});
  expect_input_error([] { parse_extrinsics("base: b\n", "e.yaml"); }, {"e.yaml", "lidars", "missing"});
}

TEST(ExtrinsicsRejects, InvalidYamlBecomesInputError) {
  expect_input_error([] { parse_extrinsics("lidars: [unclosed\n", "e.yaml"); }, {"e.yaml", "not valid YAML"});
  expect_input_error([] { parse_extrinsics("", "e.yaml"); }, {"e.yaml", "mapping"});
}

TEST(OpenCalibRealData, InitialExtrinsicsOfThreeScenes) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto folder = test::shared_data() / "real/opencalib_3lidar";
  for (const char* scene : {"0001", "0002", "0003"}) {
    const Extrinsics e = read_opencalib_initial_extrinsics(folder / scene / "initial_extrinsic.txt", {"top", "left", "right"});
    EXPECT_EQ(e.base, "top");
    ASSERT_EQ(e.lidars.size(), 3u);
    EXPECT_LT(e.lidars[0].T_base_lidar.log().norm(), 1e-12);
    // left: yaw +90 deg, so its x axis points along the top LiDAR's y axis; it sits on the +y side.
    const Mat3 r_left = e.lidars[1].T_base_lidar.rotation_matrix();
    EXPECT_LT((r_left.col(0) - Vec3::UnitY()).norm(), 1e-12) << scene;
    EXPECT_GT(e.lidars[1].T_base_lidar.translation().y(), 0.3);
    EXPECT_LT(e.lidars[2].T_base_lidar.translation().y(), -0.3);
  }
  // Perturbed guesses: same translations; R = Rz(yaw) Ry(pitch) Rx(roll) gives (R e_z).z = cos(pitch) cos(roll).
  const Extrinsics perturbed = read_opencalib_initial_extrinsics(folder / "perturbed_init/0001.txt");
  const Extrinsics initial = read_opencalib_initial_extrinsics(folder / "0001/initial_extrinsic.txt");
  EXPECT_EQ(perturbed.base, "device_0");
  EXPECT_EQ(perturbed.lidars[1].T_base_lidar.translation(), initial.lidars[1].T_base_lidar.translation());
  const double deg = M_PI / 180.0;
  EXPECT_NEAR(perturbed.lidars[1].T_base_lidar.rotation_matrix()(2, 2), std::cos(0 * deg) * std::cos(-49 * deg), 1e-12);
  EXPECT_NEAR(perturbed.lidars[2].T_base_lidar.rotation_matrix()(2, 2), std::cos(3 * deg) * std::cos(54 * deg), 1e-12);
}

TEST(OpenCalibRealData, CloudPathsNameTheSceneClouds) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto scene = test::shared_data() / "real/opencalib_3lidar/0002";
  const auto clouds = read_opencalib_cloud_paths(scene / "lidar_cloud_path.txt");
  ASSERT_EQ(clouds.size(), 3u);
  for (const auto& [id, file] : clouds) {
    EXPECT_EQ(file.parent_path(), scene) << id;
    EXPECT_TRUE(std::filesystem::exists(file)) << file;
  }
  EXPECT_EQ(clouds.at(0).filename().string().rfind("top", 0), 0u) << clouds.at(0);  // device 0: the top LiDAR
}

TEST(OpenCalibRealData, P64ToQtJson) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const Extrinsics e = read_opencalib_json(test::shared_data() / "real/opencalib_p64_qt/p64-to-qt-extrinsic.json");
  EXPECT_EQ(e.base, "qt");
  ASSERT_EQ(e.lidars.size(), 2u);
  EXPECT_EQ(e.lidars[0].name, "qt");
  EXPECT_EQ(e.lidars[1].name, "p64");
  // The file's rotation block is only approximately orthonormal (max |R^T R - I| = 0.021):
  // the reader projects it onto the nearest rotation, which stays close to it.
  Mat3 r_file;
  r_file << 0.504271, -0.718711, -0.457892, 0.604509, 0.67629, -0.394462, 0.598991, -0.0777196, 0.783179;
  const Mat3 r = e.lidars[1].T_base_lidar.rotation_matrix();
  EXPECT_LT((r - r_file).cwiseAbs().maxCoeff(), 0.02);
  EXPECT_LT((r.transpose() * r - Mat3::Identity()).norm(), 1e-12);
  EXPECT_EQ(e.lidars[1].T_base_lidar.translation(), Vec3(-1.87468, -1.86523, -0.527022));
}

TEST(OpenCalibRejects, TextAndJson) {
  expect_input_error([] { parse_opencalib_initial_extrinsics("device_id: 1\n(Roll,Pitch,Yaw,tx,ty,tz): 0 0 0 0 0 0\n", "i.txt"); },
                     {"i.txt", "device_id 0", "missing"});
  expect_input_error([] { parse_opencalib_initial_extrinsics("device_id: 0\n(Roll,Pitch,Yaw,tx,ty,tz): 0 0 0 0 0\n", "i.txt"); },
                     {"i.txt", "line 2", "6 numbers"});
  expect_input_error([] { parse_opencalib_json("{\"a\": {\"sensor_name\": \"x\"}}", "j.json"); },
                     {"j.json", "a.target_sensor_name", "missing"});
  expect_input_error([] { parse_opencalib_json("{\"a\": ", "j.json"); }, {"j.json", "not valid JSON"});
  expect_input_error([] { parse_opencalib_cloud_paths("path: a.pcd\n", "p.txt", "."); }, {"p.txt", "line 1", "without a device_id"});
  expect_input_error([] { parse_opencalib_cloud_paths("device_id: 0\npath: a.pcd\ndevice_id: 0\n", "p.txt", "."); },
                     {"p.txt", "line 3", "appears twice"});
  expect_input_error([] { parse_opencalib_cloud_paths("device_id: 1\n", "p.txt", "."); }, {"p.txt", "device_id 1", "no path line"});
  expect_input_error([] { parse_opencalib_cloud_paths("device_id: 0\npath: data/..\n", "p.txt", "."); },
                     {"p.txt", "line 2", "cloud file name"});
}

}  // namespace
}  // namespace mlidar::io
