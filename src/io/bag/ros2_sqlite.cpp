// SPDX-License-Identifier: Apache-2.0
// ROS 2 bags in rosbag2's sqlite3 storage (.db3), and the rosbag2 bag folder (metadata.yaml beside
// its storage file, .db3 or .mcap). The database is read with SQLite's C API (Debian's
// libsqlite3-dev), read-only: the `topics` table (id, name, type, serialization_format) and the
// `messages` table (topic_id, timestamp, data). Those columns are the same in every schema version
// rosbag2 has written (Foxy to Jazzy; later versions add tables and columns we do not need) and in
// the databases `rosbags` writes, so no version is asked for.
#include <sqlite3.h>

#include <cstring>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <opencv2/core/persistence.hpp>

#include "inertialnet/runtime/error.hpp"
#include "io/bag/containers.hpp"
#include "io/bag/rosbag2_message_compression.hpp"
#include "io/input_file.hpp"
#include "io/yaml_util.hpp"

namespace fs = std::filesystem;

namespace inertialnet::bag {

namespace {

using io_detail::quoted;

constexpr char kSqliteMagic[16] = "SQLite format 3";  // with its terminating NUL: 16 bytes

std::string sqlite_text(sqlite3* db) { return db != nullptr ? sqlite3_errmsg(db) : "out of memory"; }

// The open database, shared by the reader and its cursors (a cursor may outlive neither, but a
// shared handle keeps that from mattering).
using Database = std::shared_ptr<sqlite3>;

Database open_database(const fs::path& file) {
  sqlite3* raw = nullptr;
  // Read-only and without creating anything: a bag is the user's recording.
  const int status = sqlite3_open_v2(file.c_str(), &raw, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr);
  Database db(raw, [](sqlite3* d) { sqlite3_close(d); });
  if (status != SQLITE_OK) {
    throw invalid_input("The ROS 2 bag " + quoted(file) + " cannot be opened as an SQLite database (SQLite says: " +
                        sqlite_text(raw) + ").");
  }
  return db;
}

// A prepared statement; its errors name the bag, what was being read and SQLite's words for it.
class Statement {
 public:
  Statement(Database db, const fs::path& file, const std::string& sql, std::string what)
      : db_(std::move(db)), file_(file), what_(std::move(what)) {
    sqlite3_stmt* raw = nullptr;
    const int status = sqlite3_prepare_v2(db_.get(), sql.c_str(), -1, &raw, nullptr);
    statement_.reset(raw);
    if (status != SQLITE_OK) fail();
  }
  // True with a row, false at the end.
  bool step() {
    const int status = sqlite3_step(statement_.get());
    if (status == SQLITE_ROW) return true;
    if (status == SQLITE_DONE) return false;
    fail();
  }
  sqlite3_stmt* get() const { return statement_.get(); }
  std::string text(int column) const {
    const unsigned char* value = sqlite3_column_text(statement_.get(), column);
    return value != nullptr ? reinterpret_cast<const char*>(value) : "";
  }
  [[noreturn]] void fail() const {
    throw invalid_input("The ROS 2 bag " + quoted(file_) + " is not a readable rosbag2 database: " + what_ +
                        " failed (SQLite says: " + sqlite_text(db_.get()) + ").");
  }

 private:
  struct Finalize {
    void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
  };
  Database db_;
  fs::path file_;
  std::string what_;
  std::unique_ptr<sqlite3_stmt, Finalize> statement_;
};

// True when the database has both of rosbag2's tables.
bool has_rosbag2_tables(const Database& db, const fs::path& file) {
  Statement tables(db, file, "SELECT name FROM sqlite_master WHERE type = 'table' AND name IN ('topics', 'messages')",
                   "listing its tables");
  int found = 0;
  while (tables.step()) ++found;
  return found == 2;
}

class SqliteCursor : public BagCursor {
 public:
  SqliteCursor(Database db, const fs::path& file, const std::string& sql,
               std::vector<std::pair<std::int64_t, const BagConnection*>> wanted)
      : statement_(std::move(db), file, sql, "reading its messages"),
        wanted_(std::move(wanted)),
        description_("ROS 2 bag " + io_detail::quoted(file)) {}

  bool next(BagMessage& message) override {
    // Stepping a statement past its end would run the query again from the start (SQLite resets
    // it automatically), so the end is remembered.
    if (done_ || !statement_.step()) {
      done_ = true;
      return false;
    }
    const std::int64_t topic_id = sqlite3_column_int64(statement_.get(), 0);
    message.connection = nullptr;
    for (const auto& entry : wanted_) {
      if (entry.first == topic_id) message.connection = entry.second;
    }
    message.log_time_ns = sqlite3_column_int64(statement_.get(), 1);
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(statement_.get(), 2));
    const int size = sqlite3_column_bytes(statement_.get(), 2);
    // step() has read the row (a damaged page fails there); the blob can still fail to be handed
    // over for want of memory (a null pointer with a non-zero size). An empty message is a null
    // pointer with size 0.
    if (data == nullptr && size > 0) statement_.fail();
    message.data.assign(data, data + size);
    refuse_compressed_message(message, description_);
    return true;
  }

