// SPDX-License-Identifier: Apache-2.0
// ROS 1 bags, format 2.0 (http://wiki.ros.org/Bags/Format/2.0): after the "#ROSBAG V2.0\n" line,
// records of <u32 header length><header fields name=value><u32 data length><data>. The ops read
// here: the bag header (0x03), chunks (0x05: uncompressed, bz2 or lz4 — roslz4 writes LZ4 frames),
// connections (0x07: topic, type, md5sum, message_definition) and messages (0x02: conn, time);
// index data (0x04) is skipped and chunk info (0x06) gives the message counts. Messages are read
// in the order the chunks store them (rosbag record writes in receive order), one chunk in memory
// at a time. Every length is checked against the file (or the chunk) before it is used.
#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>

#include "inertialnet/runtime/error.hpp"
#include "io/bag/containers.hpp"

namespace fs = std::filesystem;

namespace inertialnet::bag {

namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::size_t kMagicSize = sizeof(kMagic) - 1;
// Record headers hold a few short fields (a connection's header is its data, not its record
// header): a larger one is damage, not a bag, and is refused before it is allocated.
constexpr std::uint32_t kMaxRecordHeader = 1u << 20;
// A chunk's declared uncompressed size is allocated before decompressing; rosbag's chunks are
// 768 KiB by default, and a chunk holds whole messages. 1 GiB bounds what damage can ask for.
constexpr std::uint32_t kMaxChunkSize = 1u << 30;

enum Op : std::uint8_t { kMessage = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05, kChunkInfo = 0x06, kConnection = 0x07 };

std::uint32_t le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16 |
         static_cast<std::uint32_t>(p[3]) << 24;
}
std::uint64_t le64(const std::uint8_t* p) { return le32(p) | static_cast<std::uint64_t>(le32(p + 4)) << 32; }

// A record's header fields by name; `where` names the record in messages.
class Fields {
 public:
  Fields(const std::uint8_t* p, std::size_t n, const std::string& where) : where_(where) {
    std::size_t at = 0;
    while (at < n) {
      if (n - at < 4) throw invalid_input(where + ": a header field's length is cut off");
      const std::uint32_t length = le32(p + at);
      at += 4;
      if (length > n - at) throw invalid_input(where + ": a header field of " + std::to_string(length) + " bytes overruns its header");
      const auto* begin = reinterpret_cast<const char*>(p + at);
      const auto* eq = static_cast<const char*>(std::memchr(begin, '=', length));
      if (!eq) throw invalid_input(where + ": a header field has no '='");
      fields_[std::string(begin, eq)] = std::string(eq + 1, begin + length);
      at += length;
    }
  }
  bool has(const std::string& name) const { return fields_.count(name) != 0; }
  const std::string& text(const std::string& name) const {
    const auto it = fields_.find(name);
    if (it == fields_.end()) throw invalid_input(where_ + ": the header has no '" + name + "' field");
    return it->second;
  }
  std::uint8_t op() const { return u8("op"); }
  std::uint8_t u8(const std::string& name) const { return static_cast<std::uint8_t>(sized(name, 1)[0]); }
  std::uint32_t u32(const std::string& name) const { return le32(reinterpret_cast<const std::uint8_t*>(sized(name, 4).data())); }
  std::uint64_t u64(const std::string& name) const { return le64(reinterpret_cast<const std::uint8_t*>(sized(name, 8).data())); }
  // ROS time: u32 seconds, u32 nanoseconds.
  std::int64_t time_ns(const std::string& name) const {
    const auto* p = reinterpret_cast<const std::uint8_t*>(sized(name, 8).data());
    return static_cast<std::int64_t>(le32(p)) * 1000000000 + le32(p + 4);
  }

 private:
  const std::string& sized(const std::string& name, std::size_t size) const {
    const std::string& value = text(name);
    if (value.size() != size) {
      throw invalid_input(where_ + ": the header field '" + name + "' has " + std::to_string(value.size()) + " bytes, not " +
                          std::to_string(size));
    }
    return value;
  }
  std::string where_;
  std::map<std::string, std::string> fields_;
};

