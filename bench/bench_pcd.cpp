// PCD read and write throughput from memory, per encoding, on a real
// binary_compressed Pandar64 sweep (opencalib top, ~90k points) re-encoded.
#include <benchmark/benchmark.h>

#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/point_table.hpp"

namespace {

using mlidar::io::PcdCloud;
using mlidar::io::PcdEncoding;

const PcdCloud& real_cloud() {
  static const PcdCloud cloud = mlidar::io::read_pcd(MLIDAR_SHARED_DATA "/real/opencalib_3lidar/0001/top.pcd");
  return cloud;
}

PcdCloud cloud_as(PcdEncoding encoding) {
  PcdCloud cloud = real_cloud();
  cloud.encoding = encoding;
  return cloud;
}

void set_counters(benchmark::State& state, std::size_t points, std::size_t bytes) {
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
}

// Bytes/s counts the encoded file read.
void BM_ParsePcd(benchmark::State& state) {
  const auto encoding = static_cast<PcdEncoding>(state.range(0));
  const std::vector<std::byte> file = mlidar::io::encode_pcd(cloud_as(encoding));
  state.SetLabel(mlidar::io::pcd_encoding_name(encoding));
  std::size_t points = 0;
  for (auto _ : state) {
    PcdCloud cloud = mlidar::io::parse_pcd(file, "bench");
    points = cloud.table.num_points;
    benchmark::DoNotOptimize(cloud.table.fields.data());
  }
  set_counters(state, points, file.size());
}

// Bytes/s counts the encoded file written.
void BM_EncodePcd(benchmark::State& state) {
  const auto encoding = static_cast<PcdEncoding>(state.range(0));
  const PcdCloud cloud = cloud_as(encoding);
  state.SetLabel(mlidar::io::pcd_encoding_name(encoding));
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::vector<std::byte> file = mlidar::io::encode_pcd(cloud);
    bytes = file.size();
    benchmark::DoNotOptimize(file.data());
  }
  set_counters(state, cloud.table.num_points, bytes);
}

// The original file, as PCL compressed it.
void BM_ParseOriginalCompressedFile(benchmark::State& state) {
  const auto file = mlidar::io::read_file_bytes(MLIDAR_SHARED_DATA "/real/opencalib_3lidar/0001/top.pcd");
  std::size_t points = 0;
  for (auto _ : state) {
    PcdCloud cloud = mlidar::io::parse_pcd(file, "bench");
    points = cloud.table.num_points;
    benchmark::DoNotOptimize(cloud.table.fields.data());
  }
  set_counters(state, points, file.size());
}

// The columns turned into the algorithms' Scan (x y z, intensity, ring, time): what every frame pays after parsing.
void BM_PcdToScan(benchmark::State& state) {
  const PcdCloud& cloud = real_cloud();
  for (auto _ : state) {
    const mlidar::Scan scan = mlidar::io::to_scan(cloud.table, "bench");
    benchmark::DoNotOptimize(scan.points.data());
  }
  set_counters(state, cloud.table.num_points, 0);
}

constexpr int kAscii = static_cast<int>(PcdEncoding::kAscii);
constexpr int kBinary = static_cast<int>(PcdEncoding::kBinary);
constexpr int kCompressed = static_cast<int>(PcdEncoding::kBinaryCompressed);

BENCHMARK(BM_ParsePcd)->Arg(kBinary)->Arg(kCompressed)->Arg(kAscii)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_EncodePcd)->Arg(kBinary)->Arg(kCompressed)->Arg(kAscii)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ParseOriginalCompressedFile)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PcdToScan)->Unit(benchmark::kMicrosecond);

}  // namespace
