// SPDX-License-Identifier: Apache-2.0
// ROS 1 bags (src/io/bag/ros1_bag.cpp) and the sensor_msgs decoders (ros_messages.hpp) over the
// field reader for both encodings (src/io/bag/message_fields.hpp). The bags are written here by
// a small writer of the format's records (http://wiki.ros.org/Bags/Format/2.0), so that damage
// can be placed exactly; the CLI test (tests/cli/ros_bags.cmake) reads bags that rosbags wrote.
#include <gtest/gtest.h>

#include <bzlib.h>
#include <lz4frame.h>

#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "inertialnet/io/bag.hpp"
#include "inertialnet/io/bag_source.hpp"
#include "inertialnet/io/ros_messages.hpp"
#include "inertialnet/runtime/error.hpp"
#include "io/bag/containers.hpp"
#include "io/bag/message_fields.hpp"
#include "support/testing.hpp"

namespace fs = std::filesystem;
using namespace inertialnet;
using inertialnet::testing::contains;
using inertialnet::testing::invalid_input_message;
using Bytes = std::vector<std::uint8_t>;

namespace {

// --- serialised messages ---------------------------------------------------------------------

// Writes fields as ROS 1 (packed little-endian) or CDR (aligned, little- or big-endian).
class Writer {
 public:
  Writer(MessageEncoding encoding, bool big_endian = false) : encoding_(encoding), big_(big_endian) {
    if (encoding_ == MessageEncoding::Cdr) bytes = {0, static_cast<std::uint8_t>(big_ ? 0 : 1), 0, 0};
  }
  void u8(std::uint8_t v) { bytes.push_back(v); }
  void u32(std::uint32_t v) { put(v, 4); }
  void f64(double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    put(bits, 8);
  }
  void string(const std::string& s) {
    const bool cdr = encoding_ == MessageEncoding::Cdr;
    u32(static_cast<std::uint32_t>(s.size() + (cdr ? 1 : 0)));
    bytes.insert(bytes.end(), s.begin(), s.end());
    if (cdr) bytes.push_back(0);
  }
  void header(std::int64_t stamp_ns, const std::string& frame = "cam0") {
    if (encoding_ == MessageEncoding::Ros1) u32(7);  // seq
    u32(static_cast<std::uint32_t>(stamp_ns / 1000000000));
    u32(static_cast<std::uint32_t>(stamp_ns % 1000000000));
    string(frame);
  }
  void byte_sequence(const Bytes& b) {
    u32(static_cast<std::uint32_t>(b.size()));
    bytes.insert(bytes.end(), b.begin(), b.end());
  }
  Bytes bytes;

 private:
  void put(std::uint64_t v, int n) {
    if (encoding_ == MessageEncoding::Cdr) {
      while ((bytes.size() - 4) % static_cast<std::size_t>(n)) bytes.push_back(0xAA);  // padding is not read
    }
    for (int i = 0; i < n; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * (big_ ? n - 1 - i : i))));
  }
  MessageEncoding encoding_;
  bool big_;
};

BagMessage message_of(const BagConnection& connection, Bytes data) {
  BagMessage m;
  m.connection = &connection;
  m.data = std::move(data);
  return m;
}

BagConnection connection(const std::string& type, MessageEncoding encoding) {
  BagConnection c;
  c.topic = "/t";
  c.type = type;
  c.encoding = encoding;
  return c;
}

Bytes image_message(MessageEncoding encoding, bool big, const std::string& pixel_encoding, std::uint32_t w, std::uint32_t h,
                    std::uint32_t step, const Bytes& data, bool data_big_endian = false) {
  Writer m(encoding, big);
  m.header(1403636579763555584);
  m.u32(h);
  m.u32(w);
  m.string(pixel_encoding);
  m.u8(data_big_endian ? 1 : 0);
  m.u32(step);
  m.byte_sequence(data);
  return m.bytes;
}

// --- a ROS 1 bag, written record by record -----------------------------------------------------

