// ROS 2 rosbag2 folders: metadata.yaml (rosbag2_bagfile_information: version,
// storage_identifier sqlite3 | mcap, relative_file_paths,
// topics_with_message_count) and the storage files. sqlite3 files hold the
// tables topics(id, name, type, serialization_format, ...) and messages(id,
// topic_id, timestamp, data) (the same columns in schema versions 1-4 and
// later); mcap files are read by the MCAP reader. A .db3 file may also be
// given alone, without metadata.yaml.
#include <sqlite3.h>

#include <map>
#include <optional>

#include <yaml-cpp/yaml.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/bag_reader.hpp"
#include "mlidar/io/file_bytes.hpp"

namespace mlidar::io {
namespace {

namespace fs = std::filesystem;

/// One read-only sqlite3 database and its prepared statements.
class Database {
 public:
  explicit Database(const fs::path& path) : source_(path.string()) {
    if (sqlite3_open_v2(source_.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) return;
    const std::string reason = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);  // the handle exists even when the open failed
    db_ = nullptr;
    throw InputError(source_, "sqlite3", "cannot open as sqlite3: " + reason);
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(source_, "sqlite3",
                     what + ": " + (db_ != nullptr ? sqlite3_errmsg(db_) : "no database") +
                         " (a rosbag2 storage file holds tables topics and messages)");
  }

  /// Runs `sql`, calling row(statement) for each result row.
  void query(const char* sql, const std::function<void(sqlite3_stmt*)>& row, std::optional<std::int64_t> parameter = std::nullopt) const {
    sqlite3_stmt* raw = nullptr;
    if (sqlite3_prepare_v2(db_, sql, -1, &raw, nullptr) != SQLITE_OK) {
      sqlite3_finalize(raw);
      fail(std::string("cannot run '") + sql + "'");
    }
    const std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> statement(raw, &sqlite3_finalize);  // also when `row` throws
    if (parameter) sqlite3_bind_int64(raw, 1, *parameter);
    int result = SQLITE_ROW;
    while ((result = sqlite3_step(raw)) == SQLITE_ROW) row(raw);
    if (result != SQLITE_DONE) fail("a query failed");
  }

  const std::string& source() const { return source_; }

 private:
  std::string source_;
  sqlite3* db_ = nullptr;
};

std::string column_text(sqlite3_stmt* statement, int column) {
  const auto* text = sqlite3_column_text(statement, column);
  return text != nullptr ? reinterpret_cast<const char*>(text) : "";
}

class Rosbag2Sqlite final : public BagReader {
 public:
  Rosbag2Sqlite(const fs::path& folder, const std::vector<fs::path>& files) : BagReader(folder) {
    for (const fs::path& file : files) databases_.push_back(std::make_unique<Database>(file));
    for (std::size_t f = 0; f < databases_.size(); ++f) {
      databases_[f]->query("SELECT id, name, type, serialization_format FROM topics", [&](sqlite3_stmt* row) {
        const std::string name = column_text(row, 1);
        const std::string format = column_text(row, 3);
        if (format != "cdr")
          throw InputError(databases_[f]->source(), "topics.serialization_format",
                           "is '" + format + "' for " + name + " (mlidar reads cdr)");
        std::optional<std::size_t> known = find_topic(name);
        if (!known) {
          known = topics_.size();
          topics_.push_back({name, column_text(row, 2), MessageEncoding::kCdr, 0});
        }
        topic_ids_[{f, sqlite3_column_int64(row, 0)}] = *known;
      });
      databases_[f]->query("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id", [&](sqlite3_stmt* row) {
        const auto it = topic_ids_.find({f, sqlite3_column_int64(row, 0)});
        if (it != topic_ids_.end()) topics_[it->second].count += static_cast<std::uint64_t>(sqlite3_column_int64(row, 1));
      });
    }
    counts_known_ = true;
  }

  BagFormat format() const override { return BagFormat::kRosbag2Sqlite; }

  std::vector<std::byte> read(const MessageRef& where) override {
    const Database& database = *databases_.at(where.file);
    std::vector<std::byte> data;
    int rows = 0;
    database.query(
        "SELECT data FROM messages WHERE id = ?",
        [&](sqlite3_stmt* row) {
          const auto* bytes = static_cast<const std::byte*>(sqlite3_column_blob(row, 0));
          data.assign(bytes, bytes + sqlite3_column_bytes(row, 0));
          ++rows;
        },
        static_cast<std::int64_t>(where.block));
    if (rows != 1)
      throw InputError(
          database.source(), "messages.id",
          std::to_string(where.block) + (rows == 0 ? " is gone" : " is not unique") + " (rosbag2 gives every message its own integer id)");
    return data;
  }

