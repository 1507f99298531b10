// SPDX-License-Identifier: Apache-2.0
// ROS 2 bags in MCAP (https://mcap.dev/spec), rosbag2's default storage since Iron. No MCAP library
// is packaged in Debian and the format is a small, documented record format, so it is read here:
// the magic, then records (an opcode byte, a little-endian u64 length, the content), some of them
// Chunks whose content is more records, stored plain, zstd-compressed (libzstd) or as an LZ4 frame
// (liblz4's LZ4F). We scan the data section from the start to its Data End record (or the footer)
// and never use the summary section or the indexes: a bag cut short still has its data section,
// and one read serves both the connection list and the messages.
//
// Messages come in the order the file stores them. MCAP does not require log-time order across
// chunks, but the writers of rosbag2 (and `rosbags`, PyPI `mcap`) write each message as it is
// logged, so the stored order is the log-time order for the bags users have.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <lz4frame.h>
#include <zstd.h>

#include "inertialnet/runtime/error.hpp"
#include "io/bag/containers.hpp"
#include "io/bag/rosbag2_message_compression.hpp"
#include "io/crc32.hpp"
#include "io/input_file.hpp"

namespace fs = std::filesystem;

namespace inertialnet::bag {

namespace {

using io_detail::quoted;

constexpr unsigned char kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::uint64_t kRecordHeader = 9;  // opcode (1) + content length (8)

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kDataEnd = 0x0F,
};

// A chunk decompresses into memory whole; rosbag2 writes chunks of about 768 KiB and the PyPI
// writers 1 MiB, so a declared size above this is a damaged length, not a bag to read.
constexpr std::uint64_t kMaxChunkSize = std::uint64_t{1} << 32;

std::string record_name(std::uint8_t opcode) {
  switch (opcode) {
    case kHeader: return "Header";
    case kFooter: return "Footer";
    case kSchema: return "Schema";
    case kChannel: return "Channel";
    case kMessage: return "Message";
    case kChunk: return "Chunk";
    case kDataEnd: return "Data End";
    default: {
      const char* digits = "0123456789abcdef";
      return std::string("0x") + digits[opcode >> 4] + digits[opcode & 15];
    }
  }
}

// The fields of one record's content, read in order; every read checks the bytes left, so a
// length that overruns its record is reported (`damaged`) rather than read past.
class Fields {
 public:
  Fields(const std::uint8_t* data, std::uint64_t size, std::function<void(const std::string&)> damaged)
      : data_(data), size_(size), damaged_(std::move(damaged)) {}

  std::uint16_t u16(const char* field) { return static_cast<std::uint16_t>(little(2, field)); }
  std::uint32_t u32(const char* field) { return static_cast<std::uint32_t>(little(4, field)); }
  std::uint64_t u64(const char* field) { return little(8, field); }
  std::string string(const char* field) {
    const std::uint32_t n = u32(field);
    const std::uint8_t* at = take(n, field);
    return std::string(reinterpret_cast<const char*>(at), n);
  }
  // A byte array with a u32 or u64 length prefix: the pointer, its size in `n`.
  const std::uint8_t* bytes32(const char* field, std::uint64_t& n) {
    n = u32(field);
    return take(n, field);
  }
  const std::uint8_t* bytes64(const char* field, std::uint64_t& n) {
    n = u64(field);
    return take(n, field);
  }
  // What is left of the record (a Message's data).
  const std::uint8_t* rest(std::uint64_t& n) {
    n = size_ - at_;
    return take(n, "data");
  }

 private:
  const std::uint8_t* take(std::uint64_t n, const char* field) {
    if (n > size_ - at_) {
      damaged_(std::string("its ") + field + " field needs " + std::to_string(n) + " bytes but the record has " +
               std::to_string(size_ - at_) + " left");
    }
    const std::uint8_t* p = data_ + at_;
    at_ += n;
    return p;
  }
  std::uint64_t little(int bytes, const char* field) {
    const std::uint8_t* p = take(static_cast<std::uint64_t>(bytes), field);
    std::uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
    return v;
  }