void le32(Bytes& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
Bytes field(const std::string& name, const Bytes& value) {
  Bytes f;
  le32(f, static_cast<std::uint32_t>(name.size() + 1 + value.size()));
  f.insert(f.end(), name.begin(), name.end());
  f.push_back('=');
  f.insert(f.end(), value.begin(), value.end());
  return f;
}
Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }
Bytes u32_bytes(std::uint32_t v) {
  Bytes b;
  le32(b, v);
  return b;
}
Bytes record(const std::vector<Bytes>& fields, const Bytes& data) {
  Bytes header;
  for (const Bytes& f : fields) header.insert(header.end(), f.begin(), f.end());
  Bytes r;
  le32(r, static_cast<std::uint32_t>(header.size()));
  r.insert(r.end(), header.begin(), header.end());
  le32(r, static_cast<std::uint32_t>(data.size()));
  r.insert(r.end(), data.begin(), data.end());
  return r;
}
Bytes connection_record(std::uint32_t id, const std::string& topic, const std::string& type) {
  Bytes details;
  for (const Bytes& f : {field("topic", text(topic)), field("type", text(type)), field("md5sum", text("060021388200f6f0f447d0fcd9c64743")),
                         field("message_definition", text("..."))}) {
    details.insert(details.end(), f.begin(), f.end());
  }
  return record({field("op", {0x07}), field("conn", u32_bytes(id)), field("topic", text(topic))}, details);
}
Bytes message_record(std::uint32_t id, std::uint32_t sec, const Bytes& data) {
  Bytes time = u32_bytes(sec);
  le32(time, 0);
  return record({field("op", {0x02}), field("conn", u32_bytes(id)), field("time", time)}, data);
}

Bytes compress(const std::string& how, const Bytes& plain) {
  if (how == "none") return plain;
  if (how == "bz2") {
    Bytes out(plain.size() * 2 + 600);
    unsigned int n = static_cast<unsigned int>(out.size());
    EXPECT_EQ(BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &n, reinterpret_cast<char*>(const_cast<std::uint8_t*>(plain.data())),
                                       static_cast<unsigned int>(plain.size()), 9, 0, 0),
              BZ_OK);
    out.resize(n);
    return out;
  }
  Bytes out(LZ4F_compressFrameBound(plain.size(), nullptr));
  const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), plain.data(), plain.size(), nullptr);
  EXPECT_FALSE(LZ4F_isError(n));
  out.resize(n);
  return out;
}

