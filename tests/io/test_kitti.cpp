// KITTI .bin / label_2 / calib and the nuScenes 5-float .bin: real files,
// round trips and rejections.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "format_test_util.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/io/text_fields.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {
using test::bytes_of;
using test::expect_input_error;

std::filesystem::path real() { return test::shared_data() / "real"; }

TEST(KittiRealData, VelodyneScansHaveSizeOver16PointsAndUnitReflectance) {
  MLIDAR_REQUIRE_SHARED_DATA();
  for (const char* frame : {"000000", "000001", "000002"}) {
    const auto path = real() / "kitti_object/training/velodyne" / (std::string(frame) + ".bin");
    const PointTable table = read_kitti_bin(path);
    EXPECT_EQ(table.num_points, std::filesystem::file_size(path) / 16) << frame;
    ASSERT_NE(table.find("intensity"), nullptr);
    for (std::size_t i = 0; i < table.num_points; ++i) {
      const double r = table.find("intensity")->value(i);
      ASSERT_TRUE(r >= 0.0 && r <= 1.0) << frame << " point " << i << " reflectance " << r;
      ASSERT_TRUE(std::isfinite(table.find("x")->value(i)));
    }
  }
}

TEST(KittiRealData, LabelsMatchTheirTextAndFrame8HasSixCars) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto objects = read_kitti_labels(real() / "kitti_object/training/label_2/000000.txt");
  ASSERT_EQ(objects.size(), 1u);
  // The file's one line: Pedestrian 0.00 0 -0.20 712.40 143.00 810.73 307.92 1.89 0.48 1.20 1.84 1.47 8.41 0.01
  EXPECT_EQ(objects[0].type, "Pedestrian");
  EXPECT_EQ(objects[0].occluded, 0);
  EXPECT_DOUBLE_EQ(objects[0].bbox[2], 810.73);
  EXPECT_EQ(objects[0].dimensions, Eigen::Vector3d(1.89, 0.48, 1.20));
  EXPECT_EQ(objects[0].location, Eigen::Vector3d(1.84, 1.47, 8.41));
  EXPECT_DOUBLE_EQ(objects[0].rotation_y, 0.01);
  EXPECT_FALSE(objects[0].score.has_value());

  const auto frame8 = read_kitti_labels(real() / "kitti_000008/000008_label_2.txt");
  EXPECT_EQ(std::count_if(frame8.begin(), frame8.end(), [](const KittiObject& o) { return o.type == "Car"; }), 6);
  EXPECT_EQ(frame8.size(), 10u);
  EXPECT_EQ(frame8[0].occluded, 3);
  EXPECT_EQ(frame8.back().type, "DontCare");
}

TEST(KittiRealData, CalibValuesAndP2AgreeWithThe4x4File) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const KittiCalib c0 = read_kitti_calib(real() / "kitti_object/training/calib/000000.txt");
  EXPECT_DOUBLE_EQ(c0.P[2](0, 3), 45.75831);
  EXPECT_DOUBLE_EQ(c0.R0_rect(0, 0), 0.9999128);
  EXPECT_DOUBLE_EQ(c0.Tr_velo_to_cam(2, 3), -0.3321029);
  ASSERT_TRUE(c0.Tr_imu_to_velo.has_value());
  const Eigen::Matrix3d r = c0.Tr_velo_to_cam.leftCols<3>();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-5);  // a real rotation

  const KittiCalib c8 = read_kitti_calib(real() / "kitti_000008/000008_calib.txt");
  const std::string p2_text = read_file_text(real() / "kitti_000008/000008_P2_4x4.txt");
  const auto p2_tokens = split_tokens(p2_text);
  ASSERT_EQ(p2_tokens.size(), 16u);
  for (int k = 0; k < 12; ++k) {
    EXPECT_NEAR(c8.P[2](k / 4, k % 4), parse_double(p2_tokens[static_cast<std::size_t>(k)], "P2_4x4", ""), 1e-9) << k;
  }
}

TEST(KittiRealData, CroppedFrame8AndNuScenesKeyframe) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto cropped = real() / "kitti_000008/000008_velodyne_reduced.bin";
  EXPECT_EQ(read_kitti_bin(cropped).num_points, std::filesystem::file_size(cropped) / 16);

  const auto folder = real() / "nuscenes_keyframe";
  const auto bin = folder / "n015-2018-07-24-11-22-45+0800__LIDAR_TOP__1532402927647951.pcd.bin";
  const PointTable nu = read_kitti_bin(bin, 5);
  EXPECT_EQ(nu.num_points, std::filesystem::file_size(bin) / 20);
  const FieldColumn* ring = nu.find("ring");
  ASSERT_NE(ring, nullptr);
  std::array<int, 32> per_ring{};
  for (std::size_t i = 0; i < nu.num_points; ++i) {
    const double value = ring->value(i);
    ASSERT_TRUE(value >= 0 && value <= 31 && value == std::floor(value)) << "ring " << value << " at point " << i;
    ++per_ring[static_cast<std::size_t>(value)];
  }
  EXPECT_GT(std::count_if(per_ring.begin(), per_ring.end(), [](int n) { return n > 0; }), 28);  // HDL-32E: 32 rings

  // Boxes: '#' header lines, then one box of 12 columns per line.
  int boxes = 0;
  const std::string boxes_text = read_file_text(folder / "LIDAR_TOP_1532402927647951_boxes.txt");
  for (const auto& line : split_lines(boxes_text)) {
    const auto content = trim(line.text);
    if (content.empty() || content.front() == '#') continue;
    EXPECT_EQ(split_tokens(content).size(), 12u) << "line " << line.number;
    ++boxes;
  }
  EXPECT_EQ(boxes, 69);
}