 private:
  Statement statement_;
  std::vector<std::pair<std::int64_t, const BagConnection*>> wanted_;
  std::string description_;
  bool done_ = false;
};

class SqliteReader : public BagReader {
 public:
  explicit SqliteReader(const fs::path& file) : file_(file) {
    io_detail::open_input_file(file, "The ROS 2 bag");  // the usual messages for a missing file
    db_ = open_database(file);
    if (!has_rosbag2_tables(db_, file)) {
      throw invalid_input("The SQLite database " + quoted(file) +
                          " is not a ROS 2 bag: it lacks rosbag2's \"topics\" and \"messages\" tables.");
    }
    Statement topics(db_, file, "SELECT id, name, type, serialization_format FROM topics ORDER BY id",
                     "reading its topics table");
    while (topics.step()) {
      BagConnection connection;
      connection.topic = topics.text(1);
      connection.type = topics.text(2);
      const std::string format = topics.text(3);
      if (format != "cdr") {
        throw invalid_input("The ROS 2 bag " + quoted(file) + " stores the topic " + connection.topic +
                            " in the serialization format \"" + format + "\"; inertialnet reads \"cdr\", which rosbag2 writes.");
      }
      connection.encoding = MessageEncoding::Cdr;
      ids_.push_back(sqlite3_column_int64(topics.get(), 0));
      connections_.push_back(std::move(connection));
    }
    Statement counts(db_, file, "SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id", "counting its messages");
    while (counts.step()) {
      const std::int64_t id = sqlite3_column_int64(counts.get(), 0);
      bool known = false;
      for (std::size_t i = 0; i < ids_.size(); ++i) {
        if (ids_[i] == id) {
          connections_[i].message_count = static_cast<std::uint64_t>(sqlite3_column_int64(counts.get(), 1));
          known = true;
        }
      }
      if (!known) {
        throw invalid_input("The ROS 2 bag " + quoted(file) + " is damaged: it has messages of topic id " +
                            std::to_string(id) + ", which its topics table does not list.");
      }
    }
  }

  const std::vector<BagConnection>& connections() const override { return connections_; }

  std::unique_ptr<BagCursor> read(const std::vector<std::string>& topics) override {
    const std::set<std::string> wanted_topics(topics.begin(), topics.end());
    std::vector<std::pair<std::int64_t, const BagConnection*>> wanted;
    std::string ids;
    for (std::size_t i = 0; i < connections_.size(); ++i) {
      if (wanted_topics.count(connections_[i].topic) == 0) continue;
      wanted.emplace_back(ids_[i], &connections_[i]);
      ids += (ids.empty() ? "" : ", ") + std::to_string(ids_[i]);
    }
    // Ordered as rosbag2's own reader orders them (by timestamp); equal timestamps keep the order
    // they were written in (id). rosbag2's timestamp_idx serves this order as it stands (an index
    // entry is its timestamp, then the rowid, which id is), so SQLite sorts nothing, blobs least
    // (EXPLAIN QUERY PLAN: "SCAN messages USING INDEX timestamp_idx"). The ids are integers from
    // the topics table, not user text.
    const std::string sql = "SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN (" + ids +
                            ") ORDER BY timestamp, id";
    return std::make_unique<SqliteCursor>(db_, file_, sql, std::move(wanted));
  }

  std::string description() const override { return "ROS 2 bag " + file_.string() + " (sqlite3)"; }

 private:
  fs::path file_;
  Database db_;
  std::vector<BagConnection> connections_;
  std::vector<std::int64_t> ids_;  // the topics table's id of each connection
};

}  // namespace

// SQLite's header alone: any SQLite file given as a sequence is meant as a bag (nothing else we
// read is one), and open_ros2_sqlite() then says what is wrong with it (rosbag2's tables missing,
// a damaged database) instead of the video reader saying that FFmpeg cannot open it.
bool looks_like_ros2_sqlite(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[sizeof kSqliteMagic] = {};
  return in.read(magic, sizeof magic) && std::memcmp(magic, kSqliteMagic, sizeof magic) == 0;
}

fs::path ros2_storage_file(const fs::path& folder) {
  const fs::path metadata = folder / "metadata.yaml";
  std::error_code ec;
  if (!fs::is_regular_file(metadata, ec)) {
    throw invalid_input("The folder " + quoted(folder) + " is not a ROS 2 bag: it has no metadata.yaml.");
  }
  const std::string where = "The ROS 2 bag folder " + quoted(folder) + " (its metadata.yaml)";
  cv::FileStorage yaml = yaml::open(metadata);
  const cv::FileNode info = yaml["rosbag2_bagfile_information"];
  if (!info.isMap()) throw invalid_input(where + " has no rosbag2_bagfile_information.");
  const std::string storage = yaml::string(info["storage_identifier"]);
  if (storage != "sqlite3" && storage != "mcap") {
    throw invalid_input(where + " has storage_identifier \"" + storage + "\"; inertialnet reads \"sqlite3\" and \"mcap\".");
  }
  // rosbag2's own compression (`ros2 bag record --compression-mode file|message`) wraps the whole
  // file or each message in zstd on top of the storage; `ros2 bag convert` writes it uncompressed.
  const std::string compression = yaml::string(info["compression_mode"]);
  if (!compression.empty() && compression != "NONE" && compression != "none") {
    throw invalid_input(where + " is compressed by rosbag2 (compression_mode " + compression +
                        "), which inertialnet does not read; convert it to an uncompressed bag first (`ros2 bag convert`).");
  }
  const cv::FileNode paths = info["relative_file_paths"];
  std::vector<std::string> files;
  if (paths.isSeq()) {
    for (const auto& node : paths) files.push_back(yaml::string(node));
  }
  if (files.size() != 1 || files[0].empty()) {
    throw invalid_input(where + " names " + std::to_string(files.size()) +
                        " storage files in relative_file_paths; inertialnet reads a bag of exactly one file"
                        " (a bag split into several is not read yet: give one of its files instead).");
  }
  const fs::path file = folder / files[0];
  if (!fs::is_regular_file(file, ec)) {
    throw invalid_input(where + " names the storage file " + files[0] + ", which is not in the folder.");
  }
  return file;
}

std::unique_ptr<BagReader> open_ros2_sqlite(const fs::path& file) { return std::make_unique<SqliteReader>(file); }

}  // namespace inertialnet::bag