// Three messages on /a (sensor_msgs/Imu, their payloads "m0".."m2") and one on /b, in one chunk
// compressed `how`, then the index section (connections, chunk info) unless `indexed` is false.
struct BagBytes {
  Bytes bytes;
  std::size_t chunk_data_offset = 0;  // of the chunk's compressed bytes
};
BagBytes bag_bytes(const std::string& how, bool indexed = true) {
  Bytes chunk;
  for (const Bytes& r : {connection_record(0, "/a", "sensor_msgs/Imu"), message_record(0, 10, text("m0")),
                         connection_record(1, "/b", "std_msgs/String"), message_record(1, 11, text("b0")),
                         message_record(0, 12, text("m1")), message_record(0, 13, text("m2"))}) {
    chunk.insert(chunk.end(), r.begin(), r.end());
  }
  BagBytes out;
  out.bytes = text("#ROSBAG V2.0\n");
  Bytes chunks = record({field("op", {0x05}), field("compression", text(how)), field("size", u32_bytes(static_cast<std::uint32_t>(chunk.size())))},
                        compress(how, chunk));
  Bytes index;
  if (indexed) {
    for (const Bytes& r : {connection_record(0, "/a", "sensor_msgs/Imu"), connection_record(1, "/b", "std_msgs/String")}) {
      index.insert(index.end(), r.begin(), r.end());
    }
    Bytes counts;
    for (std::uint32_t v : {0u, 3u, 1u, 1u}) le32(counts, v);
    Bytes t = u32_bytes(10);
    le32(t, 0);
    const Bytes info = record({field("op", {0x06}), field("ver", u32_bytes(1)), field("chunk_pos", Bytes(8, 0)), field("start_time", t),
                               field("end_time", t), field("count", u32_bytes(2))},
                              counts);
    index.insert(index.end(), info.begin(), info.end());
  }
  Bytes position(8, 0);
  const std::uint64_t index_pos = indexed ? out.bytes.size() + 4096 + chunks.size() : 0;
  for (int i = 0; i < 8; ++i) position[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(index_pos >> (8 * i));
  // rosbag pads the bag header record to 4096 bytes with spaces in its data.
  const std::vector<Bytes> header_fields = {field("op", {0x03}), field("index_pos", position), field("conn_count", u32_bytes(2)),
                                            field("chunk_count", u32_bytes(1))};
  std::size_t fields_size = 0;
  for (const Bytes& f : header_fields) fields_size += f.size();
  const Bytes header = record(header_fields, Bytes(4096 - 8 - fields_size, ' '));
  out.bytes.insert(out.bytes.end(), header.begin(), header.end());
  const std::uint32_t chunk_fields = chunks[0] | chunks[1] << 8 | chunks[2] << 16 | static_cast<std::uint32_t>(chunks[3]) << 24;
  out.chunk_data_offset = out.bytes.size() + 4 + chunk_fields + 4;
  out.bytes.insert(out.bytes.end(), chunks.begin(), chunks.end());
  out.bytes.insert(out.bytes.end(), index.begin(), index.end());
  return out;
}

// A bag of one uncompressed chunk holding `records` and no index section (as a recorder that was
// killed leaves it): the reader finds the connections in the chunk.
Bytes unindexed_bag(const std::vector<Bytes>& records) {
  Bytes chunk;
  for (const Bytes& r : records) chunk.insert(chunk.end(), r.begin(), r.end());
  Bytes out = text("#ROSBAG V2.0\n");
  const std::vector<Bytes> header_fields = {field("op", {0x03}), field("index_pos", Bytes(8, 0)), field("conn_count", u32_bytes(0)),
                                            field("chunk_count", u32_bytes(0))};
  std::size_t fields_size = 0;
  for (const Bytes& f : header_fields) fields_size += f.size();
  const Bytes header = record(header_fields, Bytes(4096 - 8 - fields_size, ' '));
  const Bytes chunks = record({field("op", {0x05}), field("compression", text("none")), field("size", u32_bytes(static_cast<std::uint32_t>(chunk.size())))}, chunk);
  out.insert(out.end(), header.begin(), header.end());
  out.insert(out.end(), chunks.begin(), chunks.end());
  return out;
}

fs::path write_file(const std::string& name, const Bytes& bytes) {
  const fs::path p = fs::path(inertialnet::testing::temporary_directory("ros1_bags")) / name;
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return p;
}

// Every message on `topics`, as "topic:payload@seconds".
std::vector<std::string> read_all(BagReader& reader, const std::vector<std::string>& topics) {
  std::vector<std::string> out;
  auto cursor = reader.read(topics);
  BagMessage m;
  while (cursor->next(m)) {
    out.push_back(m.connection->topic + ":" + std::string(m.data.begin(), m.data.end()) + "@" + std::to_string(m.log_time_ns / 1000000000));
  }
  return out;
}

}  // namespace

// --- the field reader ----------------------------------------------------------------------------

TEST(MessageFields, Ros1IsPackedLittleEndianWithSeqAndStringsWithoutNul) {
  Writer w(MessageEncoding::Ros1);
  w.header(5 * 1000000000LL + 25);
  w.u8(3);
  w.f64(-1.5);  // unaligned: ROS 1 packs
  w.string("abc");
  ASSERT_EQ(w.bytes.size(), 4u + 8u + 4u + 4u + 1u + 8u + 4u + 3u);
  bag::MessageFields f(w.bytes.data(), w.bytes.size(), MessageEncoding::Ros1, "m");
  EXPECT_EQ(f.header_stamp_ns(), 5000000025);
  EXPECT_EQ(f.u8(), 3);
  EXPECT_EQ(f.f64(), -1.5);
  EXPECT_EQ(f.string(), "abc");
}

