// Labelled detection scenes: each label box holds exactly its object's parts and
// points, the objects are not boxes, the classes and difficulties are all there,
// the splits never share a scene and the same spec gives the same bytes.
#include <algorithm>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/detection_dataset.hpp"
#include "mlidar/sim/detection_scene.hpp"
#include "mlidar/sim/ground_truth.hpp"
#include "mlidar/sim/object_shapes.hpp"
#include "test_support.hpp"

namespace mlidar::sim {
namespace {

namespace fs = std::filesystem;

/// The lyft rig with coarser sweeps, so a test frame costs a few milliseconds.
DetectionSpec small_spec(int frames, DetectionSplit split) {
  DetectionSpec spec;
  spec.rig = named_rig("lyft");
  for (auto& lidar : spec.rig.lidars) lidar.model.horizontal_resolution_deg = std::max(lidar.model.horizontal_resolution_deg, 0.6);
  spec.frames = frames;
  spec.seed = 5;
  spec.split = split;
  return spec;
}

nlohmann::json read_json(const fs::path& path) { return nlohmann::json::parse(test::read_text(path)); }

TEST(ShapedObject, EveryPartLiesInsideTheLabelBoxAndTouchesItsFaces) {
  std::mt19937_64 rng(3);
  for (const ObjectClass cls : {ObjectClass::kCar, ObjectClass::kPedestrian, ObjectClass::kCyclist}) {
    for (int i = 0; i < 20; ++i) {
      const ShapedObject object = make_shaped_object(cls, Vec3(4.0, -2.0, 0.15), 0.1 * i, 7, rng);
      SCOPED_TRACE(object.label.type);
      const io::KittiObject box = box_in_base(object.label, 0.0, SE3());
      EXPECT_NEAR(box.location.z(), 0.15, 1e-12);  // the bottom stands where it was put
      Vec3 low = Vec3::Constant(1e9), high = Vec3::Constant(-1e9);
      for (const Primitive& part : object.parts) {
        EXPECT_EQ(part.object_id, 7);
        const Vec3 local = Eigen::AngleAxisd(-object.label.yaw, Vec3::UnitZ()) * (part.centre - object.label.centre);
        const Vec3 half = part.kind == PrimitiveKind::kBox        ? part.half_extent
                          : part.kind == PrimitiveKind::kCylinder ? Vec3(part.radius, part.radius, part.half_extent.z())
                                                                  : Vec3::Constant(part.radius);
        low = low.cwiseMin(local - half);
        high = high.cwiseMax(local + half);
      }
      // The parts span the box: each face is touched (the ground face by the lowest part or the ground itself).
      const Vec3 half_size = object.label.size / 2;
      EXPECT_NEAR(low.x(), -half_size.x(), 1e-9);
      EXPECT_NEAR(high.x(), half_size.x(), 1e-9);
      EXPECT_NEAR(low.y(), -half_size.y(), 1e-9);
      EXPECT_NEAR(high.y(), half_size.y(), 1e-9);
      EXPECT_NEAR(high.z(), half_size.z(), 1e-9);
      EXPECT_GE(low.z(), -half_size.z() - 1e-9);
    }
  }
}

TEST(ShapedObject, SizesAreThoseOfTheClass) {
  std::mt19937_64 rng(4);
  for (int i = 0; i < 200; ++i) {
    const Vec3 car = make_shaped_object(ObjectClass::kCar, Vec3::Zero(), 0.0, 1, rng).label.size;
    EXPECT_GE(car.x(), 3.6);
    EXPECT_LE(car.x(), 5.2);
    EXPECT_GE(car.y(), 1.6);
    EXPECT_LE(car.y(), 2.0);
    EXPECT_GE(car.z(), 1.4);
    EXPECT_LE(car.z(), 1.9);
    const Vec3 walker = make_shaped_object(ObjectClass::kPedestrian, Vec3::Zero(), 0.0, 1, rng).label.size;
    EXPECT_GE(walker.z(), 1.5);
    EXPECT_LE(walker.z(), 1.95);
    EXPECT_LT(walker.head<2>().maxCoeff(), 1.0);
    const Vec3 rider = make_shaped_object(ObjectClass::kCyclist, Vec3::Zero(), 0.0, 1, rng).label.size;
    EXPECT_GE(rider.x(), 1.2);
    EXPECT_LE(rider.x(), 1.9);
    EXPECT_GE(rider.z(), 1.4);
    EXPECT_LE(rider.z(), 1.95);
  }
}

/// Per labelled object: the points that hit it in the base frame, over the lyft rig's three sweeps.
std::map<int, std::vector<Vec3>> object_points(const Scene& scene, const SimRig& rig) {
  std::map<int, std::vector<Vec3>> points;
  const SimTrajectory standing = SimTrajectory::stationary(SE3());
  for (std::size_t i = 0; i < rig.lidars.size(); ++i) {
    const SimulatedScan sweep = simulate_sweep(scene, rig.lidars[i], standing, 0.0, sweep_seed(1, 0, i));
    for (std::size_t k = 0; k < sweep.object_id.size(); ++k) {
      if (sweep.object_id[k] > 0)
        points[sweep.object_id[k]].push_back(rig.lidars[i].T_base_lidar * Vec3(sweep.scan.points[k].cast<double>()));
    }
  }
  return points;
}

TEST(DetectionScene, PointsOfAnObjectFallInItsBoxAndAreNotThoseOfABox) {
  const DetectionSpec spec = small_spec(1, DetectionSplit::kTrain);
  std::vector<double> inner_shares;  // per car with >= 200 points: share of points > 0.1 m inside every face
  std::map<std::string, int> classes;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const Scene scene = detection_scene(seed);
    ASSERT_FALSE(scene.objects().empty());
    for (std::size_t i = 0; i < scene.objects().size(); ++i) EXPECT_EQ(scene.objects()[i].id, static_cast<int>(i) + 1);
    for (const auto& [id, points] : object_points(scene, spec.rig)) {
      const LabelledObject& object = scene.objects()[static_cast<std::size_t>(id - 1)];
      ++classes[object.type];
      const io::KittiObject box = box_in_base(object, 0.0, SE3());
      std::size_t inner = 0;
      for (const Vec3& p : points) {
        EXPECT_TRUE(box_contains(box, p, 0.12)) << object.type << " " << id << " point " << p.transpose();  // range noise
        const Vec3 local = Eigen::AngleAxisd(-object.yaw, Vec3::UnitZ()) * (p - object.centre);
        const Vec3 depth = 0.5 * object.size - local.cwiseAbs();
        if (depth.minCoeff() > 0.1) ++inner;
      }
      // A box's points all lie on its faces; a car's cabin, bonnet and wheel arches put many inside.
      if (object.type == "Car" && points.size() >= 200) {
        inner_shares.push_back(static_cast<double>(inner) / points.size());
        EXPECT_GT(inner_shares.back(), 0.03) << "car " << id << " looks like a box";
      }
    }
  }
  ASSERT_GE(inner_shares.size(), 10u);
  std::nth_element(inner_shares.begin(), inner_shares.begin() + inner_shares.size() / 2, inner_shares.end());
  EXPECT_GT(inner_shares[inner_shares.size() / 2], 0.15);  // measured 0.28 (0.065-0.42 per car); a box gives 0
  EXPECT_GT(classes["Car"], 0);
  EXPECT_GT(classes["Pedestrian"], 0);
  EXPECT_GT(classes["Cyclist"], 0);
}

TEST(DetectionScene, NoObjectOverlapsAnotherOrTheVehicle) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const Scene scene = detection_scene(seed);
    const auto& objects = scene.objects();
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const Eigen::Vector2d a = objects[i].centre.head<2>();
      EXPECT_FALSE(a.x() > -2.5 && a.x() < 6.5 && std::abs(a.y()) < 2.2) << "object in the vehicle, seed " << seed;
      for (std::size_t j = i + 1; j < objects.size(); ++j) {
        const double reach = 0.5 * (objects[i].size.head<2>().norm() + objects[j].size.head<2>().norm());
        EXPECT_GE((objects[j].centre.head<2>() - a).norm(), reach) << "seed " << seed << " objects " << i + 1 << ", " << j + 1;
      }
    }
  }
}