  const std::uint8_t* data_;
  std::uint64_t size_;
  std::uint64_t at_ = 0;
  std::function<void(const std::string&)> damaged_;
};

std::uint64_t load_le64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// One record of the data section: its opcode and content. `data` stays valid until the next call
// of RecordScanner::next().
struct Record {
  std::uint8_t opcode = 0;
  const std::uint8_t* data = nullptr;
  std::uint64_t size = 0;
  std::string where;  // "the Message record at byte 1234" or "… at byte 56 of the chunk at byte 1234"
};

// The records of the data section in stored order, the records of each chunk in their place.
// Only Schema, Channel and Message records are handed out; the rest (indexes, attachments,
// metadata, private records) are skipped by their length.
class RecordScanner {
 public:
  explicit RecordScanner(const fs::path& file) : file_(file) {
    in_ = io_detail::open_input_file(file, "The MCAP file");
    in_.seekg(0, std::ios::end);
    file_size_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
    unsigned char magic[sizeof kMagic] = {};
    if (file_size_ < sizeof kMagic || !in_.read(reinterpret_cast<char*>(magic), sizeof magic) ||
        std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
      throw invalid_input("The file " + quoted(file) + " is not an MCAP file (it does not start with MCAP's magic bytes).");
    }
    offset_ = sizeof kMagic;
  }

  // The next Schema, Channel or Message record, or false after the Data End record or the footer.
  bool next(Record& record) {
    for (;;) {
      if (chunk_at_ < chunk_.size()) {
        const std::uint64_t left = chunk_.size() - chunk_at_;
        const std::string where = "byte " + std::to_string(chunk_at_) + " of the chunk at byte " + std::to_string(chunk_offset_);
        if (left < kRecordHeader) damaged("the chunk at byte " + std::to_string(chunk_offset_) + " ends inside a record header");
        const std::uint8_t opcode = chunk_[chunk_at_];
        const std::uint64_t length = load_le64(&chunk_[chunk_at_ + 1]);
        if (length > left - kRecordHeader) {
          damaged("the " + record_name(opcode) + " record at " + where + " is " + std::to_string(length) +
                  " bytes long but the chunk has " + std::to_string(left - kRecordHeader) + " left");
        }
        const std::uint64_t content = chunk_at_ + kRecordHeader;
        chunk_at_ = content + length;
        if (opcode == kSchema || opcode == kChannel || opcode == kMessage) {
          record = {opcode, chunk_.data() + content, length, "the " + record_name(opcode) + " record at " + where};
          return true;
        }
        continue;
      }
      if (done_) return false;
      if (offset_ == file_size_) {
        damaged("it ends at byte " + std::to_string(offset_) + " without a Data End record or footer (was the recording cut short?)");
      }
      if (file_size_ - offset_ < kRecordHeader) damaged("it ends inside the record header at byte " + std::to_string(offset_));
      std::uint8_t header[kRecordHeader];
      read_at(offset_, header, kRecordHeader);
      const std::uint8_t opcode = header[0];
      const std::uint64_t length = load_le64(header + 1);
      const std::uint64_t at = offset_;
      const std::string where = "the " + record_name(opcode) + " record at byte " + std::to_string(at);
      if (length > file_size_ - at - kRecordHeader) {
        damaged(where + " is " + std::to_string(length) + " bytes long but the file ends " +
                std::to_string(file_size_ - at - kRecordHeader) + " bytes after its header");
      }
      offset_ = at + kRecordHeader + length;
      if (at == sizeof kMagic && opcode != kHeader) damaged("its first record is " + record_name(opcode) + ", not Header");
      if (opcode == kDataEnd || opcode == kFooter) {
        done_ = true;
        return false;
      }
      if (opcode != kChunk && opcode != kSchema && opcode != kChannel && opcode != kMessage) continue;
      record_.resize(length);
      read_at(at + kRecordHeader, record_.data(), length);
      if (opcode == kChunk) {
        open_chunk(at, where);
        continue;
      }
      record = {opcode, record_.data(), length, where};
      return true;
    }
  }

  [[noreturn]] void damaged(const std::string& what) const {
    throw invalid_input("The MCAP file " + quoted(file_) + " is damaged: " + what + ".");
  }

