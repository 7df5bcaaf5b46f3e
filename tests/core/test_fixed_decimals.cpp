// Numbers as messages and reports print them.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mlidar/core/fixed_decimals.hpp"

namespace mlidar {
namespace {

TEST(FixedDecimals, RoundsToTheDigitsAndMarksAValueNotMeasured) {
  EXPECT_EQ(fixed(3.14159, 2), "3.14");
  EXPECT_EQ(fixed(2.25, 1), "2.2");  // binary 2.25 is exact: round half to even, as printf does
  EXPECT_EQ(fixed(-0.04, 1), "-0.0");
  EXPECT_EQ(fixed(1e300, 0).size(), 301U);  // the largest magnitudes fit
  EXPECT_EQ(fixed(std::nan(""), 3), "-");
  EXPECT_EQ(fixed(-std::numeric_limits<double>::infinity(), 3), "-");
}

}  // namespace
}  // namespace mlidar
