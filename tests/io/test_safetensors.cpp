// SPDX-License-Identifier: Apache-2.0
// The safetensors reader and writer: round trips, every malformed-file error (files written byte
// by byte here), exact F16 conversion, and the model-fit check's single error message.
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/io/weight_fit.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "inertialnet/runtime/error.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

class SafetensorsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "inertialnet_safetensors_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    for (const auto& file : created_) std::remove(file.c_str());
    ::rmdir(dir_.c_str());
  }

  // True when the atomic writer left a temporary file beside `file`.
  bool temporary_left_beside(const std::string& file) const {
    const std::string prefix = std::filesystem::path(file).filename().string() + ".tmp";
    for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
      if (entry.path().filename().string().rfind(prefix, 0) == 0) return true;
    }
    return false;
  }

  std::string path(const std::string& name) {
    created_.push_back(dir_ + "/" + name);
    return created_.back();
  }

  // A file made of exactly `bytes`.
  std::string write_raw(const std::string& name, const std::string& bytes) {
    const std::string p = path(name);
    std::ofstream out(p, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p;
  }

  // The 8-byte little-endian length, the header text as given, then `data`.
  std::string write_file(const std::string& name, const std::string& header, const std::string& data = "") {
    return write_raw(name, length_prefix(header.size()) + header + data);
  }

  static std::string length_prefix(uint64_t n) {
    std::string bytes(8, '\0');
    for (int i = 0; i < 8; ++i) bytes[i] = static_cast<char>((n >> (8 * i)) & 0xFF);
    return bytes;
  }

  static std::string float_bytes(std::initializer_list<float> values) {
    std::string bytes;
    for (float v : values) bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
    return bytes;
  }

  static std::string read_all(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

  bool exists(const std::string& p) { return ::access(p.c_str(), F_OK) == 0; }

  std::string dir_;
  std::vector<std::string> created_;
};

// Runs `f`, expects an invalid_input Error whose message contains every one of `parts`.
void expect_invalid_input(const std::function<void()>& f, std::initializer_list<std::string> parts) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << e.what();
    for (const auto& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
        << "message \"" << e.what() << "\" lacks \"" << part << "\"";
    return;
  }
  ADD_FAILURE() << "no inertialnet::Error thrown";
}

TEST_F(SafetensorsTest, RoundTripKeepsNamesShapesValuesAndMetadata) {
  const std::string p = path("round.safetensors");
  std::vector<HostTensor> tensors = {
      {{"z.first", {2, 3}}, {1.0f, -2.5f, 3.25f, std::numeric_limits<float>::denorm_min(), -0.0f, 1e30f}},
      {{"a.second", {3}}, {7.0f, 8.0f, 9.0f}},
      {{"scalar", {}}, {42.0f}},
      {{"empty", {0, 4}}, {}},
  };
  write_safetensors(p, tensors, {{"inertialnet.model", "FlowNet2-C"}, {"note", "ünïcode"}});

  SafetensorsFile file(p);
  EXPECT_EQ(file.path(), p);
  // Data order of the file, which is the writer's order (not the header's alphabetical order).
  EXPECT_EQ(file.names(), (std::vector<std::string>{"z.first", "a.second", "scalar", "empty"}));
  EXPECT_EQ(file.metadata(), (std::map<std::string, std::string>{{"inertialnet.model", "FlowNet2-C"},
                                                                  {"note", "ünïcode"}}));
  for (const auto& t : tensors) {
    ASSERT_TRUE(file.contains(t.name));
    EXPECT_EQ(file.dtype(t.name), DType::F32);
    EXPECT_EQ(file.shape(t.name), t.shape);
    EXPECT_EQ(file.size_bytes(t.name), t.data.size() * sizeof(float));
    const std::vector<float> back = file.to_float32(t.name);
    ASSERT_EQ(back.size(), t.data.size());
    if (!back.empty()) {
      EXPECT_EQ(std::memcmp(back.data(), t.data.data(), back.size() * sizeof(float)), 0) << t.name;
    }
  }
  float first;
  std::memcpy(&first, file.data("a.second"), sizeof first);
  EXPECT_EQ(first, 7.0f);
  EXPECT_FALSE(file.contains("missing"));
  EXPECT_FALSE(temporary_left_beside(p));
}

