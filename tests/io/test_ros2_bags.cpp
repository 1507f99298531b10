// SPDX-License-Identifier: Apache-2.0
// The ROS 2 bag containers (src/io/bag/ros2_sqlite.cpp, mcap.cpp) on bags written by independent
// writers: `rosbags` (rosbag2 folders, sqlite3 schema versions 8 and 9, MCAP plain and zstd) and
// PyPI `mcap` (lz4 and zstd chunks with CRCs), made by write_ros2_bags.py before this suite runs
// (CTest fixture; INERTIALNET_ROS2_BAGS names its folder). The topics, types, counts, log times
// and message bytes are compared with what the writers were given (expected.json); damaged
// files are refused as invalid input.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "inertialnet/io/bag.hpp"
#include "inertialnet/runtime/error.hpp"
#include "io/bag/containers.hpp"

namespace fs = std::filesystem;
using inertialnet::BagConnection;
using inertialnet::BagMessage;
using inertialnet::BagReader;
using inertialnet::Error;
using inertialnet::ErrorKind;
using inertialnet::MessageEncoding;
namespace bag = inertialnet::bag;

namespace {

fs::path bags() {
  const char* folder = std::getenv("INERTIALNET_ROS2_BAGS");
  if (folder == nullptr) ADD_FAILURE() << "INERTIALNET_ROS2_BAGS is not set (CTest's fixture sets it)";
  return folder != nullptr ? fs::path(folder) : fs::path();
}

struct Expected {
  std::string topic;
  std::int64_t log_time = 0;
  std::vector<std::uint8_t> cdr;
  std::vector<std::uint8_t> ros1;
};

std::vector<std::uint8_t> from_hex(const std::string& hex) {
  std::vector<std::uint8_t> bytes;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) bytes.push_back(static_cast<std::uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return bytes;
}

nlohmann::json expected_json() {
  std::ifstream in(bags() / "expected.json");
  EXPECT_TRUE(in) << "expected.json missing: did write_ros2_bags.py run?";
  return nlohmann::json::parse(in);
}

std::vector<Expected> expected_messages() {
  std::vector<Expected> messages;
  const nlohmann::json expected = expected_json();
  for (const auto& m : expected["messages"]) {
    messages.push_back({m["topic"].get<std::string>(), m["log_time"].get<std::int64_t>(),
                        from_hex(m["cdr"].get<std::string>()), from_hex(m["ros1"].get<std::string>())});
  }
  return messages;
}

std::unique_ptr<BagReader> open(const fs::path& file) {
  return file.extension() == ".mcap" ? bag::open_mcap(file) : bag::open_ros2_sqlite(file);
}

std::vector<BagMessage> read_all(BagReader& reader, const std::vector<std::string>& topics) {
  std::vector<BagMessage> messages;
  auto cursor = reader.read(topics);
  BagMessage message;
  while (cursor->next(message)) messages.push_back(message);
  return messages;
}

// The message of the invalid_input that `action` throws; a test failure for anything else.
std::string invalid_input_from(const std::function<void()>& action) {
  try {
    action();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << e.what();
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an inertialnet::Error: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no error";
  return "";
}

// Opens the bag and reads every message of every topic.
void open_and_read_everything(const fs::path& file) {
  auto reader = open(file);
  std::vector<std::string> topics;
  for (const auto& c : reader->connections()) topics.push_back(c.topic);
  read_all(*reader, topics);
}

std::vector<std::uint8_t> bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path write_variant(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const fs::path folder = bags() / "variants";
  fs::create_directories(folder);
  const fs::path file = folder / name;
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return file;
}

// The byte offset of the first top-level record with `opcode` (MCAP: 8 magic bytes, then records
// of an opcode byte and a little-endian u64 length), found independently of the reader.
std::size_t first_record(const std::vector<std::uint8_t>& bytes, std::uint8_t opcode) {
  std::size_t at = 8;
  while (at + 9 <= bytes.size()) {
    std::uint64_t length = 0;
    for (int i = 7; i >= 0; --i) length = (length << 8) | bytes[at + 1 + i];
    if (bytes[at] == opcode) return at;
    at += 9 + length;
  }
  ADD_FAILURE() << "no record with opcode " << int(opcode);
  return 0;
}

std::size_t find(const std::vector<std::uint8_t>& bytes, const std::vector<std::uint8_t>& pattern, std::size_t from = 0) {
  for (std::size_t i = from; i + pattern.size() <= bytes.size(); ++i) {
    if (std::equal(pattern.begin(), pattern.end(), bytes.begin() + static_cast<std::ptrdiff_t>(i))) return i;
  }
  ADD_FAILURE() << "pattern not found";
  return 0;
}

class Ros2Bag : public ::testing::TestWithParam<const char*> {};

// Every storage: the topics with their types, encodings and counts; every message, in log-time
// order, with its log time and exact bytes; a cursor over one topic; two cursors at once.
TEST_P(Ros2Bag, ReadsTopicsAndMessagesAsWritten) {
  const fs::path file = bags() / GetParam();
  auto reader = open(file);
  const nlohmann::json topics = expected_json()["topics"];
  ASSERT_EQ(reader->connections().size(), topics.size());
  for (const BagConnection& c : reader->connections()) {
    ASSERT_TRUE(topics.contains(c.topic)) << c.topic;
    EXPECT_EQ(c.type, topics[c.topic]["type"].get<std::string>());
    EXPECT_EQ(c.message_count, topics[c.topic]["count"].get<std::uint64_t>()) << c.topic;
    EXPECT_EQ(c.encoding, MessageEncoding::Cdr);
  }
  EXPECT_NE(reader->description().find(file.string()), std::string::npos);
  EXPECT_NE(reader->description().find(file.extension() == ".mcap" ? "(MCAP)" : "(sqlite3)"), std::string::npos);

  const std::vector<Expected> expected = expected_messages();
  const auto all = read_all(*reader, {"/cam0/image_raw", "/imu0", "/cam0/camera_info"});
  ASSERT_EQ(all.size(), expected.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    ASSERT_NE(all[i].connection, nullptr);
    EXPECT_EQ(all[i].connection->topic, expected[i].topic) << i;
    EXPECT_EQ(all[i].log_time_ns, expected[i].log_time) << i;
    EXPECT_EQ(all[i].data, expected[i].cdr) << i;
  }

  // Images and IMU through two cursors open at the same time, read alternately.
  auto images = reader->read({"/cam0/image_raw"});
  auto imu = reader->read({"/imu0"});
  std::vector<std::int64_t> image_times, imu_times;
  BagMessage message;
  bool more_images = true, more_imu = true;
  while (more_images || more_imu) {
    if (more_images && (more_images = images->next(message))) {
      EXPECT_EQ(message.connection->topic, "/cam0/image_raw");
      image_times.push_back(message.log_time_ns);
    }
    if (more_imu && (more_imu = imu->next(message))) {
      EXPECT_EQ(message.connection->topic, "/imu0");
      imu_times.push_back(message.log_time_ns);
    }
  }
  std::vector<std::int64_t> expected_image_times, expected_imu_times;
  for (const auto& e : expected) {
    if (e.topic == "/cam0/image_raw") expected_image_times.push_back(e.log_time);
    if (e.topic == "/imu0") expected_imu_times.push_back(e.log_time);
  }
  EXPECT_EQ(image_times, expected_image_times);
  EXPECT_EQ(imu_times, expected_imu_times);
  // At the end a cursor stays at the end (it does not start over).
  EXPECT_FALSE(images->next(message));
  EXPECT_FALSE(imu->next(message));
  EXPECT_TRUE(read_all(*reader, {}).empty());
}

INSTANTIATE_TEST_SUITE_P(Storages, Ros2Bag,
                         ::testing::Values("sqlite_v9/sqlite_v9.db3", "sqlite_v8/sqlite_v8.db3",
                                           "humble_folder/humble_folder_0.db3", "mcap_plain/mcap_plain.mcap",
                                           "mcap_zstd/mcap_zstd.mcap", "lz4.mcap", "zstd_crc.mcap", "plain_crc.mcap"));

TEST(Ros2Mcap, Ros1EncodedChannelsAreRos1) {
  auto reader = bag::open_mcap(bags() / "ros1.mcap");
  for (const BagConnection& c : reader->connections()) EXPECT_EQ(c.encoding, MessageEncoding::Ros1) << c.topic;
  const std::vector<Expected> expected = expected_messages();
  const auto all = read_all(*reader, {"/cam0/image_raw", "/imu0", "/cam0/camera_info"});
  ASSERT_EQ(all.size(), expected.size());
  for (std::size_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i].data, expected[i].ros1) << i;
}

TEST(Ros2Mcap, OtherMessageEncodingsAreRefusedByName) {
  const std::string message = invalid_input_from([] { bag::open_mcap(bags() / "json.mcap"); });
  EXPECT_NE(message.find("/points"), std::string::npos) << message;
  EXPECT_NE(message.find("\"json\""), std::string::npos) << message;
}

TEST(Ros2Bag, ContentChecks) {
  EXPECT_TRUE(bag::looks_like_ros2_sqlite(bags() / "sqlite_v9/sqlite_v9.db3"));
  // Any SQLite file: open_ros2_sqlite() names what it lacks (below), better than "not a video".
  EXPECT_TRUE(bag::looks_like_ros2_sqlite(bags() / "no_messages.db3"));
  EXPECT_TRUE(bag::looks_like_ros2_sqlite(bags() / "truncated.db3"));
  EXPECT_FALSE(bag::looks_like_ros2_sqlite(bags() / "lz4.mcap"));
  EXPECT_FALSE(bag::looks_like_ros2_sqlite(bags() / "expected.json"));
  EXPECT_FALSE(bag::looks_like_ros2_sqlite(bags() / "missing.db3"));
  EXPECT_TRUE(bag::looks_like_mcap(bags() / "lz4.mcap"));
  EXPECT_TRUE(bag::looks_like_mcap(bags() / "mcap_zstd/mcap_zstd.mcap"));
  EXPECT_FALSE(bag::looks_like_mcap(bags() / "sqlite_v9/sqlite_v9.db3"));
  EXPECT_FALSE(bag::looks_like_mcap(bags() / "missing.mcap"));
}

// metadata.yaml as `rosbags` writes it (sqlite3 and mcap) and as rosbag2 (yaml-cpp) does.
TEST(Ros2BagFolder, NamesItsOneStorageFile) {
  EXPECT_EQ(bag::ros2_storage_file(bags() / "sqlite_v9"), bags() / "sqlite_v9" / "sqlite_v9.db3");
  EXPECT_EQ(bag::ros2_storage_file(bags() / "mcap_zstd"), bags() / "mcap_zstd" / "mcap_zstd.mcap");
  EXPECT_EQ(bag::ros2_storage_file(bags() / "humble_folder"), bags() / "humble_folder" / "humble_folder_0.db3");
}

TEST(Ros2BagFolder, RefusesWhatItCannotRead) {
  std::string message = invalid_input_from([] { bag::ros2_storage_file(bags() / "split_folder"); });
  EXPECT_NE(message.find("split_folder"), std::string::npos) << message;
  EXPECT_NE(message.find("2 storage files"), std::string::npos) << message;
  message = invalid_input_from([] { bag::ros2_storage_file(bags() / "compressed_folder"); });
  EXPECT_NE(message.find("compression_mode FILE"), std::string::npos) << message;
  message = invalid_input_from([] { bag::ros2_storage_file(bags() / "no_metadata_folder"); });
  EXPECT_NE(message.find("no metadata.yaml"), std::string::npos) << message;
}

// rosbag2's "message" compression: the folder says so; the storage file alone is caught at its
// first message (a zstd frame where CDR belongs).
TEST(Ros2Bag, PerMessageCompressionIsRefusedByName) {
  std::string message = invalid_input_from([] { bag::ros2_storage_file(bags() / "sqlite_message_zstd"); });
  EXPECT_NE(message.find("compression_mode message"), std::string::npos) << message;
  for (const char* file : {"sqlite_message_zstd/sqlite_message_zstd.db3", "mcap_message_zstd/mcap_message_zstd.mcap"}) {
    message = invalid_input_from([&] { open_and_read_everything(bags() / file); });
    EXPECT_NE(message.find(fs::path(file).filename().string()), std::string::npos) << message;
    EXPECT_NE(message.find("zstd-compressed messages on /"), std::string::npos) << message;
  }
}

TEST(Ros2Sqlite, DamagedDatabasesAreInvalidInputNamingTheFile) {
  std::string message = invalid_input_from([] { bag::open_ros2_sqlite(bags() / "no_messages.db3"); });
  EXPECT_NE(message.find("no_messages.db3"), std::string::npos) << message;
  EXPECT_NE(message.find("\"messages\""), std::string::npos) << message;
  message = invalid_input_from([] { open_and_read_everything(bags() / "truncated.db3"); });
  EXPECT_NE(message.find("truncated.db3"), std::string::npos) << message;
  message = invalid_input_from([] { bag::open_ros2_sqlite(bags() / "lz4.mcap"); });
  EXPECT_NE(message.find("lz4.mcap"), std::string::npos) << message;
  message = invalid_input_from([] { bag::open_ros2_sqlite(bags() / "missing.db3"); });
  EXPECT_NE(message.find("does not exist"), std::string::npos) << message;
}

// A file cut anywhere is refused as invalid input, or (cut inside the summary section, after the
// Data End record) read whole: a record is never read past the end of the file. Every cut in the
// magic, the header and the first chunk's fields, then one every 31 bytes (about 2 ms each).
TEST(Ros2Mcap, EveryTruncationIsRefusedOrReadWhole) {
  const std::vector<Expected> expected = expected_messages();
  for (const char* name : {"lz4.mcap", "zstd_crc.mcap", "mcap_zstd/mcap_zstd.mcap"}) {
    const std::vector<std::uint8_t> bytes = bytes_of(bags() / name);
    const std::size_t data_end = first_record(bytes, 0x0F);
    const std::size_t data_end_length = bytes[data_end + 1];  // 4 (a CRC); its other length bytes are 0
    const std::size_t fields_end = first_record(bytes, 0x06) + 64;
    for (std::size_t size = 0; size < bytes.size(); size += size < fields_end ? 1 : 31) {
      const fs::path cut = write_variant("cut.mcap", std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size)));
      if (size >= data_end + 9 + data_end_length) {
        auto reader = bag::open_mcap(cut);
        EXPECT_EQ(read_all(*reader, {"/cam0/image_raw", "/imu0", "/cam0/camera_info"}).size(), expected.size());
      } else {
        const std::string message = invalid_input_from([&] { open_and_read_everything(cut); });
        EXPECT_NE(message.find("cut.mcap"), std::string::npos) << name << " cut to " << size << ": " << message;
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
}

TEST(Ros2Mcap, TruncatedChunkNamesItsOffset) {
  std::vector<std::uint8_t> bytes = bytes_of(bags() / "lz4.mcap");
  const std::size_t chunk = first_record(bytes, 0x06);
  bytes.resize(chunk + 40);
  const std::string message = invalid_input_from([&] { bag::open_mcap(write_variant("truncated.mcap", bytes)); });
  EXPECT_NE(message.find("damaged"), std::string::npos) << message;
  EXPECT_NE(message.find("Chunk record at byte " + std::to_string(chunk)), std::string::npos) << message;
}

TEST(Ros2Mcap, BadZstdFrameIsRefused) {
  std::vector<std::uint8_t> bytes = bytes_of(bags() / "mcap_zstd/mcap_zstd.mcap");  // rosbags: no CRC
  bytes[find(bytes, {0x28, 0xB5, 0x2F, 0xFD}, first_record(bytes, 0x06))] ^= 0xFF;  // the frame's magic
  const std::string message = invalid_input_from([&] { bag::open_mcap(write_variant("bad_zstd.mcap", bytes)); });
  EXPECT_NE(message.find("zstd data is invalid"), std::string::npos) << message;
}

TEST(Ros2Mcap, BadLz4FrameIsRefused) {
  std::vector<std::uint8_t> bytes = bytes_of(bags() / "lz4.mcap");
  bytes[find(bytes, {0x04, 0x22, 0x4D, 0x18}, first_record(bytes, 0x06))] ^= 0xFF;  // the frame's magic
  const std::string message = invalid_input_from([&] { bag::open_mcap(write_variant("bad_lz4.mcap", bytes)); });
  EXPECT_NE(message.find("LZ4 frame is invalid"), std::string::npos) << message;
}

TEST(Ros2Mcap, WrongChunkCrcIsRefused) {
  for (const char* name : {"zstd_crc.mcap", "lz4.mcap", "plain_crc.mcap"}) {
    std::vector<std::uint8_t> bytes = bytes_of(bags() / name);
    const std::size_t chunk = first_record(bytes, 0x06);
    // Chunk: message_start_time, message_end_time, uncompressed_size (u64 each), then the CRC.
    bytes[chunk + 9 + 24] ^= 0x01;
    const std::string message = invalid_input_from([&] { bag::open_mcap(write_variant("bad_crc.mcap", bytes)); });
    EXPECT_NE(message.find("fails its CRC check"), std::string::npos) << name << ": " << message;
  }
}

TEST(Ros2Mcap, WrongUncompressedSizeIsRefused) {
  for (const char* name : {"zstd_crc.mcap", "lz4.mcap", "plain_crc.mcap"}) {
    for (const int delta : {-1, 1}) {
      std::vector<std::uint8_t> bytes = bytes_of(bags() / name);
      const std::size_t chunk = first_record(bytes, 0x06);
      bytes[chunk + 9 + 16] = static_cast<std::uint8_t>(bytes[chunk + 9 + 16] + delta);  // uncompressed_size's low byte
      const std::string message = invalid_input_from([&] { bag::open_mcap(write_variant("bad_size.mcap", bytes)); });
      EXPECT_NE(message.find("Chunk record at byte " + std::to_string(chunk)), std::string::npos) << name << ": " << message;
    }
  }
}

TEST(Ros2Mcap, UnknownCompressionIsRefusedByName) {
  std::vector<std::uint8_t> bytes = bytes_of(bags() / "lz4.mcap");
  const std::size_t at = find(bytes, {'l', 'z', '4'}, first_record(bytes, 0x06));
  bytes[at] = 'x';
  const std::string message = invalid_input_from([&] { bag::open_mcap(write_variant("xz4.mcap", bytes)); });
  EXPECT_NE(message.find("\"xz4\""), std::string::npos) << message;
}

TEST(Ros2Mcap, NotAnMcapFile) {
  const std::string message = invalid_input_from([] { bag::open_mcap(bags() / "expected.json"); });
  EXPECT_NE(message.find("not an MCAP file"), std::string::npos) << message;
}

}  // namespace
