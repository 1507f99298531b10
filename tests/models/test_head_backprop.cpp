// SPDX-License-Identifier: Apache-2.0
// HeadBackprop: the InertialNet head's training step on the library's backward ops, checked
// against torch autograd (the committed fixture of tools/reference/make_head_gradient_fixture.py),
// against central finite differences of a float64 forward pass written here from
// docs/model_spec.md, at a small odd-sized head and at the default head on a 64×48 flow, and for
// bit-identical repeats.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/models/head_backprop.hpp"
#include "reference/basic_ops.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

std::string fixture(const std::string& name) {
  const char* root = std::getenv("INERTIALNET_TEST_DATA");
  return (std::filesystem::path(root ? root : "tests/data") / "fixtures" / name).string();
}

using HostTensors = std::map<std::string, std::vector<double>>;

// ---- a float64 forward pass of the head in training mode (fixed dropout mask) ----------------

std::vector<double> conv_relu(const std::vector<double>& x, std::int64_t n, std::int64_t ci, std::int64_t h,
                              std::int64_t w, const std::vector<double>& weight, const std::vector<double>& bias,
                              std::int64_t co, std::int64_t k) {
  const std::int64_t pad = (k - 1) / 2;
  std::vector<double> y(static_cast<std::size_t>(n * co * h * w));
  for (std::int64_t b = 0; b < n; ++b)
    for (std::int64_t o = 0; o < co; ++o)
      for (std::int64_t yy = 0; yy < h; ++yy)
        for (std::int64_t xx = 0; xx < w; ++xx) {
          double s = bias[static_cast<std::size_t>(o)];
          for (std::int64_t c = 0; c < ci; ++c)
            for (std::int64_t ky = 0; ky < k; ++ky)
              for (std::int64_t kx = 0; kx < k; ++kx) {
                const std::int64_t sy = yy - pad + ky, sx = xx - pad + kx;
                if (sy < 0 || sy >= h || sx < 0 || sx >= w) continue;
                s += x[static_cast<std::size_t>(((b * ci + c) * h + sy) * w + sx)] *
                     weight[static_cast<std::size_t>(((o * ci + c) * k + ky) * k + kx)];
              }
          y[static_cast<std::size_t>(((b * co + o) * h + yy) * w + xx)] = std::max(0.0, s);
        }
  return y;
}

std::vector<double> pool(const std::vector<double>& x, std::int64_t n, std::int64_t c, std::int64_t h, std::int64_t w,
                         std::int64_t p) {
  const std::int64_t ho = h / p, wo = w / p;
  std::vector<double> y(static_cast<std::size_t>(n * c * ho * wo));
  for (std::int64_t b = 0; b < n * c; ++b)
    for (std::int64_t yy = 0; yy < ho; ++yy)
      for (std::int64_t xx = 0; xx < wo; ++xx) {
        double m = -INFINITY;
        for (std::int64_t ky = 0; ky < p; ++ky)
          for (std::int64_t kx = 0; kx < p; ++kx) {
            m = std::max(m, x[static_cast<std::size_t>((b * h + yy * p + ky) * w + xx * p + kx)]);
          }
        y[static_cast<std::size_t>((b * ho + yy) * wo + xx)] = m;
      }
  return y;
}

std::vector<double> dense(const std::vector<double>& x, std::int64_t n, std::int64_t in, const std::vector<double>& weight,
                          const std::vector<double>& bias, std::int64_t out, bool relu) {
  std::vector<double> y(static_cast<std::size_t>(n * out));
  for (std::int64_t b = 0; b < n; ++b)
    for (std::int64_t o = 0; o < out; ++o) {
      double s = bias[static_cast<std::size_t>(o)];
      for (std::int64_t i = 0; i < in; ++i) {
        s += x[static_cast<std::size_t>(b * in + i)] * weight[static_cast<std::size_t>(o * in + i)];
      }
      y[static_cast<std::size_t>(b * out + o)] = relu ? std::max(0.0, s) : s;
    }
  return y;
}

