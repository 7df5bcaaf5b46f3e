// The bag readers against fixtures written by other libraries
// (tests/data/bags: python3-rosbag for ROS 1, npm @mcap/core for MCAP, Python
// sqlite3 with a CDR encoder written from the spec for rosbag2), their
// content listed in expected.json.
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/io/bag_reader.hpp"
#include "mlidar/io/ros_messages.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

const fs::path& bags() {
  static const fs::path folder = fs::path(MLIDAR_SOURCE_DIR) / "tests" / "data" / "bags";
  return folder;
}

const nlohmann::json& expected() {
  static const nlohmann::json json = nlohmann::json::parse(std::ifstream(bags() / "expected.json"));
  return json;
}

double number(const nlohmann::json& value) {
  if (value.is_string()) return value == "nan" ? NAN : value == "inf" ? INFINITY : -INFINITY;
  return value.get<double>();
}

/// The value of `field` at point 0, as PointTable holds it.
double first_value(const io::PointTable& table, const std::string& field) { return table.find(field)->value(0); }

void expect_cloud(const io::PointCloud2& cloud, const nlohmann::json& want, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(cloud.header.stamp.sec, want["stamp"]["sec"].get<std::int64_t>());
  EXPECT_EQ(cloud.header.stamp.nanosec, want["stamp"]["nanosec"].get<std::uint32_t>());
  EXPECT_EQ(cloud.header.frame_id, want["frame_id"]);
  EXPECT_EQ(cloud.width, want["width"]);
  EXPECT_EQ(cloud.height, want["height"]);
  EXPECT_EQ(cloud.point_step, want["point_step"]);
  EXPECT_EQ(cloud.row_step, want["row_step"]);
  EXPECT_EQ(cloud.is_bigendian, want["is_bigendian"]);
  EXPECT_EQ(cloud.is_dense, want["is_dense"]);
  ASSERT_EQ(cloud.fields.size(), want["fields"].size());
  for (std::size_t f = 0; f < cloud.fields.size(); ++f) {
    EXPECT_EQ(cloud.fields[f].name, want["fields"][f]["name"]);
    EXPECT_EQ(cloud.fields[f].offset, want["fields"][f]["offset"]);
    EXPECT_EQ(cloud.fields[f].datatype, want["fields"][f]["datatype"]);
  }
  for (const auto& [field, value] : want["first_point"].items()) {
    const double got = first_value(cloud.table, field), wanted = number(value);
    if (std::isnan(wanted))
      EXPECT_TRUE(std::isnan(got)) << field;
    else
      EXPECT_EQ(got, wanted) << field;
  }
  std::size_t finite = 0;
  double sum = 0.0;
  const io::FieldColumn& x = *cloud.table.find("x");
  for (std::size_t i = 0; i < cloud.table.num_points; ++i) {
    const double v = x.value(i);
    if (std::isfinite(v)) ++finite, sum += v;
  }
  EXPECT_EQ(finite, want["finite_x_count"]);
  EXPECT_NEAR(sum, want["finite_x_sum"].get<double>(), 1e-9 * std::max(1.0, std::abs(sum)));
}

class BagFixture : public ::testing::TestWithParam<std::string> {};

TEST_P(BagFixture, TopicsAndEveryPointCloudMatchTheIndependentWriter) {
  const std::string name = GetParam();
  const nlohmann::json& want = expected()["fixtures"][name];
  const auto bag = io::open_bag(bags() / name);
  EXPECT_EQ(io::bag_format_name(bag->format()), std::string(want["format"] == "ros1"   ? "ros1"
                                                            : want["format"] == "mcap" ? "mcap"
                                                                                       : "rosbag2-sqlite3"));
  for (const auto& topic : want["topics"]) {
    const auto t = bag->find_topic(topic["name"]);
    ASSERT_TRUE(t.has_value()) << topic["name"];
    EXPECT_EQ(bag->topics()[*t].type, topic["type"]);
    EXPECT_EQ(bag->topics()[*t].count, topic["message_count"].get<std::uint64_t>()) << topic["name"];
  }
  std::size_t seen = 0;
  const auto& clouds = want["pointclouds"];
  bag->for_each({}, [&](const io::BagMessage& m) {
    const io::BagTopic& topic = bag->topics()[m.topic];
    if (topic.type.find("PointCloud2") == std::string::npos) return;
    ASSERT_LT(seen, clouds.size());
    const nlohmann::json& cloud = clouds[seen++];
    EXPECT_EQ(topic.name, cloud["topic"]);
    EXPECT_EQ(m.index, cloud["index"].get<std::uint64_t>());
    EXPECT_EQ(m.log_time_ns, cloud["receive_ns"].get<std::int64_t>());
    expect_cloud(io::decode_pointcloud2(m.data, topic.encoding, name), cloud, topic.name + " #" + std::to_string(m.index));
    const std::vector<std::byte> again = bag->read(m.where);  // read back by reference: the same bytes
    ASSERT_EQ(again.size(), m.data.size());
    EXPECT_TRUE(std::equal(again.begin(), again.end(), m.data.begin()));
  });
  EXPECT_EQ(seen, clouds.size());
  EXPECT_EQ(bag->truncated().has_value(), want.contains("truncated_at_byte")) << bag->truncated().value_or("");
}