// Weight files given together: the first that carries the key answers, with its path.
TEST_F(SafetensorsTest, FindMetadataSearchesTheFilesInOrder) {
  const std::string a = path("a.safetensors"), b = path("b.safetensors"), c = path("c.safetensors");
  write_safetensors(a, std::vector<HostTensor>{{{"x", {1}}, {1.0f}}});
  write_safetensors(b, std::vector<HostTensor>{{{"y", {1}}, {2.0f}}}, {{"key", "from b"}});
  write_safetensors(c, std::vector<HostTensor>{{{"z", {1}}, {3.0f}}}, {{"key", "from c"}});
  const auto found = find_metadata({a, b, c}, "key");
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->path, b);
  EXPECT_EQ(found->value, "from b");
  EXPECT_EQ(find_metadata({c, b}, "key")->value, "from c");
  EXPECT_FALSE(find_metadata({a}, "key").has_value());
  EXPECT_FALSE(find_metadata({}, "key").has_value());
}

// The same files opened once (predict asks their metadata several questions): open_safetensors
// keeps the order given, find_metadata_in answers as find_metadata does by path, and a file that
// does not open is refused as it is by path.
TEST_F(SafetensorsTest, FindMetadataInOpenFilesAnswersAsByPath) {
  const std::string a = path("a.safetensors"), b = path("b.safetensors"), c = path("c.safetensors");
  write_safetensors(a, std::vector<HostTensor>{{{"x", {1}}, {1.0f}}});
  write_safetensors(b, std::vector<HostTensor>{{{"y", {1}}, {2.0f}}}, {{"key", "from b"}});
  write_safetensors(c, std::vector<HostTensor>{{{"z", {1}}, {3.0f}}}, {{"key", "from c"}});
  const std::vector<SafetensorsFile> files = open_safetensors({a, b, c});
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0].path(), a);
  EXPECT_EQ(files[2].path(), c);
  const auto found = find_metadata_in(files, "key");
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->path, b);
  EXPECT_EQ(found->value, "from b");
  EXPECT_EQ(find_metadata_in(open_safetensors({c, b}), "key")->value, "from c");
  EXPECT_FALSE(find_metadata_in(open_safetensors({a}), "key").has_value());
  EXPECT_FALSE(find_metadata_in(std::vector<SafetensorsFile>{}, "key").has_value());
  EXPECT_TRUE(open_safetensors({}).empty());
  const std::string missing = path("missing.safetensors");
  const std::string refused = testing::invalid_input_message([&] { open_safetensors({a, missing}); });
  EXPECT_TRUE(testing::contains(refused, missing)) << refused;
  EXPECT_EQ(refused, testing::invalid_input_message([&] { SafetensorsFile{missing}; }));
}

TEST_F(SafetensorsTest, WriterPadsHeaderWithSpacesToAMultipleOfEight) {
  // Try several name lengths so that at least one header needs padding.
  for (int extra = 0; extra < 8; ++extra) {
    const std::string p = path("pad" + std::to_string(extra) + ".safetensors");
    write_safetensors(p, std::vector<HostTensor>{{{"t" + std::string(extra, 'x'), {1}}, {1.5f}}});
    const std::string bytes = read_all(p);
    ASSERT_GE(bytes.size(), 8u);
    uint64_t n = 0;
    for (int i = 7; i >= 0; --i) n = (n << 8) | static_cast<unsigned char>(bytes[i]);
    EXPECT_EQ(n % 8, 0u);
    ASSERT_EQ(bytes.size(), 8 + n + 4);
    const std::string header = bytes.substr(8, n);
    const std::size_t close = header.rfind('}');
    ASSERT_NE(close, std::string::npos);
    EXPECT_EQ(header.find_first_not_of(' ', close + 1), std::string::npos) << header;
    EXPECT_EQ(SafetensorsFile(p).to_float32(header.substr(2, 1 + extra)), std::vector<float>{1.5f});
  }
}

