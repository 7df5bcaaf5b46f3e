#pragma once
// How a long job's process keeps its memory: large buffers (a decoded scan, a decompressed chunk: 0.2-1 MB a frame;
// LibTorch's activations: tens of MB a step) stay in glibc's heap instead of being mapped and unmapped every time.
// The page faults and the zeroing of fresh pages took 60 % of `bag export` (900 MB bag: 4.1 s -> 1.6 s) and half of a
// detector's training step (63 -> 33 ms). Process-wide: the CLI's main, the Python module's fleet workers and the
// tests that time-box a training call it.
namespace mlidar {

/// mallopt: M_MMAP_THRESHOLD and M_TRIM_THRESHOLD at 256 MB.
void keep_large_buffers_in_the_heap();

}  // namespace mlidar