// One record as laid out in a byte range (the file, or a decompressed chunk).
struct Record {
  std::uint64_t offset = 0;  // of its header length, in the file or the chunk
  std::vector<std::uint8_t> header, data;
};

struct ChunkRef {
  std::uint64_t offset = 0;       // of the chunk record in the file
  std::string compression;
  std::uint32_t size = 0;         // uncompressed
  std::uint64_t data_offset = 0;  // of the compressed bytes in the file
  std::uint32_t data_size = 0;
};

struct Ros1Connection {
  std::uint32_t id = 0;
  std::string topic, type;
};

class Ros1Bag;

class Ros1Cursor : public BagCursor {
 public:
  Ros1Cursor(Ros1Bag& bag, std::set<std::size_t> wanted) : bag_(bag), wanted_(std::move(wanted)) {}
  bool next(BagMessage& message) override;

 private:
  Ros1Bag& bag_;
  std::set<std::size_t> wanted_;  // indices into the bag's connections()
  std::size_t chunk_ = 0;         // the next chunk to read
  std::vector<std::uint8_t> data_;
  std::size_t at_ = 0;            // within data_
  std::uint64_t chunk_offset_ = 0;  // the chunk record's offset in the file, for messages
};

class Ros1Bag : public BagReader {
 public:
  explicit Ros1Bag(const fs::path& file) : file_(file), in_(file, std::ios::binary) {
    if (!in_) throw invalid_input("cannot open the ROS 1 bag '" + file.string() + "'");
    std::error_code error;
    size_ = fs::file_size(file, error);
    if (error) throw invalid_input("cannot read the size of the ROS 1 bag '" + file.string() + "': " + error.message());
    std::string magic(kMagicSize, '\0');
    if (size_ < kMagicSize || !in_.read(magic.data(), kMagicSize) || magic != kMagic) {
      throw invalid_input("'" + file.string() + "' is not a ROS 1 bag of format 2.0 (no '#ROSBAG V2.0' line)");
    }
    scan();
  }

  const std::vector<BagConnection>& connections() const override { return connections_; }
  std::unique_ptr<BagCursor> read(const std::vector<std::string>& topics) override {
    std::set<std::size_t> wanted;
    for (const std::string& topic : topics) {
      for (std::size_t i = 0; i < connections_.size(); ++i) {
        if (connections_[i].topic == topic) wanted.insert(i);
      }
    }
    return std::make_unique<Ros1Cursor>(*this, std::move(wanted));
  }
  std::string description() const override { return "ROS 1 bag " + file_.string(); }

  // For the cursor: the chunks, a chunk's records, and which connection a message belongs to.
  std::size_t chunk_count() const { return chunks_.size(); }
  std::uint64_t chunk_offset(std::size_t i) const { return chunks_[i].offset; }
  std::vector<std::uint8_t> chunk_data(std::size_t i) {
    const ChunkRef& chunk = chunks_[i];
    std::vector<std::uint8_t> packed = read_bytes(chunk.data_offset, chunk.data_size);
    return decompress(chunk, std::move(packed));
  }
  std::string where(std::uint64_t offset) const { return description() + " at byte " + std::to_string(offset); }
  std::string where_in_chunk(std::uint64_t chunk_offset, std::uint64_t offset) const {
    return where(chunk_offset) + " (its chunk, at byte " + std::to_string(offset) + " of the uncompressed data)";
  }
  // Index into connections() of the message's connection id; throws when the id is unknown.
  std::size_t connection_of(std::uint32_t id, const std::string& where) const {
    const auto it = index_of_id_.find(id);
    if (it == index_of_id_.end()) throw invalid_input(where + ": a message of connection " + std::to_string(id) + ", which the bag does not define");
    return it->second;
  }

