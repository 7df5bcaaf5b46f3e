// MCAP (mcap.dev/spec): magic 0x89 "MCAP0\r\n", records <opcode u8><length
// u64><content>: 0x01 header, 0x02 footer (summary_start), 0x03 schema (id,
// name, encoding, data), 0x04 channel (id, schema_id, topic, message_encoding,
// metadata), 0x05 message (channel_id, sequence, log_time, publish_time,
// data), 0x06 chunk (start/end time, uncompressed size and crc, compression
// "" | lz4 | zstd, records), 0x07 message index, 0x08 chunk index, 0x0B
// statistics (channel_message_counts), 0x0F data end; strings <u32><bytes>,
// maps <u32 byte length><pairs>. With a summary (footer's summary_start) the
// channels and counts come from it; without one (an unfinished recording) from
// a pass over the data section.
#include <algorithm>
#include <cstring>
#include <map>
#include <optional>

#include "mlidar/core/error.hpp"
#include "mlidar/io/bag_reader.hpp"
#include "mlidar/io/byte_reader.hpp"
#include "mlidar/io/decompress.hpp"

namespace mlidar::io {
namespace {

constexpr std::uint8_t kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06, kStatistics = 0x0B, kDataEnd = 0x0F;
constexpr std::uint64_t kMagicSize = 8;
constexpr std::uint64_t kFooterRecordSize = 1 + 8 + 20;

std::string mcap_string(ByteReader& in, std::string_view what) {
  const auto bytes = in.take(in.u32(what), what);
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

struct RawRecord {
  std::uint64_t offset = 0;  ///< of its opcode
  std::uint8_t opcode = 0;
  std::span<const std::byte> content;  ///< a view of the mapped file (or of a chunk)
  bool cut = false;
};

class McapFile final : public BagReader {
 public:
  explicit McapFile(const std::filesystem::path& path) : BagReader(path), file_(path), source_(path.string()) {
    size_ = file_.size();
    if (read_summary()) return;
    for_each({}, [](const BagMessage&) {});  // no summary: channels and counts from a pass
    counts_known_ = true;
  }

  BagFormat format() const override { return BagFormat::kMcap; }

  std::vector<std::byte> read(const MessageRef& where) override {
    const std::span<const std::byte> block = cache_.get(where.block, [&] {
      const std::optional<RawRecord> record = read_record(where.block);
      if (!record) throw InputError(source_, "record at byte " + std::to_string(where.block), "cannot be read again");
      return record->opcode == kChunk ? chunk_records(*record) : ChunkData{{}, record->content};
    });
    if (where.offset + where.size > block.size()) throw InputError(source_, "message reference", "outside its record");
    const auto begin = block.begin() + static_cast<std::ptrdiff_t>(where.offset);
    return {begin, begin + static_cast<std::ptrdiff_t>(where.size)};
  }

 protected:
  void pass(const std::vector<bool>& /*wanted*/, const Emit& emit) override {
    const std::uint64_t end = summary_start_ > 0 ? summary_start_ : size_;
    for (std::uint64_t at = kMagicSize; at < end;) {
      const std::optional<RawRecord> record = read_record(at);
      if (!record) {
        truncated_ = "the file ends inside the record at byte " + std::to_string(at) + " (cut short; read up to there)";
        return;
      }
      at = record->offset + 9 + record->content.size();
      if (record->opcode == kDataEnd || record->opcode == kFooter) return;
      if (record->opcode == kChunk) {
        ChunkData inner = chunk_records(*record);
        visit_records(inner.view, record->offset, record->cut, emit);
        if (!record->cut) cache_.put(record->offset, std::move(inner));
      } else {
        handle(*record, record->offset, 0, emit);
      }
      if (record->cut) {
        truncated_ =
            "the file ends inside the record at byte " + std::to_string(record->offset) + " (cut short; read up to its last whole message)";
        return;
      }
    }
  }

 private:
  std::optional<RawRecord> read_record(std::uint64_t offset) {
    if (offset + 9 > size_) return std::nullopt;
    const std::span<const std::byte> file = file_.bytes();
    RawRecord record;
    record.offset = offset;
    record.opcode = std::to_integer<std::uint8_t>(file[offset]);
    std::uint64_t length = 0;
    std::memcpy(&length, file.data() + offset + 1, 8);
    const std::uint64_t available = size_ - offset - 9;
    record.cut = length > available;
    record.content = file.subspan(offset + 9, record.cut ? available : length);
    return record;
  }

  ChunkData chunk_records(const RawRecord& chunk) {
    const std::string where = source_ + ": chunk at byte " + std::to_string(chunk.offset);
    ByteReader in(chunk.content, where);
    in.skip(16, "chunk times");
    const std::uint64_t uncompressed = in.u64("chunk uncompressed_size");
    in.skip(4, "chunk crc");
    const Compression compression = parse_compression(mcap_string(in, "chunk compression"), where);
    const std::uint64_t length = in.u64("chunk records length");
    const bool cut = chunk.cut || length > in.remaining();
    const auto records = in.take(cut ? in.remaining() : length, "chunk records");
    if (compression == Compression::kNone) {  // read in place
      if (!cut && records.size() != uncompressed)
        throw InputError(where, "chunk",
                         "holds " + std::to_string(records.size()) + " bytes where its header says " + std::to_string(uncompressed) +
                             " (the bag is corrupt)");
      return {{}, records.first(std::min<std::size_t>(uncompressed, records.size()))};
    }
    ChunkData out{decompress(compression, records, uncompressed, cut, where), {}};
    out.view = out.owned;
    return out;
  }

  void visit_records(std::span<const std::byte> inner, std::uint64_t chunk_offset, bool cut, const Emit& emit) {
    ByteReader in(inner, source_ + ": chunk at byte " + std::to_string(chunk_offset));
    while (!in.at_end()) {
      if (cut && in.remaining() < 9) return;
      const std::uint8_t opcode = in.u8("record opcode");
      const std::uint64_t length = in.u64("record length");
      if (cut && length > in.remaining()) return;  // its last record is partial
      const std::uint64_t start = in.position();
      const auto content = in.take(length, "record");
      handle(RawRecord{chunk_offset, opcode, content, false}, chunk_offset, start, emit);
    }
  }

  /// A schema, channel or message record (content starts at `offset` of block `block`).
  void handle(const RawRecord& record, std::uint64_t block, std::uint64_t offset, const Emit& emit) {
    ByteReader in(record.content, source_ + ": record at byte " + std::to_string(record.offset));
    if (record.opcode == kSchema) {
      const auto id = in.scalar<std::uint16_t>("schema id");
      schemas_[id] = mcap_string(in, "schema name");
    } else if (record.opcode == kChannel) {
      add_channel(in);
    } else if (record.opcode == kMessage) {
      const auto channel = in.scalar<std::uint16_t>("message channel_id");
      in.skip(4, "message sequence");
      const std::uint64_t log_time = in.u64("message log_time");
      in.skip(8, "message publish_time");
      const auto it = channels_.find(channel);
      if (it == channels_.end())
        throw InputError(in.source(), "message channel_id", std::to_string(channel) + " names no channel defined before it");
      const std::uint64_t data_offset = offset + in.position();
      const auto data = in.take(in.remaining(), "message data");
      emit(it->second, static_cast<std::int64_t>(log_time), data, MessageRef{0, block, data_offset, data.size()});
    }
  }

  void add_channel(ByteReader& in) {
    const auto id = in.scalar<std::uint16_t>("channel id");
    const auto schema = in.scalar<std::uint16_t>("channel schema_id");
    const std::string topic = mcap_string(in, "channel topic");
    const std::string encoding = mcap_string(in, "channel message_encoding");
    if (channels_.count(id)) return;
    const auto known = find_topic(topic);
    channels_[id] = known ? *known : topics_.size();
    if (known) return;
    const MessageEncoding message_encoding = encoding == "ros1" ? MessageEncoding::kRos1 : MessageEncoding::kCdr;
    topics_.push_back({topic, schemas_.count(schema) ? schemas_[schema] : "", message_encoding, 0});
  }

  /// Channels and counts from the summary section; false when the file has none.
  bool read_summary() {
    if (size_ < kMagicSize * 2 + kFooterRecordSize) return false;
    const std::optional<RawRecord> footer = read_record(size_ - kMagicSize - kFooterRecordSize);
    if (!footer || footer->opcode != kFooter || footer->content.size() != 20) return false;
    ByteReader in(footer->content, source_ + ": footer");
    summary_start_ = in.u64("footer summary_start");
    if (summary_start_ == 0 || summary_start_ >= size_) {
      summary_start_ = 0;
      return false;
    }
    std::map<std::uint16_t, std::uint64_t> counts;
    bool statistics = false;
    for (std::uint64_t at = summary_start_; at < size_ - kMagicSize - kFooterRecordSize;) {
      const std::optional<RawRecord> record = read_record(at);
      if (!record || record->cut) break;
      at = record->offset + 9 + record->content.size();
      handle(*record, 0, 0, [](std::size_t, std::int64_t, std::span<const std::byte>, const MessageRef&) {});
      if (record->opcode != kStatistics) continue;
      ByteReader stats(record->content, source_ + ": statistics");
      stats.skip(8 + 2 + 4 + 4 + 4 + 4 + 8 + 8, "statistics counts");
      ByteReader map(stats.take(stats.u32("channel_message_counts"), "channel_message_counts"), stats.source());
      while (!map.at_end()) {
        const auto channel = map.scalar<std::uint16_t>("channel id");
        counts[channel] = map.u64("message count");
      }
      statistics = true;
    }
    for (const auto& [channel, count] : counts)
      if (channels_.count(channel)) topics_[channels_[channel]].count = count;
    counts_known_ = statistics;
    return statistics;
  }

  MappedFile file_;
  std::string source_;
  std::uint64_t size_ = 0;
  std::uint64_t summary_start_ = 0;
  std::map<std::uint16_t, std::string> schemas_;   ///< id -> name
  std::map<std::uint16_t, std::size_t> channels_;  ///< id -> topic index
  ChunkCache cache_;
};

}  // namespace

std::unique_ptr<BagReader> open_mcap(const std::filesystem::path& path) { return std::make_unique<McapFile>(path); }

}  // namespace mlidar::io