TEST_F(SafetensorsTest, WriterStreamsProducedTensors) {
  const std::string p = path("stream.safetensors");
  std::vector<TensorSpec> decl = {{"a", {2, 2}}, {"b", {3}}};
  std::vector<std::size_t> calls;
  write_safetensors(p, decl, [&](std::size_t index, float* out) {
    calls.push_back(index);
    for (int i = 0; i < (index == 0 ? 4 : 3); ++i) out[i] = static_cast<float>(10 * index + i);
  });
  EXPECT_EQ(calls, (std::vector<std::size_t>{0, 1}));
  SafetensorsFile file(p);
  EXPECT_EQ(file.to_float32("a"), (std::vector<float>{0, 1, 2, 3}));
  EXPECT_EQ(file.to_float32("b"), (std::vector<float>{10, 11, 12}));
  EXPECT_TRUE(file.metadata().empty());
}

TEST_F(SafetensorsTest, WriterRejectsBadDeclarationsAndLeavesNoFiles) {
  const std::string p = path("bad.safetensors");
  expect_invalid_input([&] { write_safetensors(p, std::vector<HostTensor>{{{"a", {1}}, {1}}, {{"a", {1}}, {2}}}); },
                       {p, "'a'", "twice"});
  expect_invalid_input([&] { write_safetensors(p, std::vector<HostTensor>{{{"a", {2, 2}}, {1, 2, 3}}}); },
                       {p, "'a'", "[2, 2]", "4 elements", "3 values"});
  expect_invalid_input([&] { write_safetensors(p, std::vector<HostTensor>{{{"a", {-1}}, {}}}); }, {"'a'", "[-1]"});
  expect_invalid_input([&] { write_safetensors(p, std::vector<HostTensor>{{{"__metadata__", {1}}, {1}}}); },
                       {"reserved"});
  expect_invalid_input([&] { write_safetensors(p, std::vector<HostTensor>{{{"", {1}}, {1}}}); }, {"empty name"});
  EXPECT_FALSE(exists(p));

  expect_invalid_input([&] { write_safetensors(dir_ + "/no/such/dir/x.safetensors", std::vector<HostTensor>{}); },
                       {"no/such/dir", "No such file"});

  // A producer that fails half way must not leave a partial file, under either name.
  EXPECT_THROW(write_safetensors(p, std::vector<TensorSpec>{{"a", {1}}, {"b", {1}}},
                                 [](std::size_t index, float* out) {
                                   if (index == 1) throw std::runtime_error("producer failed");
                                   out[0] = 1;
                                 }),
               std::runtime_error);
  EXPECT_FALSE(exists(p));
  EXPECT_FALSE(temporary_left_beside(p));
}

TEST_F(SafetensorsTest, MoveKeepsTheMappingAlive) {
  const std::string p = path("move.safetensors");
  write_safetensors(p, std::vector<HostTensor>{{{"w", {2}}, {3.0f, 4.0f}}});
  SafetensorsFile a(p);
  SafetensorsFile b(std::move(a));
  EXPECT_EQ(b.to_float32("w"), (std::vector<float>{3.0f, 4.0f}));
}

TEST_F(SafetensorsTest, F16IsConvertedExactly) {
  // Half bit patterns and the floats they denote exactly.
  const std::vector<std::pair<uint16_t, float>> cases = {
      {0x0000, 0.0f},
      {0x3C00, 1.0f},
      {0xC000, -2.0f},
      {0x3555, 0.333251953125f},
      {0x7BFF, 65504.0f},                       // largest finite half
      {0x0400, std::ldexp(1.0f, -14)},          // smallest normal
      {0x0001, std::ldexp(1.0f, -24)},          // smallest subnormal
      {0x03FF, std::ldexp(1023.0f, -24)},       // largest subnormal
      {0x8001, -std::ldexp(1.0f, -24)},
      {0x7C00, std::numeric_limits<float>::infinity()},
      {0xFC00, -std::numeric_limits<float>::infinity()},
  };
  std::string data;
  for (const auto& c : cases) {
    data += static_cast<char>(c.first & 0xFF);
    data += static_cast<char>(c.first >> 8);
  }
  data += std::string("\x00\x80", 2);  // -0
  data += std::string("\x01\x7E", 2);  // NaN with a payload
  const std::size_t n = cases.size() + 2;
  const std::string header = R"({"h":{"dtype":"F16","shape":[)" + std::to_string(n) +
                             R"(],"data_offsets":[0,)" + std::to_string(2 * n) + "]}}";
  SafetensorsFile file(write_file("f16.safetensors", header, data));
  EXPECT_EQ(file.dtype("h"), DType::F16);
  const std::vector<float> values = file.to_float32("h");
  ASSERT_EQ(values.size(), n);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(values[i], cases[i].second) << "half 0x" << std::hex << cases[i].first;
  }
  EXPECT_EQ(values[cases.size()], 0.0f);
  EXPECT_TRUE(std::signbit(values[cases.size()]));
  uint32_t nan_bits;
  std::memcpy(&nan_bits, &values[cases.size() + 1], sizeof nan_bits);
  EXPECT_EQ(nan_bits, 0x7F800000u | (0x201u << 13));
}