double host_loss(const HeadConfig& c, const HostTensors& p, const std::vector<double>& flow, std::int64_t n,
                 const std::vector<double>& target, std::uint64_t seed) {
  const std::int64_t h = c.input_height, w = c.input_width;
  std::vector<double> x(flow.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = flow[i] * static_cast<double>(static_cast<float>(c.flow_scale));
  x = conv_relu(x, n, c.in_channels, h, w, p.at("head.conv1.weight"), p.at("head.conv1.bias"), c.conv1_channels,
                c.conv1_kernel);
  x = pool(x, n, c.conv1_channels, h, w, c.pool);
  const std::int64_t h1 = h / c.pool, w1 = w / c.pool;
  x = conv_relu(x, n, c.conv1_channels, h1, w1, p.at("head.conv2.weight"), p.at("head.conv2.bias"), c.conv2_channels,
                c.conv2_kernel);
  x = pool(x, n, c.conv2_channels, h1, w1, c.pool);
  const std::int64_t h2 = h1 / c.pool, w2 = w1 / c.pool;
  x = conv_relu(x, n, c.conv2_channels, h2, w2, p.at("head.conv3.weight"), p.at("head.conv3.bias"), c.conv3_channels,
                c.conv3_kernel);
  const auto keep = reference::dropout_keep_mask(seed, static_cast<float>(c.dropout), x.size());
  const double scale = static_cast<float>(1.0 / (1.0 - static_cast<double>(static_cast<float>(c.dropout))));
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = keep[i] ? x[i] * scale : 0.0;
  const std::int64_t features = c.fc1_inputs();
  x = dense(x, n, features, p.at("head.fc1.weight"), p.at("head.fc1.bias"), c.fc1_units, true);
  x = dense(x, n, c.fc1_units, p.at("head.fc2.weight"), p.at("head.fc2.bias"), c.outputs, false);
  double sum = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sum += (x[i] - target[i]) * (x[i] - target[i]);
  return sum / static_cast<double>(x.size());
}

// ---- helpers -----------------------------------------------------------------------------------

std::vector<double> widen(const std::vector<float>& v) { return {v.begin(), v.end()}; }

NamedTensors upload(Queue& queue, const HeadConfig& config, const std::map<std::string, std::vector<float>>& values) {
  NamedTensors out;
  for (const auto& spec : head_parameters(config)) out.emplace(spec.name, Tensor::from_host(queue, spec.shape, values.at(spec.name)));
  return out;
}

std::map<std::string, std::vector<float>> random_parameters(const HeadConfig& config, std::uint32_t seed) {
  std::map<std::string, std::vector<float>> out;
  for (const auto& spec : head_parameters(config)) {
    // Uniform in ±sqrt(3 / fan-in): activations of order one through every layer.
    const double fan_in = static_cast<double>(element_count(spec.shape) / spec.shape[0]);
    const auto bound = static_cast<float>(spec.shape.size() == 1 ? 0.1 : std::sqrt(3.0 / fan_in));
    out.emplace(spec.name, testing::random_vector(static_cast<std::size_t>(element_count(spec.shape)), seed++, -bound, bound));
  }
  return out;
}

// Within `relative` of `expected`, relative to max(|expected|, 1e-2 · max |expected| of the tensor):
// a gradient element near zero is judged against the tensor's scale.
::testing::AssertionResult close_gradients(const std::vector<float>& got, const std::vector<double>& expected,
                                           double relative) {
  double scale = 0.0;
  for (double v : expected) scale = std::max(scale, std::abs(v));
  for (std::size_t i = 0; i < got.size(); ++i) {
    const double error = std::abs(static_cast<double>(got[i]) - expected[i]);
    if (error > relative * std::max(std::abs(expected[i]), 1e-2 * scale) + 1e-12) {
      return ::testing::AssertionFailure() << "element " << i << ": got " << got[i] << ", expected " << expected[i]
                                           << " (tensor scale " << scale << ")";
    }
  }
  return ::testing::AssertionSuccess();
}

// Device gradients of every parameter against central differences of host_loss, at `per_tensor`
// elements spread over each tensor (all of them when 0).
void expect_matches_finite_differences(const HeadConfig& config, std::int64_t batch, std::size_t per_tensor) {
  Queue& queue = testing::test_queue();
  const auto values = random_parameters(config, 1001);
  const Shape flow_shape{batch, config.in_channels, config.input_height, config.input_width};
  const auto flow = testing::random_vector(static_cast<std::size_t>(element_count(flow_shape)), 1101, -3.0f, 3.0f);
  const auto target = testing::random_vector(static_cast<std::size_t>(batch * config.outputs), 1102);
  const std::uint64_t seed = 99;

  HeadBackprop head(config);
  const NamedTensors params = upload(queue, config, values);
  const NamedTensors grads = head.zeros_like_parameters(queue);
  const float loss = head.loss_and_gradients(queue, params, Tensor::from_host(queue, flow_shape, flow),
                                             Tensor::from_host(queue, {batch, config.outputs}, target), seed, grads);

  HostTensors host;
  for (const auto& [name, v] : values) host.emplace(name, widen(v));
  const auto flow64 = widen(flow), target64 = widen(target);
  const double loss64 = host_loss(config, host, flow64, batch, target64, seed);
  EXPECT_NEAR(loss, loss64, 1e-5 * std::max(1.0, loss64));
  for (const auto& spec : head_parameters(config)) {
    SCOPED_TRACE(spec.name);
    const auto got = grads.at(spec.name).to_host(queue);
    const std::size_t count = got.size();
    const std::size_t step = per_tensor == 0 || per_tensor >= count ? 1 : count / per_tensor;
    std::vector<float> sampled;
    std::vector<double> numeric;
    for (std::size_t i = 0; i < count; i += step) {
      std::vector<double>& v = host.at(spec.name);
      const double saved = v[i];
      const double h = 1e-6 * std::max(1.0, std::abs(saved));
      v[i] = saved + h;
      const double up = host_loss(config, host, flow64, batch, target64, seed);
      v[i] = saved - h;
      const double down = host_loss(config, host, flow64, batch, target64, seed);
      v[i] = saved;
      sampled.push_back(got[i]);
      numeric.push_back((up - down) / (2.0 * h));
    }
    EXPECT_TRUE(close_gradients(sampled, numeric, 1e-3));
  }
}

HeadConfig small_config() {
  HeadConfig c;
  c.input_height = 11;  // odd: the pooling drops a row
  c.input_width = 13;
  c.conv1_channels = 4;
  c.conv2_channels = 5;
  c.conv2_kernel = 5;
  c.conv3_channels = 3;
  c.fc1_units = 7;
  c.flow_scale = 0.5;
  return c;
}

// ---- tests -------------------------------------------------------------------------------------

TEST(HeadBackprop, MatchesTorchAutograd) {
  Queue& queue = testing::test_queue();
  const SafetensorsFile file(fixture("head_gradients_14x10.safetensors"));
  const HeadConfig config = head_config_from_json(file.metadata().at(kMetadataHead));
  const std::uint64_t seed = std::stoull(file.metadata().at("fixture.dropout_seed"));
  std::map<std::string, std::vector<float>> values;
  for (const auto& spec : head_parameters(config)) values.emplace(spec.name, file.to_float32(spec.name));
  const auto& fs = file.shape("flow");
  const auto& ts = file.shape("target");
  HeadBackprop head(config);
  const NamedTensors grads = head.zeros_like_parameters(queue);
  const float loss = head.loss_and_gradients(
      queue, upload(queue, config, values), Tensor::from_host(queue, Shape(fs.begin(), fs.end()), file.to_float32("flow")),
      Tensor::from_host(queue, Shape(ts.begin(), ts.end()), file.to_float32("target")), seed, grads);
  EXPECT_NEAR(loss, file.to_float32("loss").front(), 1e-5);
  for (const auto& spec : head_parameters(config)) {
    SCOPED_TRACE(spec.name);
    EXPECT_TRUE(close_gradients(grads.at(spec.name).to_host(queue), widen(file.to_float32("grad." + spec.name)), 1e-3));
  }
}

TEST(HeadBackprop, MatchesFiniteDifferencesAtOddSizes) { expect_matches_finite_differences(small_config(), 3, 0); }

TEST(HeadBackprop, MatchesFiniteDifferencesOnTheDefaultHeadAt64x48) {
  HeadConfig config;
  config.input_height = 48;
  config.input_width = 64;
  expect_matches_finite_differences(config, 2, 6);
}

TEST(HeadBackprop, RepeatsAreBitIdenticalAndPredictIsDeterministic) {
  Queue& queue = testing::test_queue();
  const HeadConfig config = small_config();
  const NamedTensors params = upload(queue, config, random_parameters(config, 1201));
  const Shape flow_shape{4, 2, config.input_height, config.input_width};
  const Tensor flow = Tensor::from_host(queue, flow_shape, testing::random_vector(static_cast<std::size_t>(element_count(flow_shape)), 1202));
  const Tensor target = Tensor::from_host(queue, {4, 3}, testing::random_vector(12, 1203));
  HeadBackprop head(config);
  const NamedTensors a = head.zeros_like_parameters(queue);
  const NamedTensors b = head.zeros_like_parameters(queue);
  const float la = head.loss_and_gradients(queue, params, flow, target, 5, a);
  const float lb = head.loss_and_gradients(queue, params, flow, target, 5, b);
  EXPECT_EQ(la, lb);
  for (const auto& [name, t] : a) {
    const auto x = t.to_host(queue), y = b.at(name).to_host(queue);
    EXPECT_TRUE(std::equal(x.begin(), x.end(), y.begin())) << name;
  }
}

TEST(HeadBackprop, RefusesAFlowOfAnotherSize) {
  Queue& queue = testing::test_queue();
  const HeadConfig config = small_config();
  HeadBackprop head(config);
  const NamedTensors params = upload(queue, config, random_parameters(config, 1301));
  testing::expect_invalid_input([&] { head.predict(queue, params, Tensor::empty(queue, {1, 2, 12, 13})); }, "13×11");
}

}  // namespace
}  // namespace inertialnet