TEST(MessageFields, CdrAlignsFromAfterTheEncapsulationHeaderInBothByteOrders) {
  for (const bool big : {false, true}) {
    Writer w(MessageEncoding::Cdr, big);
    w.header(7 * 1000000000LL + 9, "c");  // 4 + 4 + (4 + 2): the next f64 needs padding to 8
    w.u8(1);
    w.f64(2.25);
    w.string("xyz");
    w.u32(0xA1B2C3D4u);
    // sec, nanosec, "c\0" (len 2) → 14 bytes; u8 → 15; pad to 16; f64 → 24; string 4+4 → 32; u32 → 36
    ASSERT_EQ(w.bytes.size(), 4u + 36u) << big;
    bag::MessageFields f(w.bytes.data(), w.bytes.size(), MessageEncoding::Cdr, "m");
    EXPECT_EQ(f.big_endian(), big);
    EXPECT_EQ(f.header_stamp_ns(), 7000000009);
    EXPECT_EQ(f.u8(), 1);
    EXPECT_EQ(f.f64(), 2.25);
    EXPECT_EQ(f.string(), "xyz");
    EXPECT_EQ(f.u32(), 0xA1B2C3D4u);
  }
}

TEST(MessageFields, ShortOrMalformedMessagesAreInvalidInput) {
  Writer w(MessageEncoding::Ros1);
  w.header(1);
  const Bytes cut(w.bytes.begin(), w.bytes.end() - 2);
  EXPECT_TRUE(contains(invalid_input_message([&] {
                         bag::MessageFields f(cut.data(), cut.size(), MessageEncoding::Ros1, "message 4 of /x");
                         f.header_stamp_ns();
                       }),
                       "message 4 of /x"));
  Writer c(MessageEncoding::Cdr);
  c.u32(3);  // a string length of 3 without a NUL at its end
  c.bytes.insert(c.bytes.end(), {'a', 'b', 'c'});
  EXPECT_TRUE(contains(invalid_input_message([&] {
                         bag::MessageFields f(c.bytes.data(), c.bytes.size(), MessageEncoding::Cdr, "m");
                         f.string();
                       }),
                       "NUL"));
  const Bytes pl_cdr = {0, 3, 0, 0, 1, 2, 3, 4};
  EXPECT_TRUE(contains(invalid_input_message([&] { bag::MessageFields(pl_cdr.data(), pl_cdr.size(), MessageEncoding::Cdr, "m"); }),
                       "not plain CDR"));
  // A sequence count far beyond the message's bytes is refused before anything is allocated.
  Writer s(MessageEncoding::Ros1);
  s.u32(0xFFFFFFF0u);
  EXPECT_TRUE(contains(invalid_input_message([&] {
                         bag::MessageFields f(s.bytes.data(), s.bytes.size(), MessageEncoding::Ros1, "m");
                         f.byte_sequence();
                       }),
                       "ends"));
}

// --- sensor_msgs ---------------------------------------------------------------------------------

TEST(RosMessages, TypesInBothSpellings) {
  EXPECT_EQ(ros_message_kind("sensor_msgs/Image"), RosMessageKind::Image);
  EXPECT_EQ(ros_message_kind("sensor_msgs/msg/Image"), RosMessageKind::Image);
  EXPECT_EQ(ros_message_kind("sensor_msgs/msg/CompressedImage"), RosMessageKind::CompressedImage);
  EXPECT_EQ(ros_message_kind("sensor_msgs/Imu"), RosMessageKind::Imu);
  EXPECT_EQ(ros_message_kind("sensor_msgs/msg/CameraInfo"), RosMessageKind::CameraInfo);
  EXPECT_EQ(ros_message_kind("std_msgs/String"), RosMessageKind::Other);
}

