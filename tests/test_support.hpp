#pragma once
// Helpers shared by the tests: where the shared real data lives, scratch folders, reading a file.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

namespace mlidar::test {

/// ../shared/data (MLIDAR_SHARED_DATA overrides the path CMake compiled in); empty path when absent.
inline std::filesystem::path shared_data() {
  const char* env = std::getenv("MLIDAR_SHARED_DATA");
  std::filesystem::path path = env != nullptr ? env : MLIDAR_TEST_SHARED_DATA;
  return std::filesystem::is_directory(path / "real") ? path : std::filesystem::path{};
}

/// Skips the current test with a clear message when the shared data is missing.
#define MLIDAR_REQUIRE_SHARED_DATA()                                                                                                    \
  do {                                                                                                                                  \
    if (::mlidar::test::shared_data().empty()) GTEST_SKIP() << "shared real data not found (set MLIDAR_SHARED_DATA to ../shared/data)"; \
  } while (0)

/// A fresh empty folder under the system temp dir, unique per test and per
/// build tree (keyed by the mlidar binary CMake compiled in), so the Release
/// and sanitizer suites, or two checkouts, can run at once without deleting
/// each other's files. The same tree reuses (and first empties) its folders.
inline std::filesystem::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::size_t tree = std::hash<std::string>{}(MLIDAR_TEST_BIN);
  std::filesystem::path dir = std::filesystem::temp_directory_path() / "mlidar_tests" / std::to_string(tree % 1000000007u) /
                              (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The whole file as text (empty when it cannot be opened).
inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

/// Writes `text` to `path`, creating its folder first.
inline void write_text(const std::filesystem::path& path, const std::string& text) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

}  // namespace mlidar::test
