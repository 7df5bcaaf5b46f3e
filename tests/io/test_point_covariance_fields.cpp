// Per-point covariances in a PLY (map.ply of an uncertainty-aware run): written,
// read back bit for bit, and rejected with the field and the point named when
// they cannot be a covariance.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/ply.hpp"
#include "mlidar/io/point_covariance_fields.hpp"

namespace mlidar::io {
namespace {

PlyCloud cloud_with(const std::vector<UpperCovariance>& covariances) {
  Scan scan;
  for (std::size_t i = 0; i < covariances.size(); ++i) scan.points.emplace_back(static_cast<float>(i), 1.0F, 2.0F);
  PlyCloud cloud;
  cloud.table = from_scan(scan);
  add_point_covariances(cloud.table, covariances);
  return cloud;
}

/// `cloud` written and parsed again.
PointTable round_trip(const PlyCloud& cloud) { return parse_ply(encode_ply(cloud), "map.ply").table; }

TEST(PointCovarianceFields, RoundTripThroughPlyBitForBit) {
  const std::vector<UpperCovariance> covariances = {{0.04F, 0.01F, -0.002F, 0.09F, 0.003F, 0.01F}, {1e-6F, 0, 0, 2e-6F, 0, 3e-6F}};
  const PointTable table = round_trip(cloud_with(covariances));
  ASSERT_NE(table.find("cov_trace"), nullptr);
  EXPECT_FLOAT_EQ(static_cast<float>(table.find("cov_trace")->value(0)), 0.04F + 0.09F + 0.01F);
  const auto read = read_point_covariances(table, "map.ply");
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(*read, covariances);
}

TEST(PointCovarianceFields, ACloudWithoutThemHasNone) {
  Scan scan;
  scan.points = {{1.0F, 2.0F, 3.0F}};
  EXPECT_FALSE(read_point_covariances(from_scan(scan), "cloud.ply").has_value());
}

/// The message of the InputError `table` raises, or "" when it reads.
std::string rejection(const PointTable& table) {
  try {
    read_point_covariances(table, "map.ply");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PointCovarianceFields, ImpossibleCovariancesNameTheFieldAndThePoint) {
  const UpperCovariance good = {0.04F, 0.0F, 0.0F, 0.04F, 0.0F, 0.04F};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const struct {
    UpperCovariance bad;
    std::string words;
  } cases[] = {
      {{nan, 0, 0, 0.04F, 0, 0.04F}, "non-finite"},
      {{-0.01F, 0, 0, 0.04F, 0, 0.04F}, "negative variance"},
      {{0.01F, 0.05F, 0, 0.01F, 0, 0.04F}, "not positive semi-definite"},  // |xy| > sqrt(xx yy)
  };
  for (const auto& c : cases) {
    const std::string message = rejection(round_trip(cloud_with({good, c.bad})));
    EXPECT_NE(message.find("map.ply"), std::string::npos) << message;
    EXPECT_NE(message.find("point 1"), std::string::npos) << message;
    EXPECT_NE(message.find(c.words), std::string::npos) << message;
  }
  // A cov_trace that is not the diagonal's sum.
  PlyCloud lying = cloud_with({good});
  float* trace = reinterpret_cast<float*>(lying.table.find("cov_trace")->data.data());
  *trace = 1.0F;
  EXPECT_NE(rejection(round_trip(lying)).find("cov_trace"), std::string::npos);
  // Some cov_ fields without the others.
  PlyCloud partial = cloud_with({good});
  std::erase_if(partial.table.fields, [](const FieldColumn& f) { return f.name == "cov_yz"; });
  EXPECT_NE(rejection(round_trip(partial)).find("cov_yz"), std::string::npos);
}

}  // namespace
}  // namespace mlidar::io
