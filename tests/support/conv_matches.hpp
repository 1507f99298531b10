// SPDX-License-Identifier: Apache-2.0
// The one convolution check of the conv2d suites (test_conv2d: the plan's choice; test_conv2d_splitk:
// the split-K forms forced; test_winograd: weights prepared on the winograd plan): a case's random
// input, weights and bias, conv2d run with its input and output as channel slices of wider
// tensors, and the output against the float64 direct convolution of tests/reference/conv.cpp with
// the bound of every GEMM and direct convolution (the Winograd form's where it ran). Its operands
// (layer_operands) and the Winograd matrices' check also serve support/deconv_matches.hpp.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "ops/op_testing.hpp"
#include "ops/winograd.hpp"
#include "reference/conv.hpp"
#include "support/flownet_layers.hpp"
#include "support/testing.hpp"

namespace inertialnet::testing {

// One convolution: ci → co channels on an h×w input, a k×k window.
struct ConvCase {
  std::string name;
  int ci, co, h, w, k, stride, padding;
  bool bias;
  ActivationSpec activation;
};
inline void PrintTo(const ConvCase& c, std::ostream* os) { *os << c.name; }

// A FlowNet2 layer of the shared table as a case.
inline ConvCase conv_case_of(const flownet_layers::LayerShape& l) {
  return {l.identifier(), l.ci, l.co, l.h, l.w, l.k, l.stride, l.padding, l.bias, l.activation};
}

// Where the op's tensors sit inside wider tensors: `*_before` / `*_after` extra channels around
// the input and the output (0 everywhere: plain contiguous tensors); the column budget of
// Conv2dOptions (0: the op's own).
struct ConvPlacement {
  int batch = 1;
  int in_before = 0, in_after = 0;
  int out_before = 0, out_after = 0;
  std::size_t max_column_floats = 0;
};

// How a suite runs its cases: the form it forces (Default: the plan's choice) and the first of
// the five seeds of a case's random data (input, weights, bias, the wider input and output), so
// that each suite keeps data of its own; `prepared_on`: the weights prepared once for that
// backend, as a network prepares them (none: conv2d prepares them itself, on the device's plan),
// with the input's shape where `knowing_input` (as a network's graph: the size rules apply).
struct ConvRun {
  Conv2dAlgorithm algorithm = Conv2dAlgorithm::Default;
  std::uint32_t first_seed = 101;
  std::optional<GemmBackend> prepared_on = std::nullopt;
  bool knowing_input = false;
};

// A case's operands: random input, weights and bias from five seeds (seed … seed + 4: input,
// weights, bias, the wider input and output), the input and the output as channel slices of
// wider tensors whose other channels must survive, the weights and bias on the device.
struct LayerOperands {
  std::vector<float> input, weight, bias;
  Sliced in, out;
  Tensor w, b;
};

inline LayerOperands layer_operands(Queue& queue, std::uint32_t seed, const Shape& input, const Shape& weight,
                                    const Shape& output, bool bias, int in_before, int in_after, int out_before,
                                    int out_after) {
  auto count = [](const Shape& s) {
    std::size_t n = 1;
    for (const std::int64_t d : s) n *= static_cast<std::size_t>(d);
    return n;
  };
  const std::int64_t co = output[1];
  LayerOperands o;
  o.input = random_vector(count(input), seed);
  o.weight = random_vector(count(weight), seed + 1);
  o.bias = bias ? random_vector(static_cast<std::size_t>(co), seed + 2) : std::vector<float>{};
  o.in = embed_sliced(queue, o.input, input, in_before, in_before + in_after, seed + 3);
  o.out = make_sliced(queue, output, out_before, out_before + out_after, seed + 4);
  o.w = Tensor::from_host(queue, weight, o.weight);
  o.b = bias ? Tensor::from_host(queue, {co}, o.bias) : Tensor();
  return o;
}

// Weights prepared as Winograd matrices: the 36 transformed matrices of `ci` input channels and at
// least `rows` output rows, packed as one (ops/winograd.hpp).
inline void expect_winograd_matrices(const GemmWeights& prepared, std::int64_t ci, std::int64_t rows) {
  if (prepared.winograd.empty()) return;
  EXPECT_EQ(prepared.winograd.size(), 1u);
  const PackedPanels& u = prepared.winograd[0];
  EXPECT_EQ(u.depth, static_cast<std::size_t>(ci));
  EXPECT_EQ(u.lines % (detail::kWinogradElements * static_cast<std::size_t>(u.width)), 0u);
  EXPECT_GE(u.lines, detail::kWinogradElements * static_cast<std::size_t>(rows));
}

// Returns whether the Winograd form computed the output (and set the bound).
inline bool expect_conv_matches(const ConvCase& c, const ConvPlacement& p, const ConvRun& run = {}) {
  SCOPED_TRACE(c.name);
  Queue& queue = test_queue();
  const reference::ConvShape s{p.batch, c.ci, c.h, c.w, c.co, c.k, c.k, c.stride, c.padding};
  const int oh = s.conv_out_h(), ow = s.conv_out_w();
  const LayerOperands o = layer_operands(queue, run.first_seed, {p.batch, c.ci, c.h, c.w}, {c.co, c.ci, c.k, c.k},
                                         {p.batch, c.co, oh, ow}, c.bias, p.in_before, p.in_after, p.out_before,
                                         p.out_after);
  const auto expected = reference::conv2d(s, o.input, o.weight, o.bias, c.activation);
  Conv2dOptions options{c.stride, c.padding, c.activation, p.max_column_floats};
  options.algorithm = run.algorithm;
  GemmWeights prepared;
  if (run.prepared_on) {
    prepared = prepare_conv2d_weights(queue, o.w, *run.prepared_on, c.stride, c.padding,
                                      run.knowing_input ? o.in.view.shape() : Shape{});
    options.prepared = &prepared;
    // A phase-form layer's matrices take its 4·ci phase images.
    const bool phases = detail::winograd_phase_eligible(o.w.shape(), c.stride, c.padding);
    expect_winograd_matrices(prepared, (phases ? 4 : 1) * c.ci, c.co);
  }
  conv2d(queue, o.in.view, o.w, o.b, o.out.view, options);
  EXPECT_TRUE(untouched_outside(queue, o.out)) << "elements outside the output slice were written";
  // float32 accumulation of K = ci·k·k products of magnitude ≲ 1 against a double reference:
  // the error grows with the reduction length, so the absolute floor is sqrt(K) (the typical
  // output magnitude) and 1e-5 relative to that leaves ~10× margin over K·eps at K ≈ 10^4. The
  // split-K forms add the same products in another order, which changes the rounding by a few
  // K·eps at most. The winograd plan's F(4×4, 3×3) layers, where the plan chooses or the
  // weights were prepared as Winograd matrices, have a measured bound of their own (op_testing.hpp).
  const double floor = std::sqrt(static_cast<double>(c.ci) * c.k * c.k);
  const bool plan_winograd = run.algorithm == Conv2dAlgorithm::Default &&
                             gemm_backend(queue.device().info()) == GemmBackend::Winograd &&
                             detail::winograd_preferred(o.in.view.shape(), o.w.shape(), c.stride, c.padding);
  const bool winograd = run.prepared_on ? !prepared.winograd.empty() : plan_winograd;
  EXPECT_TRUE(all_close(view_values(queue, o.out), expected, winograd ? kWinogradRelativeTolerance : 1e-5, floor));
  return winograd;
}

}  // namespace inertialnet::testing
