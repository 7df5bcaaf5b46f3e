// ROS 1 bag format 2.0 (wiki.ros.org/Bags/Format/2.0): "#ROSBAG V2.0\n", then
// records <header_len u32><header: fields <len u32>name=value><data_len u32><data>
// with op 0x03 bag header (index_pos, conn_count, chunk_count), 0x05 chunk
// (compression none | bz2 | lz4, size: its records, compressed), 0x07
// connection (conn, topic; data: type, md5sum, message_definition, ...),
// 0x02 message data (conn, time: sec u32 + nsec u32), 0x04 index data, 0x06
// chunk info (chunk_pos, start/end time, per-connection counts). The index
// (connections and chunk infos at index_pos) gives topics and counts without a
// pass; a bag without one (cut short by a crash) is read by a pass.
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

constexpr std::uint8_t kMessageData = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05, kChunkInfo = 0x06, kConnection = 0x07;
constexpr std::size_t kVersionLineSize = 13;  // "#ROSBAG V2.0\n"

/// A record's header fields, name -> raw value.
using Fields = std::map<std::string, std::string>;

Fields parse_fields(std::span<const std::byte> bytes, const std::string& source, const std::string& where) {
  Fields fields;
  ByteReader in(bytes, source);
  while (!in.at_end()) {
    const std::uint32_t length = in.u32(where + " field length");
    const auto field = in.take(length, where + " field");
    const std::string text(reinterpret_cast<const char*>(field.data()), field.size());
    const auto equals = text.find('=');
    if (equals == std::string::npos) throw InputError(source, where, "a header field without '='");
    fields[text.substr(0, equals)] = text.substr(equals + 1);
  }
  return fields;
}

template <typename T>
T field_value(const Fields& fields, const char* name, const std::string& source, const std::string& where) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != sizeof(T))
    throw InputError(source, where + " " + name, it == fields.end() ? "missing" : "has " + std::to_string(it->second.size()) + " bytes");
  T value;
  std::memcpy(&value, it->second.data(), sizeof(T));
  return value;
}

std::string text_value(const Fields& fields, const char* name, const std::string& source, const std::string& where) {
  const auto it = fields.find(name);
  if (it == fields.end()) throw InputError(source, where + " " + name, "missing");
  return it->second;
}

std::int64_t time_ns(const Fields& fields, const char* name, const std::string& source, const std::string& where) {
  const auto raw = field_value<std::uint64_t>(fields, name, source, where);
  return static_cast<std::int64_t>(raw & 0xffffffffULL) * 1000000000LL + static_cast<std::int64_t>(raw >> 32);
}

/// One record of the file: its header fields and data (data possibly cut short by the end of the file).
struct Record {
  std::uint64_t offset = 0;  ///< where it starts
  Fields fields;
  std::span<const std::byte> data;  ///< a view of the mapped file (or of a chunk)
  std::uint32_t header_size = 0;
  bool cut = false;  ///< the file ended inside its data
  std::uint64_t end() const { return offset + 8 + header_size + data.size(); }
  std::uint8_t op() const { return fields.count("op") && fields.at("op").size() == 1 ? static_cast<std::uint8_t>(fields.at("op")[0]) : 0; }
};

class Ros1Bag final : public BagReader {
 public:
  explicit Ros1Bag(const std::filesystem::path& path) : BagReader(path), file_(path), source_(path.string()) {
    size_ = file_.size();
    const std::optional<Record> header = read_record(kVersionLineSize);
    if (!header || header->op() != kBagHeader) throw InputError(source_, "bag header", "missing after the version line");
    first_record_ = header->end();
    index_pos_ = field_value<std::uint64_t>(header->fields, "index_pos", source_, "bag header");
    if (index_pos_ >= first_record_ && index_pos_ < size_) read_index();
    if (!counts_known_) for_each({}, [](const BagMessage&) {});  // no index: the topics come from a pass
    counts_known_ = true;
  }

  BagFormat format() const override { return BagFormat::kRos1; }