  // The record at `at` of `bytes` (a decompressed chunk) into `record`, `at` moved past it; false at the end.
  static bool record_in(const std::vector<std::uint8_t>& bytes, std::size_t& at, Record& record, const std::string& where) {
    if (at == bytes.size()) return false;
    auto take = [&](std::vector<std::uint8_t>& out, const char* what, std::uint32_t limit) {
      if (bytes.size() - at < 4) throw invalid_input(where + ": the record's " + std::string(what) + " length is cut off");
      const std::uint32_t n = le32(bytes.data() + at);
      at += 4;
      if (n > bytes.size() - at || n > limit) {
        throw invalid_input(where + ": a record " + what + " of " + std::to_string(n) + " bytes overruns the " +
                            std::to_string(bytes.size()) + " bytes of its chunk");
      }
      out.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
      at += n;
    };
    record.offset = at;
    take(record.header, "header", kMaxRecordHeader);
    take(record.data, "data", std::numeric_limits<std::uint32_t>::max());
    return true;
  }

 private:
  std::vector<std::uint8_t> read_bytes(std::uint64_t offset, std::uint64_t n) {
    if (offset > size_ || n > size_ - offset) {
      throw invalid_input(where(offset) + ": " + std::to_string(n) + " bytes overrun the file's " + std::to_string(size_) +
                          " bytes (the bag is truncated or damaged)");
    }
    std::vector<std::uint8_t> bytes(n);
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    if (n && !in_.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(n))) {
      throw invalid_input(where(offset) + ": cannot read " + std::to_string(n) + " bytes");
    }
    return bytes;
  }
  std::uint32_t read_u32(std::uint64_t offset) { return le32(read_bytes(offset, 4).data()); }

  std::vector<std::uint8_t> decompress(const ChunkRef& chunk, std::vector<std::uint8_t> packed) {
    const std::string at = where(chunk.offset);
    if (chunk.size > kMaxChunkSize) {
      throw invalid_input(at + ": a chunk of " + std::to_string(chunk.size) + " uncompressed bytes (more than 1 GiB: damaged)");
    }
    if (chunk.compression == "none") {
      if (packed.size() != chunk.size) {
        throw invalid_input(at + ": an uncompressed chunk of " + std::to_string(packed.size()) + " bytes declares " +
                            std::to_string(chunk.size));
      }
      return packed;
    }
    if (chunk.compression == "bz2") {
      // bzip2 can expand far more than any bound worth allocating up front: the output grows with
      // what the stream makes (doubling), so a damaged size field allocates nothing by itself. One
      // byte beyond the declared size is room enough to tell a stream that makes more.
      std::vector<std::uint8_t> out;
      bz_stream stream{};
      if (BZ2_bzDecompressInit(&stream, 0, 0) != BZ_OK) throw runtime_error("cannot start a bzip2 decompression");
      stream.next_in = reinterpret_cast<char*>(packed.data());
      stream.avail_in = static_cast<unsigned int>(packed.size());
      std::size_t produced = 0;
      int status = BZ_OK;
      while (status == BZ_OK) {
        if (produced == out.size()) {
          const std::size_t limit = static_cast<std::size_t>(chunk.size) + 1;
          if (out.size() == limit) break;
          out.resize(std::min(limit, std::max<std::size_t>(65536, 2 * out.size())));
        }
        stream.next_out = reinterpret_cast<char*>(out.data() + produced);
        stream.avail_out = static_cast<unsigned int>(out.size() - produced);
        status = BZ2_bzDecompress(&stream);
        const bool stalled = stream.avail_out > 0 && stream.avail_in == 0;  // the input ended first
        produced = out.size() - stream.avail_out;
        if (status == BZ_OK && stalled) break;
      }
      BZ2_bzDecompressEnd(&stream);
      if (status != BZ_STREAM_END || produced != chunk.size) {
        throw invalid_input(at + ": its bz2 chunk does not decompress to the " + std::to_string(chunk.size) +
                            " bytes it declares" + (status < 0 ? " (bzip2 error " + std::to_string(status) + ")" : std::string()));
      }
      out.resize(produced);
      return out;
    }
    if (chunk.compression == "lz4") {
      // LZ4 expands at most 255-fold (a match token stands for at most 255 bytes per byte read):
      // a larger declared size is damage, refused before it is allocated.
      if (chunk.size > 255 * static_cast<std::uint64_t>(packed.size()) + 64) {
        throw invalid_input(at + ": its lz4 chunk of " + std::to_string(packed.size()) + " bytes declares " +
                            std::to_string(chunk.size) + " uncompressed bytes, more than LZ4 can hold in it (damaged)");
      }
      // roslz4 writes one LZ4 frame per chunk (the LZ4 frame format, not raw blocks).
      std::vector<std::uint8_t> out(chunk.size);
      LZ4F_dctx* context = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) throw runtime_error("cannot create an LZ4 decompression context");
      std::size_t in_at = 0, out_at = 0, hint = 1;
      while (hint != 0 && in_at < packed.size()) {
        std::size_t in_n = packed.size() - in_at, out_n = out.size() - out_at;
        hint = LZ4F_decompress(context, out.data() + out_at, &out_n, packed.data() + in_at, &in_n, nullptr);
        if (LZ4F_isError(hint)) {
          const std::string why = LZ4F_getErrorName(hint);
          LZ4F_freeDecompressionContext(context);
          throw invalid_input(at + ": its lz4 chunk is damaged (" + why + ")");
        }
        in_at += in_n;
        out_at += out_n;
        if (in_n == 0 && out_n == 0) break;  // no progress: the output is full or the input cut
      }
      LZ4F_freeDecompressionContext(context);
      if (hint != 0 || out_at != chunk.size) {
        throw invalid_input(at + ": its lz4 chunk ends before its frame does, or does not make the " + std::to_string(chunk.size) +
                            " bytes it declares");
      }
      return out;
    }
    throw invalid_input(at + ": a chunk compressed with '" + chunk.compression + "'; ROS 1 bags use none, bz2 or lz4");
  }

  // One pass over the top-level records: the bag header, chunks (their place only), connections,
  // chunk infos. A bag whose index was never written (the recorder was killed) has no connection
  // records outside its chunks: then the chunks are read for them.
  void scan() {
    std::uint64_t at = kMagicSize;
    std::map<std::uint32_t, std::uint64_t> counts;
    bool header_seen = false, counted = false;
    while (at < size_) {
      const std::uint64_t record = at;
      const std::uint32_t header_size = read_u32(at);
      if (header_size > kMaxRecordHeader) throw invalid_input(where(record) + ": a record header of " + std::to_string(header_size) + " bytes (damaged)");
      const std::vector<std::uint8_t> header = read_bytes(at + 4, header_size);
      at += 4 + header_size;
      const std::uint32_t data_size = read_u32(at);
      at += 4;
      if (data_size > size_ - std::min(at, size_)) {
        throw invalid_input(where(record) + ": the record's " + std::to_string(data_size) + " data bytes overrun the file's " +
                            std::to_string(size_) + " bytes (the bag is truncated or damaged)");
      }
      const Fields fields(header.data(), header.size(), where(record));
      switch (fields.op()) {
        case kBagHeader:
          header_seen = true;
          break;
        case kChunk: {
          ChunkRef chunk{record, fields.text("compression"), fields.u32("size"), at, data_size};
          chunks_.push_back(chunk);
          break;
        }
        case kConnection:
          add_connection(fields, read_bytes(at, data_size), where(record));
          break;
        case kChunkInfo: {
          const std::vector<std::uint8_t> data = read_bytes(at, data_size);
          const std::uint32_t n = fields.u32("count");
          if (data.size() / 8 < n) throw invalid_input(where(record) + ": a chunk info listing " + std::to_string(n) + " connections in " + std::to_string(data.size()) + " bytes");
          for (std::uint32_t i = 0; i < n; ++i) counts[le32(data.data() + 8 * i)] += le32(data.data() + 8 * i + 4);
          counted = true;
          break;
        }
        case kMessage: case kIndexData:
          break;
        default:
          throw invalid_input(where(record) + ": a record of unknown op " + std::to_string(fields.op()));
      }
      at += data_size;
    }
    if (!header_seen) throw invalid_input(description() + " has no bag header record (damaged)");
    if (connections_.empty() || !counted) {
      // Unindexed: the connections and counts come from the chunks themselves.
      counts.clear();
      for (std::size_t i = 0; i < chunks_.size(); ++i) {
        const std::vector<std::uint8_t> bytes = chunk_data(i);
        std::size_t in = 0;
        Record r;
        while (record_in(bytes, in, r, where_in_chunk(chunks_[i].offset, in))) {
          const std::string at_record = where_in_chunk(chunks_[i].offset, r.offset);
          const Fields f(r.header.data(), r.header.size(), at_record);
          if (f.op() == kConnection) add_connection(f, r.data, at_record);
          if (f.op() == kMessage) ++counts[f.u32("conn")];
        }
      }
    }
    for (const auto& [id, count] : counts) {
      const auto it = index_of_id_.find(id);
      if (it != index_of_id_.end()) connections_[it->second].message_count += count;
    }
  }

  // Connections of one topic and type (several publishers, or a recording resumed) are one.
  void add_connection(const Fields& fields, const std::vector<std::uint8_t>& data, const std::string& where) {
    const std::uint32_t id = fields.u32("conn");
    if (index_of_id_.count(id)) return;  // connections appear in chunks and again in the index
    const Fields details(data.data(), data.size(), where + " (connection " + std::to_string(id) + ")");
    const std::string topic = fields.text("topic");
    const std::string type = details.text("type");
    for (std::size_t i = 0; i < connections_.size(); ++i) {
      if (connections_[i].topic == topic && connections_[i].type == type) {
        index_of_id_[id] = i;
        return;
      }
    }
    BagConnection connection;
    connection.topic = topic;
    connection.type = type;
    connection.encoding = MessageEncoding::Ros1;
    index_of_id_[id] = connections_.size();
    connections_.push_back(connection);
  }

  fs::path file_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::vector<ChunkRef> chunks_;
  std::vector<BagConnection> connections_;
  std::map<std::uint32_t, std::size_t> index_of_id_;
};