 private:
  void read_at(std::uint64_t offset, std::uint8_t* to, std::uint64_t n) {
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    if (!in_.read(reinterpret_cast<char*>(to), static_cast<std::streamsize>(n))) {
      throw invalid_input("The MCAP file " + quoted(file_) + " could not be read at byte " + std::to_string(offset) + ".");
    }
  }

  // Decompresses the Chunk record in record_ into chunk_ and checks its size and CRC.
  void open_chunk(std::uint64_t at, const std::string& where) {
    Fields fields(record_.data(), record_.size(), [&](const std::string& what) { damaged(where + ": " + what); });
    fields.u64("message_start_time");
    fields.u64("message_end_time");
    const std::uint64_t uncompressed_size = fields.u64("uncompressed_size");
    const std::uint32_t crc = fields.u32("uncompressed_crc");
    const std::string compression = fields.string("compression");
    std::uint64_t size = 0;
    const std::uint8_t* records = fields.bytes64("records", size);
    if (uncompressed_size > kMaxChunkSize) {
      damaged(where + " says it holds " + std::to_string(uncompressed_size) + " bytes (more than the 4 GiB a chunk is read with)");
    }
    chunk_.clear();
    chunk_at_ = 0;
    chunk_offset_ = at;
    if (compression.empty()) {
      if (size != uncompressed_size) {
        damaged(where + " is uncompressed with " + std::to_string(size) + " bytes of records but says " +
                std::to_string(uncompressed_size));
      }
      chunk_.assign(records, records + size);
    } else if (compression == "zstd") {
      unzstd(records, size, uncompressed_size, where);
    } else if (compression == "lz4") {
      unlz4(records, size, uncompressed_size, where);
    } else {
      throw invalid_input("The MCAP file " + quoted(file_) + " uses the chunk compression \"" + compression +
                          "\" (" + where + "); inertialnet reads uncompressed, zstd and lz4 chunks.");
    }
    // The CRC is optional in MCAP (0 means "not computed"; `rosbags` writes 0); checked when
    // given, so that a damaged chunk that still decompresses is refused rather than misread.
    if (crc != 0 && io_detail::crc32_of(chunk_.data(), chunk_.size()) != crc) {
      damaged(where + " fails its CRC check");
    }
  }

  // The output buffer grows as the decompressor produces data (to one byte past the declared size,
  // which tells a chunk that holds more than it says), so a damaged size never allocates by itself.
  std::size_t grow(std::uint64_t declared) {
    const std::uint64_t limit = declared + 1;
    const std::uint64_t now = chunk_.size();
    const std::uint64_t next = std::min<std::uint64_t>(limit, std::max<std::uint64_t>(now * 2, 1 << 16));
    chunk_.resize(static_cast<std::size_t>(next));
    return chunk_.size();
  }

  void check_size(std::uint64_t produced, std::uint64_t declared, const std::string& where) {
    if (produced != declared) {
      damaged(where + " decompresses to " + (produced > declared ? "more than " + std::to_string(declared)
                                                                 : std::to_string(produced)) +
              " bytes but says " + std::to_string(declared));
    }
    chunk_.resize(static_cast<std::size_t>(produced));
  }

  void unzstd(const std::uint8_t* data, std::uint64_t size, std::uint64_t declared, const std::string& where) {
    std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> context(ZSTD_createDCtx(), &ZSTD_freeDCtx);
    if (!context) throw runtime_error("Out of memory creating a zstd decompression context.");
    ZSTD_inBuffer in{data, static_cast<std::size_t>(size), 0};
    std::uint64_t produced = 0;
    std::size_t hint = 1;  // 0 once a frame is complete
    while (in.pos < in.size || hint != 0) {
      if (produced == chunk_.size()) {
        if (chunk_.size() == declared + 1) break;
        grow(declared);
      }
      ZSTD_outBuffer out{chunk_.data(), chunk_.size(), static_cast<std::size_t>(produced)};
      const std::size_t in_before = in.pos;
      hint = ZSTD_decompressStream(context.get(), &out, &in);
      if (ZSTD_isError(hint)) damaged(where + ": its zstd data is invalid (" + ZSTD_getErrorName(hint) + ")");
      const bool progress = in.pos != in_before || out.pos != produced;
      produced = out.pos;
      if (hint != 0 && in.pos == in.size && produced < chunk_.size()) damaged(where + ": its zstd data ends inside a frame");
      if (!progress && produced < chunk_.size()) damaged(where + ": its zstd data is invalid (no progress)");
    }
    check_size(produced, declared, where);
  }