  std::optional<std::vector<IndexedTopic>> indexed_topics() override {
    if (chunk_positions_.empty()) return std::nullopt;
    std::vector<IndexedTopic> out(topics_.size());
    std::vector<bool> seen(topics_.size(), false);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> first(topics_.size());  // (chunk, record offset in it)
    for (const std::uint64_t chunk : chunk_positions_) {
      const std::optional<Record> record = read_record(chunk);
      if (!record || record->cut || record->op() != kChunk) return std::nullopt;
      // The index data records follow their chunk: per connection, (time, offset of the message record in the chunk).
      for (std::optional<Record> index = read_record(record->end()); index && !index->cut && index->op() == kIndexData;
           index = read_record(index->end())) {
        const auto conn = field_value<std::uint32_t>(index->fields, "conn", source_, "index data");
        if (!connections_.count(conn)) continue;
        const std::size_t t = connections_[conn];
        ByteReader in(index->data, source_ + ": index data");
        while (in.remaining() >= 12) {
          const std::uint64_t raw = in.u64("index time");
          const std::uint32_t offset = in.u32("index offset");
          const std::int64_t ns = static_cast<std::int64_t>(raw & 0xffffffffULL) * 1000000000LL + static_cast<std::int64_t>(raw >> 32);
          if (!seen[t] || ns < out[t].first_ns) out[t].first_ns = ns, first[t] = {chunk, offset};
          if (!seen[t] || ns > out[t].last_ns) out[t].last_ns = ns;
          seen[t] = true;
        }
      }
    }
    for (std::size_t t = 0; t < out.size(); ++t) {
      if (!seen[t]) continue;
      const std::optional<Record> chunk = read_record(first[t].first);
      const ChunkData inner = chunk_records(*chunk);
      ByteReader in(inner.view, source_ + ": chunk at byte " + std::to_string(first[t].first));
      in.seek(first[t].second);
      in.skip(in.u32("record header length"), "record header");
      const auto data = in.take(in.u32("record data length"), "record data");
      out[t].first_message.assign(data.begin(), data.end());
    }
    return out;
  }

  std::vector<std::byte> read(const MessageRef& where) override {
    const std::span<const std::byte> block = cache_.get(where.block, [&] {
      const std::optional<Record> record = read_record(where.block);
      if (!record) throw InputError(source_, "chunk at byte " + std::to_string(where.block), "cannot be read again");
      return record->op() == kChunk ? chunk_records(*record) : ChunkData{{}, record->data};
    });
    if (where.offset + where.size > block.size()) throw InputError(source_, "message reference", "outside its chunk");
    const auto begin = block.begin() + static_cast<std::ptrdiff_t>(where.offset);
    return {begin, begin + static_cast<std::ptrdiff_t>(where.size)};
  }

 protected:
  void pass(const std::vector<bool>& /*wanted*/, const Emit& emit) override {
    const std::uint64_t end = index_pos_ >= first_record_ && index_pos_ <= size_ ? index_pos_ : size_;
    for (std::uint64_t at = first_record_; at < end;) {
      const std::optional<Record> record = read_record(at);
      if (!record) {
        truncated_ = "the file ends inside the record at byte " + std::to_string(at) + " (cut short; read up to there)";
        return;
      }
      at = record->end();
      if (record->op() == kChunk) {
        ChunkData inner = chunk_records(*record);
        visit_records(inner.view, record->offset, record->cut, emit);
        if (!record->cut) cache_.put(record->offset, std::move(inner));
      } else if (record->op() == kConnection) {
        add_connection(*record);
      } else if (record->op() == kMessageData) {
        emit_message(record->fields, record->data, {0, record->offset, 0, record->data.size()}, emit);
      }
      if (record->cut) {
        truncated_ = "the file ends inside the " + std::string(record->op() == kChunk ? "chunk" : "record") + " at byte " +
                     std::to_string(record->offset) + " (cut short; read up to its last whole message)";
        return;
      }
    }
  }

 private:
  /// The record at `offset`, or nullopt when the file ends inside its header.
  std::optional<Record> read_record(std::uint64_t offset) {
    const std::span<const std::byte> file = file_.bytes();
    if (offset + 4 > size_) return std::nullopt;
    std::uint32_t header_size = 0, data_size = 0;
    std::memcpy(&header_size, file.data() + offset, 4);
    if (offset + 8 + header_size > size_) return std::nullopt;
    Record record;
    record.offset = offset;
    record.header_size = header_size;
    record.fields = parse_fields(file.subspan(offset + 4, header_size), source_, "record at byte " + std::to_string(offset));
    std::memcpy(&data_size, file.data() + offset + 4 + header_size, 4);
    const std::uint64_t available = size_ - (offset + 8 + header_size);
    record.cut = data_size > available;
    record.data = file.subspan(offset + 8 + header_size, record.cut ? available : data_size);
    return record;
  }

