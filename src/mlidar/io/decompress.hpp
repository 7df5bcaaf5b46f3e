#pragma once
// The block compressions of the bag formats: bz2 (ROS 1), LZ4 frames (ROS 1's
// roslz4 and MCAP's lz4) and zstd (MCAP). Each decompresses a whole block of
// known size, or, for a block cut short (a truncated bag), as much as the
// input holds.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace mlidar::io {

enum class Compression { kNone, kBz2, kLz4, kZstd };

/// "none", "bz2", "lz4" (ROS 1) and "", "lz4", "zstd" (MCAP); InputError naming `source` and the name otherwise.
Compression parse_compression(const std::string& name, const std::string& source);

/// Decompresses `input` into exactly `size` bytes. With `partial` (the input was cut short), returns what the
/// input holds, possibly fewer bytes; otherwise InputError naming `source` when the output differs from `size`
/// or the stream is corrupt. `size` above `max_size` is refused (a lying header).
std::vector<std::byte> decompress(Compression compression, std::span<const std::byte> input, std::size_t size, bool partial,
                                  const std::string& source, std::size_t max_size = std::size_t{1} << 28);

}  // namespace mlidar::io