 protected:
  void pass(const std::vector<bool>& /*wanted*/, const Emit& emit) override {
    for (std::size_t f = 0; f < databases_.size(); ++f) {
      databases_[f]->query("SELECT topic_id, timestamp, data, id FROM messages ORDER BY timestamp, id", [&](sqlite3_stmt* row) {
        const auto it = topic_ids_.find({f, sqlite3_column_int64(row, 0)});
        if (it == topic_ids_.end())
          throw InputError(databases_[f]->source(), "messages.topic_id", std::to_string(sqlite3_column_int64(row, 0)) + " names no topic");
        if (sqlite3_column_type(row, 3) != SQLITE_INTEGER)
          throw InputError(databases_[f]->source(), "messages.id", "is not an integer (rosbag2 gives every message its own integer id)");
        const auto* bytes = static_cast<const std::byte*>(sqlite3_column_blob(row, 2));
        const std::span<const std::byte> data(bytes, static_cast<std::size_t>(sqlite3_column_bytes(row, 2)));
        emit(it->second, sqlite3_column_int64(row, 1), data,
             MessageRef{static_cast<std::uint32_t>(f), static_cast<std::uint64_t>(sqlite3_column_int64(row, 3)), 0, data.size()});
      });
    }
  }

 private:
  std::vector<std::unique_ptr<Database>> databases_;
  std::map<std::pair<std::size_t, std::int64_t>, std::size_t> topic_ids_;  ///< (file, topic id) -> topic index
};

/// metadata.yaml's storage and files (relative to the folder).
struct Metadata {
  std::string storage;
  std::vector<fs::path> files;
};

Metadata read_metadata(const fs::path& folder) {
  const fs::path file = folder / "metadata.yaml";
  YAML::Node info;
  try {
    info = YAML::Load(read_file_text(file))["rosbag2_bagfile_information"];
  } catch (const YAML::Exception& e) {
    throw InputError(file.string(), "(document)", std::string("not valid YAML: ") + e.what());
  }
  if (!info || !info.IsMap()) throw InputError(file.string(), "rosbag2_bagfile_information", "missing");
  Metadata metadata;
  try {
    metadata.storage = info["storage_identifier"] ? info["storage_identifier"].as<std::string>() : "sqlite3";
    if (info["compression_mode"] && !info["compression_mode"].as<std::string>().empty())
      throw InputError(file.string(), "compression_mode",
                       "'" + info["compression_mode"].as<std::string>() +
                           "' (compressed rosbag2 files are not read yet; decompress with ros2 bag convert)");
    for (const auto& path : info["relative_file_paths"]) metadata.files.push_back(folder / path.as<std::string>());
  } catch (const YAML::Exception& e) {
    throw InputError(file.string(), "rosbag2_bagfile_information", std::string("unexpected layout: ") + e.what());
  }
  if (metadata.files.empty()) throw InputError(file.string(), "relative_file_paths", "lists no storage file");
  return metadata;
}

/// Several MCAP files of one rosbag2 folder as one bag.
class Rosbag2Mcap final : public BagReader {
 public:
  Rosbag2Mcap(const fs::path& folder, const std::vector<fs::path>& files) : BagReader(folder) {
    for (const auto& file : files) {
      parts_.push_back(open_mcap(file));
      for (const BagTopic& topic : parts_.back()->topics()) {
        const auto known = find_topic(topic.name);
        if (known)
          topics_[*known].count += topic.count;
        else
          topics_.push_back(topic);
      }
    }
    counts_known_ = true;
  }
  BagFormat format() const override { return BagFormat::kMcap; }
  std::vector<std::byte> read(const MessageRef& where) override { return parts_.at(where.file)->read(where); }

 protected:
  void pass(const std::vector<bool>& /*wanted*/, const Emit& emit) override {
    for (std::size_t f = 0; f < parts_.size(); ++f) {
      parts_[f]->for_each({}, [&](const BagMessage& m) {
        MessageRef where = m.where;
        where.file = static_cast<std::uint32_t>(f);
        emit(*find_topic(parts_[f]->topics()[m.topic].name), m.log_time_ns, m.data, where);
      });
      if (parts_[f]->truncated()) truncated_ = parts_[f]->truncated();
    }
  }

 private:
  std::vector<std::unique_ptr<BagReader>> parts_;
};

}  // namespace

std::unique_ptr<BagReader> open_rosbag2(const fs::path& folder) {
  std::error_code ec;
  if (!fs::exists(folder / "metadata.yaml", ec)) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(folder, ec))
      if (entry.path().extension() == ".db3") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    if (files.empty())
      throw InputError(folder.string(), "metadata.yaml", "missing (a rosbag2 folder holds metadata.yaml and its storage files)");
    return std::make_unique<Rosbag2Sqlite>(folder, files);
  }
  const Metadata metadata = read_metadata(folder);
  if (metadata.storage == "mcap") return std::make_unique<Rosbag2Mcap>(folder, metadata.files);
  if (metadata.storage != "sqlite3")
    throw InputError((folder / "metadata.yaml").string(), "storage_identifier",
                     "'" + metadata.storage + "' (mlidar reads sqlite3 and mcap)");
  return std::make_unique<Rosbag2Sqlite>(folder, metadata.files);
}

}  // namespace mlidar::io
