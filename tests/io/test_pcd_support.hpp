#pragma once
// Helpers shared by the PCD tests.
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/pcd.hpp"

namespace mlidar::io::test {

inline std::vector<std::byte> to_bytes(const std::string& text) {
  const auto* first = reinterpret_cast<const std::byte*>(text.data());
  return {first, first + text.size()};
}

/// Runs `parse` and checks it throws InputError whose message names `source` and `field`.
inline void expect_input_error(const std::function<void()>& parse, const std::string& source, const std::string& field) {
  try {
    parse();
    ADD_FAILURE() << "expected InputError naming " << field;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(source), std::string::npos) << message;
    EXPECT_NE(message.find(field), std::string::npos) << "message does not name " << field << ": " << message;
  }
}

inline void expect_rejected(const std::vector<std::byte>& bytes, const std::string& field) {
  expect_input_error([&] { parse_pcd(bytes, "crafted.pcd"); }, "crafted.pcd", field);
}

inline void expect_rejected(const std::string& text, const std::string& field) { expect_rejected(to_bytes(text), field); }

/// Same layout (names, types, counts, size) and bit-identical columns.
inline void expect_same_table(const PointTable& expected, const PointTable& actual) {
  ASSERT_EQ(actual.num_points, expected.num_points);
  ASSERT_EQ(actual.fields.size(), expected.fields.size());
  for (std::size_t f = 0; f < expected.fields.size(); ++f) {
    const FieldColumn& want = expected.fields[f];
    const FieldColumn& got = actual.fields[f];
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.type, want.type) << want.name;
    EXPECT_EQ(got.count, want.count) << want.name;
    EXPECT_TRUE(got.data == want.data) << "column " << want.name << " differs";
  }
}

}  // namespace mlidar::io::test