TEST(RosMessages, ImagesOfEveryEncodingInBothSerialisations) {
  // 2 × 1 pixels; the second row of bytes is step padding, which is not pixels.
  struct Case {
    std::string encoding;
    Bytes data;
    std::uint32_t step;
    bool big;
    float r0, g0, b0;  // pixel 0 as planar RGB 0..255
  };
  const std::vector<Case> cases = {
      {"mono8", {10, 20, 99, 99}, 4, false, 10, 10, 10},
      {"8UC1", {10, 20}, 2, false, 10, 10, 10},
      {"mono16", {0x01, 0x02, 0, 0}, 4, false, 0x0201 / 257.0f, 0x0201 / 257.0f, 0x0201 / 257.0f},
      {"mono16", {0x01, 0x02, 0, 0}, 4, true, 0x0102 / 257.0f, 0x0102 / 257.0f, 0x0102 / 257.0f},
      {"rgb8", {1, 2, 3, 4, 5, 6}, 6, false, 1, 2, 3},
      {"bgr8", {1, 2, 3, 4, 5, 6}, 6, false, 3, 2, 1},
      {"8UC3", {1, 2, 3, 4, 5, 6}, 6, false, 3, 2, 1},
      {"rgba8", {1, 2, 3, 255, 4, 5, 6, 255}, 8, false, 1, 2, 3},
      {"bgra8", {1, 2, 3, 255, 4, 5, 6, 255}, 8, false, 3, 2, 1},
  };
  for (const MessageEncoding encoding : {MessageEncoding::Ros1, MessageEncoding::Cdr}) {
    const BagConnection c = connection(encoding == MessageEncoding::Cdr ? "sensor_msgs/msg/Image" : "sensor_msgs/Image", encoding);
    for (const Case& k : cases) {
      const BagMessage m = message_of(c, image_message(encoding, encoding == MessageEncoding::Cdr, k.encoding, 2, 1, k.step, k.data, k.big));
      const HostImage image = decode_ros_image(m, "m");
      ASSERT_EQ(image.width, 2) << k.encoding;
      ASSERT_EQ(image.height, 1);
      EXPECT_FLOAT_EQ(image.at(0, 0, 0), k.r0) << k.encoding << (k.big ? " big-endian" : "");
      EXPECT_FLOAT_EQ(image.at(1, 0, 0), k.g0) << k.encoding;
      EXPECT_FLOAT_EQ(image.at(2, 0, 0), k.b0) << k.encoding;
      EXPECT_EQ(ros_header_stamp_ns(m, "m"), 1403636579763555584);
    }
  }
}

TEST(RosMessages, BayerAndShortImagesAreRefusedByName) {
  const BagConnection c = connection("sensor_msgs/Image", MessageEncoding::Ros1);
  const std::string bayer = invalid_input_message(
      [&] { decode_ros_image(message_of(c, image_message(MessageEncoding::Ros1, false, "bayer_rggb8", 2, 2, 2, Bytes(4))), "message 0"); });
  EXPECT_TRUE(contains(bayer, "bayer_rggb8")) << bayer;
  EXPECT_TRUE(contains(bayer, "mono8, mono16, rgb8, bgr8, rgba8")) << bayer;
  const std::string other = invalid_input_message(
      [&] { decode_ros_image(message_of(c, image_message(MessageEncoding::Ros1, false, "32FC1", 1, 1, 4, Bytes(4))), "m"); });
  EXPECT_TRUE(contains(other, "'32FC1'")) << other;
  const std::string short_data = invalid_input_message(
      [&] { decode_ros_image(message_of(c, image_message(MessageEncoding::Ros1, false, "rgb8", 4, 4, 12, Bytes(40))), "m"); });
  EXPECT_TRUE(contains(short_data, "needs 48 bytes")) << short_data;
  const std::string odd_step = invalid_input_message(
      [&] { decode_ros_image(message_of(c, image_message(MessageEncoding::Ros1, false, "mono16", 2, 2, 5, Bytes(10))), "m"); });
  EXPECT_TRUE(contains(odd_step, "odd row step of 5 bytes")) << odd_step;
}