TEST_F(SafetensorsTest, OtherDTypesOpenButAreNotReadAsFloat) {
  const std::string header =
      R"({"i":{"dtype":"I32","shape":[2],"data_offsets":[0,8]},"b":{"dtype":"BF16","shape":[2],"data_offsets":[8,12]}})";
  SafetensorsFile file(write_file("ints.safetensors", header, std::string(12, '\x01')));
  EXPECT_EQ(file.dtype("i"), DType::I32);
  EXPECT_EQ(file.dtype("b"), DType::BF16);
  EXPECT_EQ(file.size_bytes("i"), 8u);
  expect_invalid_input([&] { file.to_float32("i"); }, {"ints.safetensors", "'i'", "I32", "F32 and F16"});
  expect_invalid_input([&] { file.to_float32("b"); }, {"'b'", "BF16"});
  expect_invalid_input([&] { file.info("nope"); }, {"ints.safetensors", "'nope'"});
}

// ---- malformed files, one per check -----------------------------------------------------------

TEST_F(SafetensorsTest, MissingFile) {
  expect_invalid_input([&] { SafetensorsFile f(dir_ + "/absent.safetensors"); }, {"absent.safetensors", "No such file"});
}

TEST_F(SafetensorsTest, ShorterThanTheLengthField) {
  const std::string p = write_raw("short.safetensors", std::string("\x05\x00\x00\x00\x00", 5));
  expect_invalid_input([&] { SafetensorsFile f(p); }, {"short.safetensors", "5 bytes", "8-byte"});
  const std::string empty = write_raw("empty.safetensors", "");
  expect_invalid_input([&] { SafetensorsFile f(empty); }, {"empty.safetensors", "0 bytes"});
}

TEST_F(SafetensorsTest, ShorterThanTheHeader) {
  const std::string p = write_raw("trunc.safetensors", length_prefix(100) + "{}");
  expect_invalid_input([&] { SafetensorsFile f(p); }, {"trunc.safetensors", "claims 100 bytes", "only 2"});
  // A huge length (e.g. a text file read as safetensors) must not overflow the check.
  const std::string q = write_raw("huge.safetensors", std::string(8, '\xFF') + "{}");
  expect_invalid_input([&] { SafetensorsFile f(q); }, {"huge.safetensors", "18446744073709551615"});
}

TEST_F(SafetensorsTest, HeaderNotJson) {
  expect_invalid_input([&] { SafetensorsFile f(write_file("nojson.safetensors", "{\"a\": ")); },
                       {"nojson.safetensors", "not valid JSON"});
  expect_invalid_input([&] { SafetensorsFile f(write_file("zero.safetensors", "")); },
                       {"zero.safetensors", "not valid JSON"});
}

// The message names the file and the position in our words; nlohmann's own text
// ("[json.exception.parse_error.101] parse error at line 1, …") was embedded before. The x is
// the 9th byte of the header.
TEST_F(SafetensorsTest, HeaderNotJsonSaysWhereWithoutTheParsersText) {
  const std::string p = write_file("broken.safetensors", "{\"a\": 1 x}");
  expect_invalid_input([&] { SafetensorsFile f(p); },
                       {"broken.safetensors", "header is not valid JSON", "malformed at byte 9 of the header"});
  const std::string q = write_file("overflow.safetensors", "{\"a\": 1e999}");
  expect_invalid_input([&] { SafetensorsFile f(q); }, {"overflow.safetensors", "a number out of range"});
  for (const auto& file : {p, q}) {
    try {
      SafetensorsFile f(file);
      ADD_FAILURE() << file << " was read";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find("json.exception"), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find("syntax error"), std::string::npos) << e.what();
    }
  }
}