  void unlz4(const std::uint8_t* data, std::uint64_t size, std::uint64_t declared, const std::string& where) {
    LZ4F_dctx* raw = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
      throw runtime_error("Out of memory creating an LZ4 decompression context.");
    }
    std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> context(raw, &LZ4F_freeDecompressionContext);
    std::uint64_t consumed = 0;
    std::uint64_t produced = 0;
    std::size_t hint = 1;  // 0 once a frame is complete
    while (consumed < size || hint != 0) {
      if (produced == chunk_.size()) {
        if (chunk_.size() == declared + 1) break;
        grow(declared);
      }
      std::size_t out_size = chunk_.size() - static_cast<std::size_t>(produced);
      std::size_t in_size = static_cast<std::size_t>(size - consumed);
      hint = LZ4F_decompress(context.get(), chunk_.data() + produced, &out_size, data + consumed, &in_size, nullptr);
      if (LZ4F_isError(hint)) damaged(where + ": its LZ4 frame is invalid (" + LZ4F_getErrorName(hint) + ")");
      consumed += in_size;
      produced += out_size;
      if (hint != 0 && consumed == size && produced < chunk_.size()) damaged(where + ": its LZ4 data ends inside a frame");
      if (in_size == 0 && out_size == 0 && produced < chunk_.size()) damaged(where + ": its LZ4 frame is invalid (no progress)");
    }
    check_size(produced, declared, where);
  }

  fs::path file_;
  std::ifstream in_;
  std::uint64_t file_size_ = 0;
  std::uint64_t offset_ = 0;
  bool done_ = false;
  std::vector<std::uint8_t> record_;  // the content of the current top-level record
  std::vector<std::uint8_t> chunk_;   // the records of the current chunk, decompressed
  std::uint64_t chunk_at_ = 0;
  std::uint64_t chunk_offset_ = 0;
};

struct MessageFields {
  std::uint16_t channel = 0;
  std::uint64_t log_time = 0;
  const std::uint8_t* data = nullptr;
  std::uint64_t size = 0;
};

MessageFields parse_message(const Record& record, const RecordScanner& scanner) {
  Fields fields(record.data, record.size, [&](const std::string& what) { scanner.damaged(record.where + ": " + what); });
  MessageFields message;
  message.channel = fields.u16("channel_id");
  fields.u32("sequence");
  message.log_time = fields.u64("log_time");
  fields.u64("publish_time");
  message.data = fields.rest(message.size);
  if (message.log_time > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    scanner.damaged(record.where + ": its log time " + std::to_string(message.log_time) + " ns is out of range");
  }
  return message;
}

class McapCursor : public BagCursor {
 public:
  McapCursor(const fs::path& file, std::map<std::uint16_t, const BagConnection*> wanted)
      : scanner_(file), wanted_(std::move(wanted)), description_("MCAP file " + quoted(file)) {}

  bool next(BagMessage& message) override {
    Record record;
    while (scanner_.next(record)) {
      if (record.opcode != kMessage) continue;
      const MessageFields fields = parse_message(record, scanner_);
      const auto found = wanted_.find(fields.channel);
      if (found == wanted_.end()) continue;
      message.connection = found->second;
      message.log_time_ns = static_cast<std::int64_t>(fields.log_time);
      message.data.assign(fields.data, fields.data + fields.size);
      refuse_compressed_message(message, description_);
      return true;
    }
    return false;
  }

 private:
  RecordScanner scanner_;
  std::map<std::uint16_t, const BagConnection*> wanted_;
  std::string description_;
};

