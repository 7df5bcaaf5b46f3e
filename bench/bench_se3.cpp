// SE(3) hot operations: compose, inverse, exp, log, interpolate, and
// transforming a 100k-point cloud (float points, double pose).
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "mlidar/core/se3.hpp"

namespace {

using mlidar::SE3;
using mlidar::Vec6;

constexpr std::size_t kSamples = 1024;  // a pool of inputs so results are not constant-folded

std::vector<Vec6> random_twists(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Vec6> twists(kSamples);
  for (Vec6& xi : twists) {
    for (int i = 0; i < 6; ++i) xi(i) = (i < 3 ? 5.0 : 1.8) * unit(rng);
  }
  return twists;
}

std::vector<SE3> random_poses(unsigned seed) {
  std::vector<SE3> poses;
  for (const Vec6& xi : random_twists(seed)) poses.push_back(SE3::exp(xi));
  return poses;
}

void BM_Compose(benchmark::State& state) {
  const std::vector<SE3> a = random_poses(1);
  const std::vector<SE3> b = random_poses(2);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(a[i] * b[i]);
    i = (i + 1) % kSamples;
  }
}
BENCHMARK(BM_Compose);

void BM_Inverse(benchmark::State& state) {
  const std::vector<SE3> a = random_poses(3);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(a[i].inverse());
    i = (i + 1) % kSamples;
  }
}
BENCHMARK(BM_Inverse);

void BM_Exp(benchmark::State& state) {
  const std::vector<Vec6> twists = random_twists(4);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(SE3::exp(twists[i]));
    i = (i + 1) % kSamples;
  }
}
BENCHMARK(BM_Exp);

void BM_Log(benchmark::State& state) {
  const std::vector<SE3> a = random_poses(5);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(a[i].log());
    i = (i + 1) % kSamples;
  }
}
BENCHMARK(BM_Log);

void BM_Interpolate(benchmark::State& state) {
  const std::vector<SE3> a = random_poses(6);
  const std::vector<SE3> b = random_poses(7);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(mlidar::interpolate(a[i], b[i], 0.37));
    i = (i + 1) % kSamples;
  }
}
BENCHMARK(BM_Interpolate);

std::vector<Eigen::Vector3f> random_cloud(std::size_t count) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> coord(-50.0f, 50.0f);
  std::vector<Eigen::Vector3f> points(count);
  for (Eigen::Vector3f& p : points) p = {coord(rng), coord(rng), coord(rng)};
  return points;
}

// One pose applied to a cloud, as when moving a scan into the map frame:
// point by point through SE3::operator* (quaternion rotation each time) ...
void BM_TransformPointsOneByOne(benchmark::State& state) {
  const std::vector<Eigen::Vector3f> points = random_cloud(static_cast<std::size_t>(state.range(0)));
  std::vector<Eigen::Vector3f> out(points.size());
  const SE3 T = random_poses(9).front();
  for (auto _ : state) {
    for (std::size_t k = 0; k < points.size(); ++k) out[k] = T * points[k];
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points.size()));
}
BENCHMARK(BM_TransformPointsOneByOne)->Arg(100000);

// ... and through transform_points (rotation matrix built once).
void BM_TransformPoints(benchmark::State& state) {
  const std::vector<Eigen::Vector3f> points = random_cloud(static_cast<std::size_t>(state.range(0)));
  std::vector<Eigen::Vector3f> out(points.size());
  const SE3 T = random_poses(9).front();
  for (auto _ : state) {
    mlidar::transform_points(T, points, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points.size()));
}
BENCHMARK(BM_TransformPoints)->Arg(100000);

}  // namespace