TEST(DetectionDataset, LabelsListEveryObjectWithItsPointsAndDifficulty) {
  const fs::path out = test::scratch_dir() / "det";
  const DetectionSpec spec = small_spec(3, DetectionSplit::kTrain);
  write_detection_dataset(spec, out);
  const io::Dataset dataset = io::read_dataset_yaml(out);
  ASSERT_EQ(dataset.lidars.size(), 3u);
  ASSERT_TRUE(dataset.groundtruth.boxes.has_value());
  EXPECT_EQ(*dataset.groundtruth.boxes, fs::path("groundtruth/label_2"));
  int with_points = 0, without_points = 0;
  for (int frame = 0; frame < 3; ++frame) {
    const std::string name = "00000" + std::to_string(frame);
    const auto boxes = io::read_kitti_labels(out / "groundtruth/label_2" / (name + ".txt"));
    const nlohmann::json labels = read_json(out / "groundtruth/labels" / (name + ".json"));
    ASSERT_EQ(labels["objects"].size(), boxes.size());
    const Scene scene = detection_scene(detection_scene_seed(spec.seed, spec.split, frame));
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const nlohmann::json& object = labels["objects"][i];
      const LabelledObject& truth = scene.objects()[object["id"].get<std::size_t>() - 1];
      EXPECT_EQ(boxes[i].type, truth.type);
      EXPECT_NEAR(boxes[i].dimensions.z(), truth.size.x(), 1e-9);  // label_2 h w l; the JSON l w h
      EXPECT_NEAR(object["box"]["size_lwh"][0].get<double>(), truth.size.x(), 1e-9);
      EXPECT_NEAR(boxes[i].location.x(), object["box"]["center_bottom"][0].get<double>(), 1e-6);
      const double distance = boxes[i].location.head<2>().norm();
      EXPECT_LE(distance, 70.0);
      EXPECT_EQ(object["difficulty"], detection_difficulty(distance));
      int total = 0;
      for (const auto& lidar : spec.rig.lidars) total += object["points"][lidar.name].get<int>();
      EXPECT_EQ(object["points_total"].get<int>(), total);
      EXPECT_EQ(object["has_points"].get<bool>(), total > 0);
      (total > 0 ? with_points : without_points)++;
    }
  }
  EXPECT_GT(with_points, 20);
  EXPECT_GT(without_points, 0);  // hidden objects are kept, marked
  const nlohmann::json summary = read_json(out / "groundtruth/detection.json");
  EXPECT_EQ(summary["split"], "train");
  EXPECT_EQ(summary["frames"], 3);
  int tallied = 0;
  for (const auto& [cls, buckets] : summary["objects"].items())
    for (const auto& [bucket, count] : buckets.items()) tallied += count.get<int>();
  EXPECT_EQ(tallied, with_points + without_points);
  // The scans read back as a dataset's frames: the base LiDAR's first scan has the points its sweep made.
  const io::PcdCloud top = io::read_pcd(out / "scans/top/000000.pcd");
  EXPECT_GT(top.table.num_points, 1000u);
}

