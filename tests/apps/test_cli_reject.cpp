// Every rejection rule of the readers, seen from the command line: a broken
// file gives exit code 3 and a message naming the file and the field, and a
// failed `convert` leaves no output behind.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "apps/cli_runner.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

struct BrokenFile {
  const char* name;     // file name (its extension picks the reader)
  std::string content;  // the broken bytes
  const char* field;    // what the message must name
};

std::string pcd_header(const std::string& fields, const std::string& size, const std::string& type, const std::string& count, int width,
                       int points, const std::string& data) {
  return "VERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " + type + "\nCOUNT " + count + "\nWIDTH " + std::to_string(width) +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) + "\nDATA " + data + "\n";
}

std::string xyz_header(int width, int points, const std::string& data) {
  return pcd_header("x y z", "4 4 4", "F F F", "1 1 1", width, points, data);
}

std::string compressed_with_sizes(std::uint32_t compressed, std::uint32_t uncompressed) {
  std::string body = xyz_header(2, 2, "binary_compressed");
  char sizes[8];
  std::memcpy(sizes, &compressed, 4);
  std::memcpy(sizes + 4, &uncompressed, 4);
  return body + std::string(sizes, 8) + std::string(8, '\0');
}

std::vector<BrokenFile> broken_files() {
  return {
      {"points_mismatch.pcd", xyz_header(3, 4, "ascii") + "0 0 0\n", "POINTS"},
      {"size_length.pcd", pcd_header("x y z", "4 4", "F F F", "1 1 1", 1, 1, "ascii") + "0 0 0\n", "SIZE"},
      {"type_length.pcd", pcd_header("x y z", "4 4 4", "F F", "1 1 1", 1, 1, "ascii") + "0 0 0\n", "TYPE"},
      {"count_length.pcd", pcd_header("x y z", "4 4 4", "F F F", "1 1", 1, 1, "ascii") + "0 0 0\n", "COUNT"},
      {"bad_type_size.pcd", pcd_header("x y z", "4 4 3", "F F F", "1 1 1", 1, 1, "ascii") + "0 0 0\n", "TYPE"},
      {"short_binary.pcd", xyz_header(10, 10, "binary") + std::string(12, '\0'), "DATA"},
      {"short_ascii.pcd", xyz_header(3, 3, "ascii") + "0 0 0\n1 1 1\n", "DATA"},
      {"lying_compressed.pcd", compressed_with_sizes(1000000, 24), "DATA"},
      {"wrong_uncompressed.pcd", compressed_with_sizes(8, 999), "DATA"},
      {"unknown_data.pcd", xyz_header(1, 1, "zipped") + "0 0 0\n", "DATA"},
      {"no_magic.ply", "plx\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n", "ply"},
      {"bad_format.ply", "ply\nformat utf8 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n", "format"},
      {"bad_type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n0\n", "property"},
      {"short.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n" +
           std::string(7, '\0'),
       "vertex"},
      {"odd_size.bin", std::string(18, '\0'), "size"},
  };
}

class CliRejects : public ::testing::TestWithParam<BrokenFile> {};

TEST_P(CliRejects, InfoExitsThreeNamingFileAndField) {
  const fs::path dir = scratch_dir();
  const BrokenFile& broken = GetParam();
  const fs::path file = dir / broken.name;
  std::ofstream(file, std::ios::binary) << broken.content;
  const CliResult result = run_cli("info " + quoted(file.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find(broken.name), std::string::npos) << result.output;
  EXPECT_NE(result.output.find(broken.field), std::string::npos) << result.output;
}

TEST_P(CliRejects, ConvertLeavesNothingBehind) {
  const fs::path dir = scratch_dir();
  const BrokenFile& broken = GetParam();
  const fs::path file = dir / broken.name;
  std::ofstream(file, std::ios::binary) << broken.content;
  const CliResult result = run_cli("convert " + quoted(file.string()) + " " + quoted((dir / "out.ply").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir)) left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{broken.name});
}

std::string broken_name(const ::testing::TestParamInfo<BrokenFile>& info) {
  std::string name = info.param.name;
  for (char& c : name) {
    if (c == '.') c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Readers, CliRejects, ::testing::ValuesIn(broken_files()), broken_name);

// The extrinsics YAML reaches the CLI through `eval calib`.
struct BrokenExtrinsics {
  const char* name;
  const char* yaml;
  const char* key;
};

const char* const kGoodExtrinsics = "base: base\nlidars:\n  top:\n    translation: [0, 0, 1]\n    quaternion_wxyz: [1, 0, 0, 0]\n";

const BrokenExtrinsics kBrokenExtrinsics[] = {
    {"unknown_key",
     "base: base\nlidars:\n  top:\n    translation: [0, 0, 1]\n    quaternion_wxyz: [1, 0, 0, 0]\n"
     "    colour: red\n",
     "colour"},
    {"non_unit_quaternion", "base: base\nlidars:\n  top:\n    translation: [0, 0, 1]\n    quaternion_wxyz: [1, 0, 0.1, 0]\n",
     "quaternion_wxyz"},
    {"non_psd_covariance",
     "base: base\nlidars:\n  top:\n    translation: [0, 0, 1]\n    quaternion_wxyz: [1, 0, 0, 0]\n"
     "    covariance: [-1,0,0,0,0,0, 0,1,0,0,0,0, 0,0,1,0,0,0, 0,0,0,1,0,0, 0,0,0,0,1,0, 0,0,0,0,0,1]\n",
     "covariance"},
    {"asymmetric_covariance",
     "base: base\nlidars:\n  top:\n    translation: [0, 0, 1]\n    quaternion_wxyz: [1, 0, 0, 0]\n"
     "    covariance: [1,0.5,0,0,0,0, 0,1,0,0,0,0, 0,0,1,0,0,0, 0,0,0,1,0,0, 0,0,0,0,1,0, 0,0,0,0,0,1]\n",
     "covariance"},
};

TEST(CliRejectsExtrinsics, EvalCalibExitsThreeNamingTheKey) {
  const fs::path dir = scratch_dir();
  std::ofstream(dir / "good.yaml") << kGoodExtrinsics;
  for (const auto& broken : kBrokenExtrinsics) {
    const fs::path file = dir / (std::string(broken.name) + ".yaml");
    std::ofstream(file) << broken.yaml;
    const CliResult result = run_cli("eval calib --gt " + quoted((dir / "good.yaml").string()) + " --est " + quoted(file.string()));
    EXPECT_EQ(result.exit_code, 3) << broken.name << ": " << result.output;
    EXPECT_NE(result.output.find(file.filename().string()), std::string::npos) << result.output;
    EXPECT_NE(result.output.find(broken.key), std::string::npos) << broken.name << ": " << result.output;
  }
}

}  // namespace
}  // namespace mlidar::test