bool Ros1Cursor::next(BagMessage& message) {
  for (;;) {
    if (at_ == data_.size()) {
      if (chunk_ == bag_.chunk_count()) return false;
      chunk_offset_ = bag_.chunk_offset(chunk_);
      data_ = bag_.chunk_data(chunk_);
      at_ = 0;
      ++chunk_;
      continue;
    }
    Record record;
    Ros1Bag::record_in(data_, at_, record, bag_.where_in_chunk(chunk_offset_, at_));
    const std::string where = bag_.where_in_chunk(chunk_offset_, record.offset);
    const Fields fields(record.header.data(), record.header.size(), where);
    if (fields.op() != kMessage) continue;
    const std::size_t connection = bag_.connection_of(fields.u32("conn"), where);
    if (!wanted_.count(connection)) continue;
    message.connection = &bag_.connections()[connection];
    message.log_time_ns = fields.time_ns("time");
    message.data = std::move(record.data);
    return true;
  }
}

}  // namespace

// Any "#ROSBAG V" line: open_ros1_bag() then names a version other than 2.0 rather than the bag
// being called no bag at all.
bool looks_like_ros1_bag(const fs::path& file) {
  constexpr char kAnyVersion[] = "#ROSBAG V";
  std::ifstream in(file, std::ios::binary);
  char head[sizeof kAnyVersion - 1] = {};
  return in.read(head, sizeof head) && std::memcmp(head, kAnyVersion, sizeof head) == 0;
}

std::unique_ptr<BagReader> open_ros1_bag(const fs::path& file) {
  // Another version of the format is refused by name rather than misread.
  std::ifstream in(file, std::ios::binary);
  std::string line;
  if (in && std::getline(in, line) && line.rfind("#ROSBAG V", 0) == 0 && line != "#ROSBAG V2.0") {
    throw invalid_input("'" + file.string() + "' is a ROS 1 bag of format " + line.substr(9) +
                        "; only format 2.0 (ROS Groovy and later; `rosbag fix` converts older bags) is read");
  }
  return std::make_unique<Ros1Bag>(file);
}

}  // namespace inertialnet::bag