TEST(KittiRoundTrip, BinLabelsAndCalibAreExact) {
  const auto dir = test::scratch_dir();
  PointTable table;
  table.num_points = 3;
  for (const char* name : {"x", "y", "z", "intensity"}) {
    FieldColumn& column = table.add_field(name, ScalarType::kF32);
    for (std::size_t i = 0; i < 3; ++i) {
      const float v = 0.1f * static_cast<float>(i + 1) + static_cast<float>(name[0]);
      std::memcpy(column.data.data() + 4 * i, &v, 4);
    }
  }
  write_kitti_bin(dir / "scan.bin", table);
  const PointTable bin = read_kitti_bin(dir / "scan.bin");
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(bin.fields[k].data, table.fields[k].data);

  KittiObject car{"Car", 0.12345678901234, 2, -1.0 / 3.0, {1.5, 2.25, 300.125, 400.0625}, {1.6, 1.7, 4.1}, {-2.7, 1.74, 3.68}, 0.1, 0.97};
  KittiObject dont_care;
  dont_care.type = "DontCare";
  write_kitti_labels(dir / "labels.txt", {car, dont_care});
  const auto labels = read_kitti_labels(dir / "labels.txt");
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].truncated, car.truncated);
  EXPECT_EQ(labels[0].alpha, car.alpha);
  EXPECT_EQ(labels[0].bbox, car.bbox);
  EXPECT_EQ(labels[0].location, car.location);
  EXPECT_EQ(labels[0].score, car.score);
  EXPECT_FALSE(labels[1].score.has_value());

  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1000.0, 1000.0);
  const auto random = [&] { return uniform(rng); };
  KittiCalib calib;
  for (auto& p : calib.P) p = Eigen::Matrix<double, 3, 4>::NullaryExpr(random);
  calib.R0_rect = Eigen::Matrix3d::NullaryExpr(random);
  calib.Tr_velo_to_cam = Eigen::Matrix<double, 3, 4>::NullaryExpr(random);
  write_kitti_calib(dir / "calib.txt", calib);
  const KittiCalib back = read_kitti_calib(dir / "calib.txt");
  for (int k = 0; k < 4; ++k) EXPECT_EQ(back.P[static_cast<std::size_t>(k)], calib.P[static_cast<std::size_t>(k)]);
  EXPECT_EQ(back.R0_rect, calib.R0_rect);
  EXPECT_EQ(back.Tr_velo_to_cam, calib.Tr_velo_to_cam);
  EXPECT_FALSE(back.Tr_imu_to_velo.has_value());
}

TEST(KittiRejects, BinSizeNotAMultipleOfThePointSize) {
  const std::string bytes(36, '\0');
  expect_input_error([&] { parse_kitti_bin(bytes_of(bytes), "scan.bin"); }, {"scan.bin", "36 bytes", "multiple of 16"});
  expect_input_error([&] { parse_kitti_bin(bytes_of(bytes), "nu.bin", 5); }, {"nu.bin", "36 bytes", "multiple of 20"});
}

TEST(KittiRejects, LabelColumnCountAndNumbersNameTheLine) {
  expect_input_error([] { parse_kitti_labels("Car 0 0 0 1 2 3 4 1 1 1 0 0 5\n", "l.txt"); }, {"l.txt", "line 1", "found 14"});
  expect_input_error([] { parse_kitti_labels("\nCar 0 0 0 1 2 3 4 1 x 1 0 0 5 0\n", "l.txt"); },
                     {"l.txt", "line 2 column 10 (width)", "'x'"});
  expect_input_error([] { parse_kitti_labels("Car 0 7 0 1 2 3 4 1 1 1 0 0 5 0\n", "l.txt"); }, {"l.txt", "line 1 column 3 (occluded)"});
  expect_input_error([] { parse_kitti_labels("Car 0 0 nan 1 2 3 4 1 1 1 0 0 5 0\n", "l.txt"); }, {"l.txt", "column 4 (alpha)", "finite"});
}

std::string valid_calib() {
  std::string text;
  for (const char* name : {"P0", "P1", "P2", "P3", "Tr_velo_to_cam"}) text += std::string(name) + ": 1 0 0 0 0 1 0 0 0 0 1 0\n";
  return text + "R0_rect: 1 0 0 0 1 0 0 0 1\n";
}

TEST(KittiRejects, CalibMissingKeysWrongCountsAndDuplicates) {
  EXPECT_NO_THROW(parse_kitti_calib(valid_calib(), "c.txt"));
  std::string no_r0 = valid_calib();
  no_r0.erase(no_r0.find("R0_rect"));
  expect_input_error([&] { parse_kitti_calib(no_r0, "c.txt"); }, {"c.txt", "R0_rect", "missing"});
  expect_input_error([] { parse_kitti_calib(valid_calib() + "Tr_imu_to_velo: 1 2 3\n", "c.txt"); },
                     {"c.txt", "line 7 (Tr_imu_to_velo)", "expected 12 numbers, found 3"});
  expect_input_error([] { parse_kitti_calib(valid_calib() + "P2: 1 0 0 0 0 1 0 0 0 0 1 0\n", "c.txt"); },
                     {"c.txt", "line 7 (P2)", "twice"});
  expect_input_error([] { parse_kitti_calib(valid_calib() + "garbage\n", "c.txt"); }, {"c.txt", "line 7", "NAME: numbers"});
  expect_input_error([] { parse_kitti_calib("P0: 1 2 abc\n", "c.txt"); }, {"c.txt", "line 1 (P0)", "'abc'"});
}

}  // namespace
}  // namespace mlidar::io