TEST_F(SafetensorsTest, HeaderNotAnObject) {
  expect_invalid_input([&] { SafetensorsFile f(write_file("array.safetensors", "[1, 2]")); },
                       {"array.safetensors", "array", "not an object"});
}

TEST_F(SafetensorsTest, EmptyHeaderObjectIsAValidEmptyFile) {
  SafetensorsFile f(write_file("nothing.safetensors", "{}        "));
  EXPECT_TRUE(f.names().empty());
  EXPECT_TRUE(f.metadata().empty());
}

TEST_F(SafetensorsTest, UnknownDType) {
  const std::string h = R"({"w":{"dtype":"F128","shape":[1],"data_offsets":[0,16]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("dtype.safetensors", h, std::string(16, '\0'))); },
                       {"dtype.safetensors", "'w'", "unknown dtype \"F128\"", "F32"});
  const std::string h2 = R"({"w":{"dtype":32,"shape":[1],"data_offsets":[0,4]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("dtype2.safetensors", h2, std::string(4, '\0'))); },
                       {"'w'", "\"dtype\" that is not a string"});
}

TEST_F(SafetensorsTest, OffsetsOutOfTheFile) {
  const std::string h = R"({"w":{"dtype":"F32","shape":[4],"data_offsets":[0,16]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("beyond.safetensors", h, std::string(12, '\0'))); },
                       {"beyond.safetensors", "'w'", "[0, 16]", "beyond the end", "12 bytes"});
}

TEST_F(SafetensorsTest, OffsetsEndingBeforeTheyBegin) {
  const std::string h = R"({"w":{"dtype":"F32","shape":[1],"data_offsets":[8,4]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("backwards.safetensors", h, std::string(8, '\0'))); },
                       {"'w'", "[8, 4]", "before"});
}

TEST_F(SafetensorsTest, MalformedOffsets) {
  for (const std::string offsets : {"[0]", "[0,4,8]", "[-4,4]", "[0,4.0]", "\"0-4\""}) {
    const std::string h = R"({"w":{"dtype":"F32","shape":[1],"data_offsets":)" + offsets + "}}";
    expect_invalid_input([&] { SafetensorsFile f(write_file("offsets.safetensors", h, std::string(8, '\0'))); },
                         {"offsets.safetensors", "'w'", "data_offsets"});
  }
}

TEST_F(SafetensorsTest, OverlappingTensors) {
  const std::string h = R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]},)"
                        R"("b":{"dtype":"F32","shape":[2],"data_offsets":[4,12]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("overlap.safetensors", h, std::string(12, '\0'))); },
                       {"overlap.safetensors", "'a'", "'b'", "overlap"});
  // A tensor nested inside a larger one overlaps too, even when its neighbour does not.
  const std::string h2 = R"({"big":{"dtype":"F32","shape":[4],"data_offsets":[0,16]},)"
                         R"("in":{"dtype":"F32","shape":[1],"data_offsets":[4,8]},)"
                         R"("also":{"dtype":"F32","shape":[1],"data_offsets":[8,12]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("nested.safetensors", h2, std::string(16, '\0'))); },
                       {"'big'", "overlap"});
}

TEST_F(SafetensorsTest, MisSizedTensor) {
  const std::string h = R"({"w":{"dtype":"F32","shape":[2,3],"data_offsets":[0,16]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("size.safetensors", h, std::string(24, '\0'))); },
                       {"size.safetensors", "'w'", "16 bytes", "[2, 3]", "needs 24 bytes"});
}

TEST_F(SafetensorsTest, NonIntegerShapes) {
  const std::string base = R"({"w":{"dtype":"F32","data_offsets":[0,8],"shape":)";
  expect_invalid_input([&] { SafetensorsFile f(write_file("s1.safetensors", base + "[2.0]}}", std::string(8, '\0'))); },
                       {"s1.safetensors", "'w'", "not an integer", "2.0"});
  expect_invalid_input([&] { SafetensorsFile f(write_file("s2.safetensors", base + "[\"2\"]}}", std::string(8, '\0'))); },
                       {"'w'", "not an integer"});
  expect_invalid_input([&] { SafetensorsFile f(write_file("s3.safetensors", base + "[-2]}}", std::string(8, '\0'))); },
                       {"'w'", "negative", "-2"});
  expect_invalid_input([&] { SafetensorsFile f(write_file("s4.safetensors", base + "2}}", std::string(8, '\0'))); },
                       {"'w'", "not an array"});
  // A shape whose element count overflows must be caught, not wrapped into a small size.
  expect_invalid_input(
      [&] {
        SafetensorsFile f(write_file("s5.safetensors", base + "[4294967296,4294967296,4]}}", std::string(8, '\0')));
      },
      {"'w'", "too large"});
}

