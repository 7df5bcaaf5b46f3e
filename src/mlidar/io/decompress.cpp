#include "mlidar/io/decompress.hpp"

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>

#include "mlidar/core/error.hpp"

namespace mlidar::io {
namespace {

[[noreturn]] void corrupt(const std::string& source, const std::string& what) {
  throw InputError(source, "chunk", what + " (the bag is corrupt)");
}

std::size_t bz2(std::span<const std::byte> input, std::vector<std::byte>& out, bool partial, const std::string& source) {
  bz_stream stream{};
  if (BZ2_bzDecompressInit(&stream, 0, 0) != BZ_OK) corrupt(source, "bz2 cannot start");
  stream.next_in = const_cast<char*>(reinterpret_cast<const char*>(input.data()));
  stream.avail_in = static_cast<unsigned>(input.size());
  stream.next_out = reinterpret_cast<char*>(out.data());
  stream.avail_out = static_cast<unsigned>(out.size());
  const int result = BZ2_bzDecompress(&stream);
  const std::size_t produced = out.size() - stream.avail_out;
  BZ2_bzDecompressEnd(&stream);
  if (result != BZ_STREAM_END && result != BZ_OK) {
    if (!partial) corrupt(source, "bz2 data corrupt (error " + std::to_string(result) + ")");
  }
  return produced;
}

std::size_t lz4(std::span<const std::byte> input, std::vector<std::byte>& out, bool partial, const std::string& source) {
  LZ4F_dctx* context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) corrupt(source, "lz4 cannot start");
  std::size_t produced = 0, consumed = 0;
  while (consumed < input.size() && produced < out.size()) {
    std::size_t out_size = out.size() - produced, in_size = input.size() - consumed;
    const std::size_t hint = LZ4F_decompress(context, out.data() + produced, &out_size, input.data() + consumed, &in_size, nullptr);
    if (LZ4F_isError(hint)) {
      LZ4F_freeDecompressionContext(context);
      if (partial) return produced;
      corrupt(source, std::string("lz4 data corrupt: ") + LZ4F_getErrorName(hint));
    }
    produced += out_size;
    consumed += in_size;
    if (hint == 0 || (out_size == 0 && in_size == 0)) break;
  }
  LZ4F_freeDecompressionContext(context);
  return produced;
}

std::size_t zstd(std::span<const std::byte> input, std::vector<std::byte>& out, bool partial, const std::string& source) {
  ZSTD_DStream* stream = ZSTD_createDStream();
  ZSTD_inBuffer in{input.data(), input.size(), 0};
  ZSTD_outBuffer output{out.data(), out.size(), 0};
  while (in.pos < in.size && output.pos < output.size) {
    const std::size_t result = ZSTD_decompressStream(stream, &output, &in);
    if (ZSTD_isError(result)) {
      ZSTD_freeDStream(stream);
      if (partial) return output.pos;
      corrupt(source, std::string("zstd data corrupt: ") + ZSTD_getErrorName(result));
    }
    if (result == 0) break;
  }
  ZSTD_freeDStream(stream);
  return output.pos;
}

}  // namespace

Compression parse_compression(const std::string& name, const std::string& source) {
  if (name == "none" || name.empty()) return Compression::kNone;
  if (name == "bz2") return Compression::kBz2;
  if (name == "lz4") return Compression::kLz4;
  if (name == "zstd") return Compression::kZstd;
  throw InputError(source, "compression", "unknown compression '" + name + "' (mlidar reads none, bz2, lz4 and zstd)");
}

std::vector<std::byte> decompress(Compression compression, std::span<const std::byte> input, std::size_t size, bool partial,
                                  const std::string& source, std::size_t max_size) {
  if (size > max_size)
    throw InputError(source, "chunk",
                     "claims " + std::to_string(size) + " uncompressed bytes, above the " + std::to_string(max_size) +
                         " mlidar accepts (a length that lies)");
  std::vector<std::byte> out(size);
  std::size_t produced = 0;
  switch (compression) {
    case Compression::kNone:
      produced = std::min(size, input.size());
      if (produced > 0) std::memcpy(out.data(), input.data(), produced);
      if (!partial && input.size() != size)
        corrupt(source, "holds " + std::to_string(input.size()) + " bytes where its header says " + std::to_string(size));
      break;
    case Compression::kBz2:
      produced = bz2(input, out, partial, source);
      break;
    case Compression::kLz4:
      produced = lz4(input, out, partial, source);
      break;
    case Compression::kZstd:
      produced = zstd(input, out, partial, source);
      break;
  }
  if (!partial && produced != size)
    corrupt(source, "decompresses to " + std::to_string(produced) + " bytes where its header says " + std::to_string(size));
  out.resize(produced);
  return out;
}

}  // namespace mlidar::io