class McapReader : public BagReader {
 public:
  explicit McapReader(const fs::path& file) : file_(file) {
    // One scan of the whole data section: the channels (which rosbag2 and `rosbags` write inside
    // the chunks, before their first message), the message counts, and every length, size and
    // CRC checked once, so that a damaged bag is refused before any frame is processed.
    RecordScanner scanner(file);
    std::map<std::uint16_t, std::pair<std::string, std::string>> schemas;  // id -> name, encoding
    std::map<std::uint16_t, BagConnection> channels;
    Record record;
    while (scanner.next(record)) {
      Fields fields(record.data, record.size, [&](const std::string& what) { scanner.damaged(record.where + ": " + what); });
      if (record.opcode == kSchema) {
        const std::uint16_t id = fields.u16("id");
        std::string name = fields.string("name");
        std::string encoding = fields.string("encoding");
        std::uint64_t n = 0;
        fields.bytes32("data", n);
        if (id == 0) scanner.damaged(record.where + ": it has the schema id 0, which MCAP reserves for \"no schema\"");
        schemas.emplace(id, std::make_pair(std::move(name), std::move(encoding)));
      } else if (record.opcode == kChannel) {
        const std::uint16_t id = fields.u16("id");
        const std::uint16_t schema_id = fields.u16("schema_id");
        const std::string topic = fields.string("topic");
        const std::string encoding = fields.string("message_encoding");
        std::uint64_t n = 0;
        fields.bytes32("metadata", n);
        if (channels.count(id) != 0) {
          if (channels[id].topic != topic) {
            scanner.damaged(record.where + ": it defines channel " + std::to_string(id) + " again, as " + topic +
                            " instead of " + channels[id].topic);
          }
          continue;
        }
        BagConnection connection;
        connection.topic = topic;
        if (encoding == "cdr") {
          connection.encoding = MessageEncoding::Cdr;
        } else if (encoding == "ros1") {
          connection.encoding = MessageEncoding::Ros1;
        } else {
          throw invalid_input("The MCAP file " + quoted(file) + " has the topic " + topic + " in the message encoding \"" +
                              encoding + "\"; inertialnet reads ROS messages only (\"cdr\" of ROS 2, \"ros1\").");
        }
        const auto schema = schemas.find(schema_id);
        if (schema == schemas.end()) {
          scanner.damaged(record.where + ": the topic " + topic + " names the schema " + std::to_string(schema_id) +
                          ", which no Schema record before it defines (a ROS message needs its type)");
        }
        connection.type = schema->second.first;
        channels.emplace(id, std::move(connection));
      } else if (record.opcode == kMessage) {
        const MessageFields message = parse_message(record, scanner);
        const auto channel = channels.find(message.channel);
        if (channel == channels.end()) {
          scanner.damaged(record.where + ": its channel " + std::to_string(message.channel) +
                          " is defined by no Channel record before it");
        }
        ++channel->second.message_count;
      }
    }
    for (auto& entry : channels) {
      ids_.push_back(entry.first);
      connections_.push_back(std::move(entry.second));
    }
  }

  const std::vector<BagConnection>& connections() const override { return connections_; }

  std::unique_ptr<BagCursor> read(const std::vector<std::string>& topics) override {
    const std::set<std::string> wanted_topics(topics.begin(), topics.end());
    std::map<std::uint16_t, const BagConnection*> wanted;
    for (std::size_t i = 0; i < connections_.size(); ++i) {
      if (wanted_topics.count(connections_[i].topic) != 0) wanted.emplace(ids_[i], &connections_[i]);
    }
    return std::make_unique<McapCursor>(file_, std::move(wanted));
  }

  std::string description() const override { return "ROS 2 bag " + file_.string() + " (MCAP)"; }

 private:
  fs::path file_;
  std::vector<BagConnection> connections_;
  std::vector<std::uint16_t> ids_;  // the MCAP channel id of each connection
};

}  // namespace

bool looks_like_mcap(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char magic[sizeof kMagic] = {};
  return in.read(reinterpret_cast<char*>(magic), sizeof magic) && std::memcmp(magic, kMagic, sizeof kMagic) == 0;
}

std::unique_ptr<BagReader> open_mcap(const fs::path& file) { return std::make_unique<McapReader>(file); }

}  // namespace inertialnet::bag