TEST_F(SafetensorsTest, MissingFields) {
  expect_invalid_input(
      [&] { SafetensorsFile f(write_file("m1.safetensors", R"({"w":{"shape":[1],"data_offsets":[0,4]}})", "abcd")); },
      {"m1.safetensors", "'w'", "no \"dtype\""});
  expect_invalid_input(
      [&] { SafetensorsFile f(write_file("m2.safetensors", R"({"w":{"dtype":"F32","data_offsets":[0,4]}})", "abcd")); },
      {"'w'", "no \"shape\""});
  expect_invalid_input(
      [&] { SafetensorsFile f(write_file("m3.safetensors", R"({"w":{"dtype":"F32","shape":[1]}})", "abcd")); },
      {"'w'", "no \"data_offsets\""});
  expect_invalid_input([&] { SafetensorsFile f(write_file("m4.safetensors", R"({"w":[1,2]})", "abcd")); },
                       {"'w'", "not an object"});
}

TEST_F(SafetensorsTest, BadMetadata) {
  expect_invalid_input(
      [&] { SafetensorsFile f(write_file("meta1.safetensors", R"({"__metadata__":{"seed":1}})")); },
      {"meta1.safetensors", "'seed'", "not a string"});
  expect_invalid_input([&] { SafetensorsFile f(write_file("meta2.safetensors", R"({"__metadata__":"x"})")); },
                       {"meta2.safetensors", "__metadata__"});
}

TEST_F(SafetensorsTest, DuplicateTensorName) {
  const std::string h = R"({"w":{"dtype":"F32","shape":[1],"data_offsets":[0,4]},)"
                        R"("w":{"dtype":"F32","shape":[1],"data_offsets":[4,8]}})";
  expect_invalid_input([&] { SafetensorsFile f(write_file("dup.safetensors", h, std::string(8, '\0'))); },
                       {"dup.safetensors", "'w'", "more than once"});
}

TEST_F(SafetensorsTest, HandWrittenValidFileReadsBack) {
  // Written by hand as a foreign writer would: unpadded header, tensors out of name order.
  const std::string h = R"({"b":{"dtype":"F32","shape":[1],"data_offsets":[0,4]},)"
                        R"("a":{"dtype":"F32","shape":[1,2],"data_offsets":[4,12]},"__metadata__":{"k":"v"}})";
  SafetensorsFile f(write_file("hand.safetensors", h, float_bytes({1.0f, 2.0f, 3.0f})));
  EXPECT_EQ(f.names(), (std::vector<std::string>{"b", "a"}));
  EXPECT_EQ(f.to_float32("a"), (std::vector<float>{2.0f, 3.0f}));
  EXPECT_EQ(f.to_float32("b"), (std::vector<float>{1.0f}));
  EXPECT_EQ(f.metadata().at("k"), "v");
  EXPECT_EQ(f.info("a").data_begin, 4u);
  EXPECT_EQ(f.info("a").numel(), 2);
}

// ---- model fit ----------------------------------------------------------------------------------

TEST_F(SafetensorsTest, CheckWeightsFitListsEveryProblemInOneError) {
  const std::string p = path("weights.safetensors");
  write_safetensors(p, std::vector<HostTensor>{
                           {{"conv1.weight", {64, 6, 7, 7}}, std::vector<float>(64 * 6 * 49)},
                           {{"conv1.bias", {64}}, std::vector<float>(64)},
                           {{"extra.a", {1}}, {0}},
                           {{"extra.b", {1}}, {0}},
                       });
  SafetensorsFile file(p);
  const std::vector<TensorSpec> model = {
      {"conv1.weight", {64, 12, 7, 7}},
      {"conv1.bias", {64}},
      {"conv2.weight", {128, 64, 5, 5}},
      {"conv2.bias", {128}},
  };
  try {
    check_weights_fit(file, model, "FlowNet2");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_EQ(std::string(e.what()),
              "weights " + p +
                  " do not fit FlowNet2: missing 2 tensors (conv2.weight, conv2.bias); 2 unexpected (extra.a, "
                  "extra.b); 1 with wrong shape (conv1.weight: file [64, 6, 7, 7], model [64, 12, 7, 7])");
  }

  EXPECT_NO_THROW(check_weights_fit(file, {{"conv1.weight", {64, 6, 7, 7}}, {"conv1.bias", {64}},
                                           {"extra.a", {1}}, {"extra.b", {1}}},
                                    "M"));
  expect_invalid_input([&] { check_weights_fit(file, {{"conv1.bias", {64}}}, "M"); },
                       {"do not fit M: 3 unexpected (conv1.weight, extra.a, extra.b)"});
}

