// Issue 17: reading bags. One pass over the fixtures of tests/data/bags (the same 251 messages in each format,
// 0.3-0.5 MB) and the decoding of their PointCloud2 messages; bytes/s is of the file as stored.
#include <filesystem>

#include <benchmark/benchmark.h>

#include "mlidar/io/bag_reader.hpp"

namespace {

namespace fs = std::filesystem;
using namespace mlidar;

const fs::path kBags = fs::path(MLIDAR_SOURCE_DIR) / "tests" / "data" / "bags";
const char* const kFixtures[] = {"ros1_none.bag", "ros1_lz4.bag",   "ros1_bz2.bag", "mcap_none.mcap",
                                 "mcap_lz4.mcap", "mcap_zstd.mcap", "rosbag2_db3"};

std::uint64_t stored_bytes(const fs::path& path) {
  if (!fs::is_directory(path)) return fs::file_size(path);
  std::uint64_t total = 0;
  for (const auto& entry : fs::directory_iterator(path)) total += entry.file_size();
  return total;
}

/// A pass that visits every message (decompressing every chunk).
void BM_BagPass(benchmark::State& state) {
  const fs::path path = kBags / kFixtures[state.range(0)];
  state.SetLabel(kFixtures[state.range(0)]);
  for (auto _ : state) {
    const auto bag = io::open_bag(path);
    std::size_t bytes = 0;
    bag->for_each({}, [&](const io::BagMessage& m) { bytes += m.data.size(); });
    benchmark::DoNotOptimize(bytes);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stored_bytes(path)));
}
BENCHMARK(BM_BagPass)->DenseRange(0, 6)->Unit(benchmark::kMillisecond);

/// The same pass decoding every PointCloud2 into a PointTable (what export and the jobs do).
void BM_BagDecode(benchmark::State& state) {
  const fs::path path = kBags / kFixtures[state.range(0)];
  state.SetLabel(kFixtures[state.range(0)]);
  for (auto _ : state) {
    const auto bag = io::open_bag(path);
    std::size_t points = 0;
    bag->for_each({}, [&](const io::BagMessage& m) {
      const io::BagTopic& topic = bag->topics()[m.topic];
      if (topic.type.find("PointCloud2") != std::string::npos)
        points += io::decode_pointcloud2(m.data, topic.encoding, "bench").table.num_points;
    });
    benchmark::DoNotOptimize(points);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stored_bytes(path)));
}
BENCHMARK(BM_BagDecode)->DenseRange(0, 6)->Unit(benchmark::kMillisecond);

}  // namespace