TEST_P(BagFixture, TfStaticGivesTheTransforms) {
  const auto bag = io::open_bag(bags() / GetParam());
  const auto tf = bag->find_topic("/tf_static");
  ASSERT_TRUE(tf.has_value());
  std::vector<io::RosTransform> transforms;
  bag->for_each({}, [&](const io::BagMessage& m) {
    if (m.topic == *tf) transforms = io::decode_tf_message(m.data, bag->topics()[m.topic].encoding, GetParam());
  });
  const auto& want = expected()["tf_static"];
  ASSERT_EQ(transforms.size(), want.size());
  for (std::size_t i = 0; i < transforms.size(); ++i) {
    EXPECT_EQ(transforms[i].header.frame_id, want[i]["parent"]);
    EXPECT_EQ(transforms[i].child_frame_id, want[i]["child"]);
    for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(transforms[i].T_parent_child.translation()(a), want[i]["translation"][a].get<double>());
    const Quat& q = transforms[i].T_parent_child.rotation();
    EXPECT_NEAR(q.x(), want[i]["rotation_xyzw"][0].get<double>(), 1e-12);
    EXPECT_NEAR(q.w(), want[i]["rotation_xyzw"][3].get<double>(), 1e-12);
  }
}

INSTANTIATE_TEST_SUITE_P(Fixtures, BagFixture,
                         ::testing::Values("ros1_none.bag", "ros1_bz2.bag", "ros1_lz4.bag", "ros1_truncated.bag", "mcap_none.mcap",
                                           "mcap_zstd.mcap", "mcap_lz4.mcap", "mcap_nosummary.mcap", "mcap_bigendian.mcap", "rosbag2_db3"),
                         [](const auto& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '.', '_');
                           return name;
                         });

/// The fixture's .db3 alone in a scratch folder, its messages table rebuilt without the primary key and then `sql` run on it.
fs::path db3_with(const std::string& sql) {
  const fs::path folder = scratch_dir();
  const fs::path file = folder / "bag_0.db3";
  fs::copy_file(bags() / "rosbag2_db3" / "rosbag2_db3_0.db3", file);
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(file.string().c_str(), &db), SQLITE_OK);
  const std::string script =
      "CREATE TABLE m2(id, topic_id, timestamp, data); INSERT INTO m2 SELECT id, topic_id, timestamp, data FROM messages;"
      "DROP TABLE messages; ALTER TABLE m2 RENAME TO messages; " +
      sql;
  EXPECT_EQ(sqlite3_exec(db, script.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  sqlite3_close(db);
  return folder;
}

/// Visits every message and reads it again by its reference, as the jobs do.
void read_all_twice(const fs::path& folder) {
  const auto bag = io::open_rosbag2(folder);
  bag->for_each({}, [&](const io::BagMessage& m) {
    const std::vector<std::byte> again = bag->read(m.where);
    EXPECT_TRUE(std::equal(again.begin(), again.end(), m.data.begin(), m.data.end()));
  });
}

TEST(Rosbag2, AMessageIdThatIsNotOneIntegerOfOneRowIsBadInput) {
  // The untouched rebuild reads; fuzz_rosbag2 found the duplicate, where reading again gave another row's bytes.
  EXPECT_NO_THROW(read_all_twice(db3_with("")));
  const std::pair<const char*, const char*> cases[] = {
      {"INSERT INTO messages SELECT id, topic_id, timestamp + 1, data || x'00' FROM messages LIMIT 1;", "is not unique"},
      {"UPDATE messages SET id = CAST(id AS TEXT) || '.5' WHERE rowid = (SELECT MIN(rowid) FROM messages);", "is not an integer"},
      {"UPDATE messages SET id = -id;", ""}};  // negative but unique: fine
  for (const auto& [sql, problem] : cases) {
    SCOPED_TRACE(sql);
    const fs::path folder = db3_with(sql);
    if (std::string(problem).empty()) {
      EXPECT_NO_THROW(read_all_twice(folder));
      continue;
    }
    try {
      read_all_twice(folder);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("messages.id"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
  }
}


/// A ROS 1 sensor_msgs/PointCloud2 of `height` x `width` points with float fields x, y, z (point_step 12) and no data.
std::vector<std::byte> ros1_cloud_without_data(std::uint32_t height, std::uint32_t width) {
  std::vector<std::byte> message;
  const auto u32 = [&](std::uint32_t v) {
    for (int b = 0; b < 4; ++b) message.push_back(static_cast<std::byte>(v >> (8 * b)));
  };
  const auto text = [&](const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    for (const char c : s) message.push_back(static_cast<std::byte>(c));
  };
  u32(7), u32(1700000000), u32(5), text("lidar");  // header: seq, stamp, frame_id
  u32(height), u32(width), u32(3);
  for (std::uint32_t f = 0; f < 3; ++f) text(std::string(1, static_cast<char>('x' + f))), u32(4 * f), message.push_back(std::byte{7}), u32(1);
  message.push_back(std::byte{0});  // is_bigendian
  u32(12), u32(12 * width), u32(0);  // point_step, row_step, no data
  message.push_back(std::byte{1});  // is_dense
  return message;
}

TEST(PointCloud2, AnEmptyCloudOfManyRowsIsEmptyAtOnce) {
  // fuzz_mcap found a width of 0 under a height of 1.7e9, which walked every empty row of every field for minutes
  // (the input is kept in fuzz/corpus/mcap, so that every fuzz run replays it under its 10 s timeout).
  for (const std::uint32_t height : {1u, 4000000000u}) {
    const io::PointCloud2 cloud = io::decode_pointcloud2(ros1_cloud_without_data(height, 0), io::MessageEncoding::kRos1, "t");
    EXPECT_EQ(cloud.header.frame_id, "lidar");
    EXPECT_EQ(cloud.height, height);
    EXPECT_EQ(cloud.table.num_points, 0u);
    ASSERT_NE(cloud.table.find("z"), nullptr);
    EXPECT_TRUE(cloud.table.find("z")->data.empty());
  }
  // Points but no bytes is still a lie.
  EXPECT_THROW(io::decode_pointcloud2(ros1_cloud_without_data(1, 1), io::MessageEncoding::kRos1, "t"), InputError);
}

}  // namespace
}  // namespace mlidar::test