  ChunkData chunk_records(const Record& chunk) {
    const std::string where = "chunk at byte " + std::to_string(chunk.offset);
    const Compression compression = parse_compression(text_value(chunk.fields, "compression", source_, where), source_ + ": " + where);
    const auto size = field_value<std::uint32_t>(chunk.fields, "size", source_, where);
    if (compression == Compression::kNone) {  // read in place
      if (!chunk.cut && chunk.data.size() != size)
        throw InputError(source_ + ": " + where, "chunk",
                         "holds " + std::to_string(chunk.data.size()) + " bytes where its header says " + std::to_string(size) +
                             " (the bag is corrupt)");
      return {{}, chunk.data.first(std::min<std::size_t>(size, chunk.data.size()))};
    }
    ChunkData out{decompress(compression, chunk.data, size, chunk.cut, source_ + ": " + where), {}};
    out.view = out.owned;
    return out;
  }

  void visit_records(std::span<const std::byte> inner, std::uint64_t chunk_offset, bool cut, const Emit& emit) {
    const std::string where = "chunk at byte " + std::to_string(chunk_offset);
    ByteReader in(inner, source_);
    while (!in.at_end()) {
      if (cut && in.remaining() < 8) return;
      try {
        const Fields fields = parse_fields(in.take(in.u32(where), where), source_, where);
        const std::uint32_t data_length = in.u32(where);
        const auto data = in.take(data_length, where + " record data");
        const auto op = fields.count("op") ? static_cast<std::uint8_t>(fields.at("op")[0]) : 0;
        if (op == kConnection) add_connection(Record{chunk_offset, fields, data, 0, false});
        if (op == kMessageData) emit_message(fields, data, {0, chunk_offset, in.position() - data_length, data_length}, emit);
      } catch (const InputError&) {
        if (cut) return;  // the chunk was cut short: its last record is partial
        throw;
      }
    }
  }

  void add_connection(const Record& record) {
    const std::string where = "connection record at byte " + std::to_string(record.offset);
    const auto conn = field_value<std::uint32_t>(record.fields, "conn", source_, where);
    if (connections_.count(conn)) return;
    const Fields details = parse_fields(record.data, source_, where);
    BagTopic topic{text_value(record.fields, "topic", source_, where), text_value(details, "type", source_, where), MessageEncoding::kRos1,
                   0};
    const std::optional<std::size_t> known = find_topic(topic.name);
    connections_[conn] = known ? *known : topics_.size();
    if (!known) topics_.push_back(std::move(topic));
  }

  void emit_message(const Fields& fields, std::span<const std::byte> data, const MessageRef& where, const Emit& emit) {
    const std::string what = "message record";
    const auto conn = field_value<std::uint32_t>(fields, "conn", source_, what);
    const auto it = connections_.find(conn);
    if (it == connections_.end()) throw InputError(source_, what, "names connection " + std::to_string(conn) + ", which no record defined");
    emit(it->second, time_ns(fields, "time", source_, what), data, where);
  }

  void read_index() {
    std::map<std::uint32_t, std::uint64_t> counts;
    for (std::uint64_t at = index_pos_; at < size_;) {
      const std::optional<Record> record = read_record(at);
      if (!record || record->cut) return;  // an index cut short: use a pass instead
      at = record->end();
      if (record->op() == kConnection) add_connection(*record);
      if (record->op() != kChunkInfo) continue;
      chunk_positions_.push_back(field_value<std::uint64_t>(record->fields, "chunk_pos", source_, "chunk info"));
      ByteReader in(record->data, source_);
      while (!in.at_end()) {
        const std::uint32_t conn = in.u32("chunk info");
        counts[conn] += in.u32("chunk info");
      }
    }
    for (const auto& [conn, count] : counts)
      if (connections_.count(conn)) topics_[connections_[conn]].count += count;
    counts_known_ = !topics_.empty();
  }

  MappedFile file_;
  std::string source_;
  std::uint64_t size_ = 0;
  std::uint64_t first_record_ = 0;
  std::uint64_t index_pos_ = 0;
  std::vector<std::uint64_t> chunk_positions_;        ///< from the index's chunk infos
  std::map<std::uint32_t, std::size_t> connections_;  ///< conn id -> topic index
  ChunkCache cache_;
};

}  // namespace

std::unique_ptr<BagReader> open_ros1_bag(const std::filesystem::path& path) { return std::make_unique<Ros1Bag>(path); }

}  // namespace mlidar::io
