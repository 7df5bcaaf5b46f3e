// The main of every Google Benchmark program: the process keeps its memory as the CLI's does
// (core/heap_settings.hpp), so a benchmark measures what a command pays, not glibc mapping its first large buffers
// afresh (a PCD read alone measured 18 ms against 1.8 ms after other benchmarks had grown the heap).
#include <benchmark/benchmark.h>

#include "mlidar/core/heap_settings.hpp"

int main(int argc, char** argv) {
  mlidar::keep_large_buffers_in_the_heap();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