TEST(RosMessages, ImuAndCameraInfo) {
  for (const MessageEncoding encoding : {MessageEncoding::Ros1, MessageEncoding::Cdr}) {
    const BagConnection imu = connection("sensor_msgs/Imu", encoding);
    Writer w(encoding);
    w.header(2000000003);
    for (int i = 0; i < 13; ++i) w.f64(100 + i);  // orientation, covariance
    for (double v : {0.1, -0.2, 0.3}) w.f64(v);
    for (int i = 0; i < 9; ++i) w.f64(0);
    for (double v : {9.8, 0.0, -0.5}) w.f64(v);
    for (int i = 0; i < 9; ++i) w.f64(0);
    const ImuSample s = decode_ros_imu(message_of(imu, w.bytes), "m");
    EXPECT_EQ(s.t_ns, 2000000003);
    EXPECT_EQ(s.gyro, (Vec3{0.1, -0.2, 0.3}));
    EXPECT_EQ(s.accel, (Vec3{9.8, 0.0, -0.5}));

    const BagConnection info = connection("sensor_msgs/msg/CameraInfo", encoding);
    for (const std::string model : {"plumb_bob", "equidistant", "rational_polynomial"}) {
      Writer k(encoding);
      k.header(1);
      k.u32(480);
      k.u32(752);
      k.string(model);
      const std::vector<double> d = model == "equidistant" ? std::vector<double>{0.1, 0.2, 0.3, 0.4}
                                    : model == "plumb_bob" ? std::vector<double>{-0.28, 0.07, 0.0002, 0.00002, 0}
                                                           : std::vector<double>(8, 0.01);
      k.u32(static_cast<std::uint32_t>(d.size()));
      for (double v : d) k.f64(v);
      for (double v : {458.6, 0.0, 367.2, 0.0, 457.3, 248.4, 0.0, 0.0, 1.0}) k.f64(v);
      const BagMessage m = message_of(info, k.bytes);
      if (model == "rational_polynomial") {
        EXPECT_TRUE(contains(invalid_input_message([&] { decode_ros_camera_info(m, "m"); }), "rational_polynomial"));
        continue;
      }
      const CameraCalibration c = decode_ros_camera_info(m, "m");
      EXPECT_EQ(c.width, 752);
      EXPECT_EQ(c.height, 480);
      EXPECT_EQ(c.intrinsics, (std::array<double, 4>{458.6, 457.3, 367.2, 248.4}));
      EXPECT_EQ(c.distortion_model, model == "plumb_bob" ? "radial-tangential" : "equidistant");
      EXPECT_EQ(c.distortion.size(), 4u);  // plumb_bob's zero k3 dropped: the same lens
      EXPECT_EQ(c.T_BS, (std::array<double, 16>{}));  // CameraInfo has no extrinsics
    }
  }
}

TEST(RosMessages, AMessageOfAnotherTypeIsNamed) {
  const BagConnection c = connection("std_msgs/String", MessageEncoding::Ros1);
  EXPECT_TRUE(contains(invalid_input_message([&] { decode_ros_imu(message_of(c, Bytes(200)), "m"); }), "std_msgs/String"));
}

// --- ROS 1 bags ----------------------------------------------------------------------------------

TEST(Ros1Bag, ReadsEveryCompressionIndexedOrNot) {
  for (const std::string how : {"none", "bz2", "lz4"}) {
    for (const bool indexed : {true, false}) {
      const fs::path p = write_file(how + (indexed ? "_indexed.bag" : ".bag"), bag_bytes(how, indexed).bytes);
      ASSERT_TRUE(bag::looks_like_ros1_bag(p));
      ASSERT_TRUE(is_bag(p));
      const auto reader = open_bag(p);
      ASSERT_EQ(reader->connections().size(), 2u) << how;
      EXPECT_EQ(reader->connections()[0].topic, "/a");
      EXPECT_EQ(reader->connections()[0].type, "sensor_msgs/Imu");
      EXPECT_EQ(reader->connections()[0].message_count, 3u) << how << indexed;
      EXPECT_EQ(reader->connections()[1].message_count, 1u);
      EXPECT_EQ(read_all(*reader, {"/a"}), (std::vector<std::string>{"/a:m0@10", "/a:m1@12", "/a:m2@13"})) << how;
      EXPECT_EQ(read_all(*reader, {"/a", "/b"}).size(), 4u);
      EXPECT_TRUE(read_all(*reader, {"/nothing"}).empty());
      EXPECT_TRUE(contains(reader->description(), p.string()));
    }
  }
}

TEST(Ros1Bag, TruncatedAnywhereIsInvalidInputNeverACrash) {
  for (const std::string how : {"none", "bz2", "lz4"}) {
    const Bytes whole = bag_bytes(how).bytes;
    // Every cut shorter than the whole: opening or reading throws invalid_input, or (a cut in the
    // index section, after the chunk) reads messages that were whole.
    for (std::size_t n = 13; n < whole.size(); n += (n < 4200 ? 97 : 1)) {
      const fs::path p = write_file("cut.bag", Bytes(whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(n)));
      try {
        const auto reader = bag::open_ros1_bag(p);
        for (const std::string& m : read_all(*reader, {"/a", "/b"})) EXPECT_EQ(m.size(), 8u) << m;
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << e.what();
        EXPECT_TRUE(contains(e.what(), p.string())) << e.what();
        EXPECT_TRUE(contains(e.what(), "byte") || contains(e.what(), "bag header")) << e.what();
      }
    }
  }
}