TEST(DetectionDataset, SameSpecSameBytesAndTheSplitsShareNoScene) {
  const fs::path dir = test::scratch_dir();
  write_detection_dataset(small_spec(2, DetectionSplit::kTrain), dir / "a");
  write_detection_dataset(small_spec(2, DetectionSplit::kTrain), dir / "b");
  write_detection_dataset(small_spec(2, DetectionSplit::kTest), dir / "test");
  for (const char* file : {"groundtruth/label_2/000001.txt", "groundtruth/labels/000001.json", "scans/front_left/000001.pcd"}) {
    EXPECT_EQ(test::read_text(dir / "a" / file), test::read_text(dir / "b" / file)) << file;
    EXPECT_NE(test::read_text(dir / "a" / file), test::read_text(dir / "test" / file)) << file;
  }
  for (int frame = 0; frame < 1000; ++frame) {
    EXPECT_NE(detection_scene_seed(5, DetectionSplit::kTrain, frame), detection_scene_seed(5, DetectionSplit::kTest, frame));
  }
}

TEST(DetectionDataset, DifficultyFollowsTheThesisDistances) {
  EXPECT_EQ(detection_difficulty(0.0), "easy");
  EXPECT_EQ(detection_difficulty(19.99), "easy");
  EXPECT_EQ(detection_difficulty(20.0), "moderate");
  EXPECT_EQ(detection_difficulty(29.99), "moderate");
  EXPECT_EQ(detection_difficulty(30.0), "hard");
  EXPECT_EQ(detection_difficulty(49.99), "hard");
  EXPECT_EQ(detection_difficulty(50.0), "beyond");
  EXPECT_THROW(detection_split_from_name("val"), UsageError);
}

}  // namespace
}  // namespace mlidar::sim