TEST_F(SafetensorsTest, CheckWeightsFitRejectsUnreadableDTypes) {
  const std::string h = R"({"w":{"dtype":"F64","shape":[1],"data_offsets":[0,8]}})";
  SafetensorsFile f(write_file("f64.safetensors", h, std::string(8, '\0')));
  expect_invalid_input([&] { check_weights_fit(f, {{"w", {1}}}, "Head"); },
                       {"f64.safetensors do not fit Head", "1 with a dtype other than F32/F16 (w: F64)"});
}

// The check WeightSet::check uses: only the names the model owns can be unexpected, long lists are
// cut, and a set holding none of the model's tensors is called another model's.
TEST(WeightFit, HeldShapesOwnedNamesCutListsAndTheOtherModelHint) {
  const std::map<std::string, Shape> held = {{"a", {2}}, {"head.x", {1}}, {"stray", {1}}};
  WeightFitOptions flow_only;
  flow_only.owns = [](const std::string& name) { return name.rfind("head.", 0) != 0; };
  EXPECT_NO_THROW(check_weights_fit("weights w", {{"a", {2}}, {"stray", {1}}}, {{"a", {2}}, {"stray", {1}}}, "M",
                                    flow_only));
  expect_invalid_input([&] { check_weights_fit("weights w", held, {{"a", {2}}}, "M", flow_only); },
                       {"weights w do not fit M: 1 unexpected (stray)"});

  std::vector<TensorSpec> many;
  for (int i = 0; i < 10; ++i) many.push_back({"t" + std::to_string(i), {1}});
  expect_invalid_input([&] { check_weights_fit("weights w", {}, many, "Big"); },
                       {"missing 10 tensors (t0, t1, t2, t3, t4, t5, t6, t7, … 2 more)",
                        "Is this a weight file of another model?"});
  expect_invalid_input([&] { check_weights_fit("weights w", held, {{"a", {3}}, {"b", {1}}}, "M", flow_only); },
                       {"missing 1 tensor (b); 1 unexpected (stray); 1 with wrong shape (a: file [2], model [3])"});
}

// ---- files written by the reference implementation ------------------------------------------------

std::string fixture_dir() {
  if (const char* data = std::getenv("INERTIALNET_TEST_DATA")) return std::string(data) + "/fixtures";
  const std::string here = __FILE__;  // tests/io/this.cpp -> tests/data/fixtures
  return here.substr(0, here.rfind("/io/")) + "/data/fixtures";
}

TEST(SafetensorsInterop, ReadsFilesWrittenByThePythonPackage) {
  // tools/reference/make_fixtures.py writes these with safetensors.numpy.save_file.
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(fixture_dir(), ec)) {
    if (entry.path().extension() == ".safetensors") files.push_back(entry.path().string());
  }
  ASSERT_FALSE(files.empty()) << "no .safetensors fixtures under " << fixture_dir() << " (they are committed)";
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    SafetensorsFile file(f);
    EXPECT_FALSE(file.names().empty());
    EXPECT_EQ(file.metadata().count("inertialnet.model"), 1u);
    for (const auto& name : file.names()) {
      if (file.dtype(name) != DType::F32 && file.dtype(name) != DType::F16) continue;
      const std::vector<float> values = file.to_float32(name);
      EXPECT_EQ(static_cast<int64_t>(values.size()), file.info(name).numel()) << name;
      for (float v : values) ASSERT_TRUE(std::isfinite(v)) << name;
    }
  }
}

}  // namespace
}  // namespace inertialnet