TEST(Ros1Bag, DamagedCompressedChunksAreInvalidInputNamingTheOffset) {
  for (const std::string how : {"bz2", "lz4"}) {
    BagBytes bag = bag_bytes(how);
    bag.bytes[bag.chunk_data_offset] ^= 0xFF;  // the frame's magic number (lz4) or "BZh" (bz2)
    const fs::path p = write_file("damaged.bag", bag.bytes);
    const std::string message = invalid_input_message([&] {
      const auto reader = bag::open_ros1_bag(p);
      read_all(*reader, {"/a"});
    });
    EXPECT_TRUE(contains(message, how + " chunk")) << message;
    EXPECT_TRUE(contains(message, "at byte 4109")) << message;  // the chunk record, after the 4096-byte bag header
  }
  // A chunk whose declared size is not what its frame holds.
  BagBytes bag = bag_bytes("lz4");
  const fs::path p = write_file("cut_frame.bag", [&] {
    Bytes b = bag.bytes;
    b[bag.chunk_data_offset + 20] ^= 0x5A;  // inside the compressed block
    return b;
  }());
  try {
    const auto reader = bag::open_ros1_bag(p);
    read_all(*reader, {"/a", "/b"});
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << e.what();
  }
}

// A damaged size field must not make the reader allocate what it declares (a gigabyte here): LZ4's
// is bounded by its 255-fold expansion, bzip2's output grows with what the stream makes.
TEST(Ros1Bag, ACompressedChunkDeclaringAGigabyteIsRefusedWithoutAllocatingIt) {
  for (const std::string how : {"lz4", "bz2"}) {
    Bytes bag = bag_bytes("none").bytes;
    const Bytes huge = record({field("op", {0x05}), field("compression", text(how)), field("size", u32_bytes(1000000000u))},
                              compress(how, text("tiny")));
    bag.insert(bag.end(), huge.begin(), huge.end());
    const fs::path p = write_file("huge.bag", bag);
    const std::string message = invalid_input_message([&] {
      const auto reader = bag::open_ros1_bag(p);
      read_all(*reader, {"/a"});
    });
    EXPECT_TRUE(contains(message, how == "lz4" ? "declares 1000000000 uncompressed bytes, more than LZ4 can hold"
                                               : "does not decompress to the 1000000000 bytes it declares"))
        << message;
  }
}

TEST(Ros1Bag, OtherVersionsAndOtherFilesAreRefusedByName) {
  const fs::path old = write_file("old.bag", text("#ROSBAG V1.2\nrest"));
  EXPECT_TRUE(is_bag(old));
  const std::string message = invalid_input_message([&] { open_bag(old); });
  EXPECT_TRUE(contains(message, "format 1.2")) << message;
  const fs::path other = write_file("other.bag", text("not a bag at all"));
  EXPECT_FALSE(bag::looks_like_ros1_bag(other));
  EXPECT_TRUE(contains(invalid_input_message([&] { bag::open_ros1_bag(other); }), "not a ROS 1 bag"));
  Bytes unknown = bag_bytes("none").bytes;
  const Bytes bad_chunk = record({field("op", {0x05}), field("compression", text("zstd")), field("size", u32_bytes(1))}, Bytes(1));
  unknown.insert(unknown.end(), bad_chunk.begin(), bad_chunk.end());
  const fs::path zstd = write_file("zstd.bag", unknown);
  const std::string refused = invalid_input_message([&] {
    const auto reader = bag::open_ros1_bag(zstd);
    read_all(*reader, {"/a"});
  });
  EXPECT_TRUE(contains(refused, "'zstd'")) << refused;
}

// --- a bag as a sequence -------------------------------------------------------------------------

