// SPDX-License-Identifier: Apache-2.0
// Deterministic synthetic weights (docs/model_spec.md): bit-exact against values computed
// independently in Python and, once committed, against tests/data/fixtures/synthetic_weights.json
// written by the Python twin in tools/reference/.
#include "inertialnet/models/synthetic_weights.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/weight_fit.hpp"
#include "support/sha256.hpp"

namespace inertialnet {
namespace {

std::string sha256_of(const std::vector<float>& values) {
  return testing::sha256_hex(values.data(), values.size() * sizeof(float));
}

// Every tensor name the project knows, with its spec: FlowNet2 (prefixed), the standalone
// networks and the default head.
const std::map<std::string, ParameterSpec>& known_specs() {
  static const std::map<std::string, ParameterSpec> table = [] {
    std::map<std::string, ParameterSpec> t;
    for (ModelKind kind : all_model_kinds()) {
      for (const auto& p : model_parameters(kind)) t.emplace(p.name, p);
    }
    return t;
  }();
  return table;
}

float from_hex(const std::string& hex) { return static_cast<float>(std::strtod(hex.c_str(), nullptr)); }

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(SyntheticWeights, HashAndMixerMatchTheirStandardDefinitions) {
  // FNV-1a 64 reference vectors and splitmix64's well-known first output from state 0.
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("flownetc.conv1.0.weight"), 0x5206b9fea3e7aae6ull);
  EXPECT_EQ(splitmix64(0), 0xe220a8397b1dcdafull);
  EXPECT_EQ(synthetic_key("a", 0), fnv1a64("a"));
  EXPECT_EQ(synthetic_key("a", 1), fnv1a64("a") ^ 0x9E3779B97F4A7C15ull);
}

TEST(SyntheticWeights, SHA256HelperMatchesFips180Vectors) {
  EXPECT_EQ(testing::sha256_hex("", 0), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(testing::sha256_hex("abc", 3), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const std::string two_blocks = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  EXPECT_EQ(testing::sha256_hex(two_blocks.data(), two_blocks.size()),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // One million 'a' fed in uneven pieces exercises the buffering across block boundaries.
  testing::Sha256 sha;
  const std::string chunk(997, 'a');
  std::size_t left = 1000000;
  while (left > 0) {
    const std::size_t n = std::min(left, chunk.size());
    sha.update(chunk.data(), n);
    left -= n;
  }
  std::string hex;
  for (uint8_t byte : sha.finish()) {
    static const char* digits = "0123456789abcdef";
    hex += digits[byte >> 4];
    hex += digits[byte & 0xF];
  }
  EXPECT_EQ(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Computed with a few lines of stdlib-only Python (struct + hashlib) written from docs/model_spec.md, not
// from this implementation: sha256 of the tensor's little-endian float32 bytes, first values as
// float.hex() of the float32 values.
struct HandComputed {
  uint64_t seed;
  const char* name;
  const char* sha256;
  std::vector<const char*> first;
};

const std::vector<HandComputed>& hand_computed() {
  static const std::vector<HandComputed> cases = {
      {1, "flownetc.conv1.0.weight", "4946eaff1e9d8dc057214626bfd2e5a32933fd836e3cd441662d415bb911b7e2",
       {"-0x1.1c4bf00000000p-3", "0x1.5869e60000000p-5", "-0x1.2fa5040000000p-3", "0x1.4dd8ac0000000p-3"}},
      {1, "flownetc.conv1.0.bias", "5102633bfb4d559d156ba5dfdbb48df5e462bf0680b71e95115830e943bb9e18",
       {"0x1.36e2520000000p-8", "0x1.1779480000000p-10", "0x1.8875ec0000000p-8", "0x1.7bc3d80000000p-13"}},
      {1, "flownets_1.upsampled_flow6_to_5.weight", "d04ddde15329f95dcb1ebb46bb3820b0dc58488b1aef73c1295d8cf8636e1173",
       {"-0x1.1cc0240000000p-1", "0x1.a52f420000000p-2", "0x1.65f9ca0000000p-3", "-0x1.9c5d360000000p-3"}},
      {1, "flownetfusion.predict_flow0.weight", "d95bd2a658c598f473c378b2537054c2e391a4eb4b30072a565bf017a1295674",
       {"-0x1.04175e0000000p-5", "0x1.99e8360000000p-6", "-0x1.f90c2e0000000p-5", "0x1.4622040000000p-4"}},
      {1, "flownets_d.deconv2.0.weight", "fe352de62263629d50bc72e3c7c122c4196cf2e39d4d14b2edbb5752b4ef9393",
       {"0x1.10a1700000000p-5", "0x1.38db140000000p-6", "-0x1.10e0520000000p-6", "0x1.8bc67e0000000p-7"}},
      {1, "head.fc2.weight", "92e04335e7a10dbcf1aecf8772d07995b2a0ecaeb75fceb121b5c5c1dec94321",
       {"0x1.7d8fec0000000p-4", "0x1.515fbe0000000p-3", "-0x1.20b2fc0000000p-3", "-0x1.e34ec60000000p-4"}},
      {1, "head.fc2.bias", "4c8949988cb9f646a497b8e3ee39e7d9444356f4f1b5916e76b9b05cba4925fa",
       {"-0x1.48970a0000000p-12", "-0x1.ba0f700000000p-9", "-0x1.4e0b6c0000000p-8"}},
      {12345, "flownetc.conv1.0.weight", "59147cde080c088b333f2c2b756b73372bf39aa4e9dbb6eca3b22eebd930ea84",
       {"0x1.d9b1c80000000p-4", "-0x1.2827ca0000000p-3", "-0x1.4673c40000000p-3", "-0x1.c5f3700000000p-5"}},
      {12345, "flownetc.conv1.0.bias", "cf7c0561d2738c5fa56a29c0b8844137c578e9112ca6c20132a212093eddcac7",
       {"0x1.3b74f60000000p-11", "-0x1.44e37a0000000p-8", "-0x1.1d84c60000000p-7", "-0x1.10e2140000000p-10"}},
      {12345, "flownets_1.upsampled_flow6_to_5.weight",
       "42f0e4fbd08fc2bedc9d210accc7eca6ca9ef579a553b7ffa3aca38c0ddae6db",
       {"0x1.6e60100000000p-2", "-0x1.14ed560000000p-1", "-0x1.ccf7880000000p-3", "0x1.341a880000000p-1"}},
      {12345, "flownetfusion.predict_flow0.weight", "015b3225835cc87d4fa887f58a3d024b243e6bd730a0efe68aaff0355bd8365f",
       {"0x1.f8c1c40000000p-5", "-0x1.a550ae0000000p-6", "0x1.6cdd980000000p-5", "0x1.a4bd060000000p-4"}},
      {12345, "flownets_d.deconv2.0.weight", "b1ca908a2d6ca59c6fa675d155cc1a363724f446f27218e42964726b3ba4b767",
       {"0x1.f3f4520000000p-5", "0x1.cf99920000000p-5", "-0x1.7abe1e0000000p-5", "0x1.234cc60000000p-5"}},
      {12345, "head.fc2.weight", "40a63e88fbd4fd3f6997f0f28e2a8ad30b6c922f276872e5c69b6572d7ac2798",
       {"0x1.27a6320000000p-3", "0x1.d507260000000p-4", "-0x1.07aa060000000p-5", "0x1.53b2600000000p-7"}},
      {12345, "head.fc2.bias", "62243b275ece57be42a30e11374008b423cc8f42bea8832496456e1925ae4c67",
       {"0x1.3b27ae0000000p-9", "0x1.75f1c20000000p-8", "0x1.deb2d80000000p-9"}},
  };
  return cases;
}

TEST(SyntheticWeights, MatchesIndependentlyComputedValues) {
  for (const auto& c : hand_computed()) {
    SCOPED_TRACE(std::string(c.name) + " seed " + std::to_string(c.seed));
    const ParameterSpec& spec = known_specs().at(c.name);
    const std::vector<float> values = synthetic_tensor(spec, c.seed);
    ASSERT_EQ(static_cast<int64_t>(values.size()), spec.numel());
    for (std::size_t i = 0; i < c.first.size(); ++i) {
      EXPECT_TRUE(same_bits(values[i], from_hex(c.first[i]))) << i << ": " << values[i] << " vs " << c.first[i];
    }
    EXPECT_EQ(sha256_of(values), c.sha256);
  }
}

TEST(SyntheticWeights, ValuesStayWithinTheirBounds) {
  for (const char* name : {"flownetc.conv3_1.0.weight", "flownetc.predict_flow2.weight", "flownetc.conv3_1.0.bias"}) {
    const ParameterSpec& spec = known_specs().at(name);
    const double bound = spec.is_bias ? 0.01 : std::sqrt(6.0 / static_cast<double>(spec.fan_in)) * spec.gain;
    const std::vector<float> values = synthetic_tensor(spec, 7);
    double lo = 0, hi = 0, mean = 0;
    for (float v : values) {
      lo = std::min(lo, static_cast<double>(v));
      hi = std::max(hi, static_cast<double>(v));
      mean += v;
    }
    mean /= static_cast<double>(values.size());
    // Float rounding can reach the bound itself, never beyond it.
    EXPECT_GE(lo, -bound) << name;
    EXPECT_LE(hi, bound) << name;
    if (values.size() > 1000) {
      // A uniform sample of >1000 values spans most of the range and centres near 0
      // (std of the mean ≈ bound/sqrt(3n) < 0.02·bound).
      EXPECT_LT(lo, -0.9 * bound) << name;
      EXPECT_GT(hi, 0.9 * bound) << name;
      EXPECT_LT(std::abs(mean), 0.1 * bound) << name;
    }
  }
}

TEST(SyntheticWeights, DependsOnSeedAndName) {
  ParameterSpec spec{{"x.weight", {64}}, LayerKind::Conv2d, false, 9, 1.0};
  const auto a = synthetic_tensor(spec, 1);
  EXPECT_EQ(a, synthetic_tensor(spec, 1));
  EXPECT_NE(a, synthetic_tensor(spec, 2));
  spec.name = "y.weight";
  EXPECT_NE(a, synthetic_tensor(spec, 1));
  spec.fan_in = 0;
  EXPECT_THROW(synthetic_tensor(spec, 1), Error);
}

TEST(SyntheticWeights, WholeModelAndWrittenFileAgree) {
  HeadConfig head;
  head.input_height = 32;
  head.input_width = 24;
  head.fc1_units = 10;
  const auto tensors = synthetic_weights(ModelKind::InertialNetHead, 99, head);
  const auto specs = model_parameters(ModelKind::InertialNetHead, head);
  ASSERT_EQ(tensors.size(), specs.size());

  std::string dir = ::testing::TempDir() + "inertialnet_synthetic_XXXXXX";
  ASSERT_NE(::mkdtemp(dir.data()), nullptr);
  const std::string path = dir + "/head.safetensors";
  write_synthetic_weights(path, ModelKind::InertialNetHead, 99, head);
  {
    SafetensorsFile file(path);
    const std::vector<TensorSpec> expected(specs.begin(), specs.end());
    EXPECT_NO_THROW(check_weights_fit(file, expected, "InertialNetHead"));
    for (std::size_t i = 0; i < specs.size(); ++i) {
      EXPECT_EQ(tensors[i].name, specs[i].name);
      EXPECT_EQ(tensors[i].data, synthetic_tensor(specs[i], 99));
      EXPECT_EQ(file.to_float32(specs[i].name), tensors[i].data) << specs[i].name;
    }
    EXPECT_EQ(file.metadata().at("inertialnet.model"), "InertialNetHead");
    EXPECT_EQ(file.metadata().at("inertialnet.synthetic"), "true");
    EXPECT_EQ(file.metadata().at("inertialnet.seed"), "99");
    EXPECT_EQ(head_config_from_json(file.metadata().at("inertialnet.head")), head);
  }
  std::remove(path.c_str());
  ::rmdir(dir.c_str());

  const auto meta = synthetic_metadata(ModelKind::FlowNet2, 18446744073709551615ull, head);
  EXPECT_EQ(meta.at("inertialnet.model"), "FlowNet2");
  EXPECT_EQ(meta.at("inertialnet.seed"), "18446744073709551615");
  EXPECT_EQ(meta.count("inertialnet.head"), 0u);
}

// ---- the Python twin's fixture --------------------------------------------------------------------

std::string fixture_path() {
  if (const char* data = std::getenv("INERTIALNET_TEST_DATA")) {
    return std::string(data) + "/fixtures/synthetic_weights.json";
  }
  std::string here = __FILE__;  // tests/models/this.cpp -> tests/data/
  return here.substr(0, here.rfind("/models/")) + "/data/fixtures/synthetic_weights.json";
}

uint64_t parse_hex64(const std::string& text) { return std::strtoull(text.c_str(), nullptr, 16); }

const char* python_kind(LayerKind kind) {
  switch (kind) {
    case LayerKind::Conv2d: return "conv";
    case LayerKind::ConvTranspose2d: return "deconv";
    case LayerKind::Linear: return "linear";
  }
  return "?";
}

// Layout written by tools/reference/make_fixtures.py: {"fnv1a64": {text: hex}, "splitmix64":
// {hex: hex}, "seeds": [{"seed": n, "tensors": [{"model", "name", "shape", "numel", "kind",
// "param", "fan_in", "gain" (null for biases), "key", "first4_u", "first4_hex", "last_hex",
// "sha256"}]}]}. Each tensor is looked up in OUR table of its model (the default head for the
// head), so the fixture checks the tables as well as the generator.
TEST(SyntheticWeightsFixture, MatchesThePythonTwin) {
  const std::string path = fixture_path();
  std::ifstream in(path);
  ASSERT_TRUE(in) << path << " is missing: it is committed; tools/reference/regenerate_fixtures.sh rebuilds it";
  nlohmann::json fixture;
  ASSERT_NO_THROW(fixture = nlohmann::json::parse(in)) << path;

  ASSERT_TRUE(fixture.contains("fnv1a64"));
  for (auto it = fixture["fnv1a64"].begin(); it != fixture["fnv1a64"].end(); ++it) {
    EXPECT_EQ(fnv1a64(it.key()), parse_hex64(it.value().get<std::string>())) << "\"" << it.key() << "\"";
  }
  ASSERT_TRUE(fixture.contains("splitmix64"));
  for (auto it = fixture["splitmix64"].begin(); it != fixture["splitmix64"].end(); ++it) {
    EXPECT_EQ(splitmix64(parse_hex64(it.key())), parse_hex64(it.value().get<std::string>())) << it.key();
  }

  std::set<uint64_t> seeds;
  std::size_t checked = 0;
  for (const auto& group : fixture.at("seeds")) {
    const uint64_t seed = group.at("seed").get<uint64_t>();
    seeds.insert(seed);
    for (const auto& t : group.at("tensors")) {
      const std::string name = t.at("name").get<std::string>();
      const std::string model = t.at("model").get<std::string>();
      SCOPED_TRACE(model + " " + name + " seed " + std::to_string(seed));
      const auto table = model_parameters(model_kind_from_string(model));
      auto spec_it = std::find_if(table.begin(), table.end(), [&](const ParameterSpec& p) { return p.name == name; });
      ASSERT_NE(spec_it, table.end()) << "our " << model << " table has no such tensor";
      const ParameterSpec& spec = *spec_it;

      EXPECT_EQ(t.at("shape").get<std::vector<int64_t>>(), spec.shape);
      EXPECT_EQ(t.at("numel").get<int64_t>(), spec.numel());
      EXPECT_EQ(t.at("kind").get<std::string>(), python_kind(spec.kind));
      EXPECT_EQ(t.at("param").get<std::string>(), spec.is_bias ? "bias" : "weight");
      EXPECT_EQ(t.at("fan_in").get<int64_t>(), spec.fan_in);
      if (spec.is_bias) {
        EXPECT_TRUE(t.at("gain").is_null());  // biases ignore the gain
      } else {
        EXPECT_EQ(t.at("gain").get<double>(), spec.gain);
      }
      const uint64_t key = synthetic_key(name, seed);
      EXPECT_EQ(key, parse_hex64(t.at("key").get<std::string>()));

      const std::vector<float> values = synthetic_tensor(spec, seed);
      const auto& first_u = t.at("first4_u");
      for (std::size_t i = 0; i < first_u.size(); ++i) {
        EXPECT_EQ(synthetic_uniform(key, i), std::strtod(first_u[i].get<std::string>().c_str(), nullptr)) << i;
      }
      const auto& first = t.at("first4_hex");
      ASSERT_LE(first.size(), values.size());
      for (std::size_t i = 0; i < first.size(); ++i) {
        const std::string hex = first[i].get<std::string>();
        EXPECT_TRUE(same_bits(values[i], from_hex(hex))) << i << ": " << values[i] << " vs " << hex;
      }
      const std::string last = t.at("last_hex").get<std::string>();
      EXPECT_TRUE(same_bits(values.back(), from_hex(last))) << values.back() << " vs " << last;
      EXPECT_EQ(sha256_of(values), t.at("sha256").get<std::string>());
      ++checked;
    }
  }
  EXPECT_EQ(seeds.count(1), 1u);
  EXPECT_EQ(seeds.count(12345), 1u);
  EXPECT_GT(checked, 20u);
}

}  // namespace
}  // namespace inertialnet