TEST(BagFrameSource, HeaderStampsMustIncreaseAndTopicsAreNamed) {
  const Bytes pixels = {1, 2, 3, 4};
  auto image = [&](std::int64_t stamp) {
    Writer m(MessageEncoding::Ros1);
    m.header(stamp);
    m.u32(2);
    m.u32(2);
    m.string("mono8");
    m.u8(0);
    m.u32(2);
    m.byte_sequence(pixels);
    return m.bytes;
  };
  const std::int64_t s = 1000000000;
  // Log times in order, header stamps not: the stamps are what is checked.
  const fs::path backwards = write_file("backwards.bag", unindexed_bag({connection_record(0, "/cam/image", "sensor_msgs/Image"),
                                                                        message_record(0, 1, image(3 * s)), message_record(0, 2, image(5 * s)),
                                                                        message_record(0, 3, image(4 * s))}));
  const std::string message = invalid_input_message([&] { open_bag_frame_source(backwards, {}); });
  EXPECT_TRUE(contains(message, "message 2 of /cam/image")) << message;
  EXPECT_TRUE(contains(message, "goes back")) << message;

  const fs::path good = write_file("good.bag", unindexed_bag({connection_record(0, "/cam/image", "sensor_msgs/Image"),
                                                              connection_record(1, "/imu", "sensor_msgs/Imu"),
                                                              message_record(0, 9, image(3 * s)), message_record(0, 8, image(5 * s))}));
  const auto source = open_bag_frame_source(good, {});
  ASSERT_EQ(source->size(), 2u);
  EXPECT_EQ(source->timestamp_ns(1), 5 * s);  // the header stamp, not the log time (8 s)
  EXPECT_TRUE(source->sequential());
  EXPECT_EQ(source->decode(0).at(0, 1, 1), 4.0f);
  EXPECT_EQ(source->decode(0).at(0, 1, 1), 4.0f);  // the frame decoded last, asked again
  EXPECT_EQ(source->decode(1).width, 2);
  EXPECT_FALSE(source->calibration());
  const std::string missing = invalid_input_message([&] { open_bag_frame_source(good, {"/cam1/image", "", ""}); });
  EXPECT_TRUE(contains(missing, "/cam/image (sensor_msgs/Image, 2 messages), /imu (sensor_msgs/Imu, 0 messages)")) << missing;
  std::vector<std::string> notes;
  EXPECT_TRUE(contains(invalid_input_message([&] { read_bag_imu(good, {}, notes); }), "holds 0 messages"));
}

TEST(RosMessages, CompressedImagesDecodeAsOpenCvEncodedThem) {
  cv::Mat bgr(6, 8, CV_8UC3);
  cv::randu(bgr, 0, 255);
  for (const std::string format : {"png", "jpeg"}) {
    std::vector<unsigned char> encoded;
    ASSERT_TRUE(cv::imencode(format == "png" ? ".png" : ".jpg", bgr, encoded));
    const cv::Mat expected = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);  // a JPEG is lossy: its own decoding
    for (const MessageEncoding encoding : {MessageEncoding::Ros1, MessageEncoding::Cdr}) {
      const BagConnection c = connection("sensor_msgs/msg/CompressedImage", encoding);
      Writer w(encoding);
      w.header(42);
      w.string("bgr8; " + format + " compressed bgr8");
      w.byte_sequence(Bytes(encoded.begin(), encoded.end()));
      const HostImage image = decode_ros_image(message_of(c, w.bytes), "m");
      ASSERT_EQ(image.width, 8);
      ASSERT_EQ(image.height, 6);
      for (int y = 0; y < 6; ++y) {
        for (int x = 0; x < 8; ++x) {
          const cv::Vec3b p = expected.at<cv::Vec3b>(y, x);
          EXPECT_EQ(image.at(0, y, x), p[2]) << format;
          EXPECT_EQ(image.at(2, y, x), p[0]) << format;
        }
      }
      // Cut short: named as a truncated image, not decoded with a grey bottom.
      Writer cut(encoding);
      cut.header(42);
      cut.string(format);
      cut.byte_sequence(Bytes(encoded.begin(), encoded.end() - 10));
      EXPECT_TRUE(contains(invalid_input_message([&] { decode_ros_image(message_of(c, cut.bytes), "message 3"); }), "message 3 is truncated"));
    }
  }
}
