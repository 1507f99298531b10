// SPDX-License-Identifier: Apache-2.0
// The one transposed-convolution check of the conv_transpose2d suites (test_conv_transpose2d: the
// plan's choice or a form forced; test_winograd_deconv: weights prepared on the winograd plan): a
// case's random input, weights and bias, conv_transpose2d run with its input and output as channel
// slices of wider tensors, and the output against the float64 scatter definition of
// tests/reference/conv.cpp with the bound of every GEMM and sub-pixel form (the Winograd form's
// where it ran).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "ops/op_testing.hpp"
#include "ops/winograd.hpp"
#include "reference/conv.hpp"
#include "support/conv_matches.hpp"
#include "support/flownet_layers.hpp"
#include "support/testing.hpp"

namespace inertialnet::testing {

// One transposed convolution: ci → co channels on an h×w input, a k×k kernel (the fields of a
// convolution's case), and a FlowNet2 layer of the shared table as one.
using DeconvCase = ConvCase;
inline DeconvCase deconv_case_of(const flownet_layers::LayerShape& l) { return conv_case_of(l); }

// Where the op's tensors sit inside wider tensors (`*_before` / `*_after` extra channels around
// the input and the output), the column budget of ConvTranspose2dOptions (0: the op's own) and
// the form forced (Default: the plan's choice).
struct DeconvPlacement {
  int batch = 1;
  int in_before = 0, in_after = 0;
  int out_before = 0, out_after = 0;
  std::size_t max_column_floats = 0;
  DeconvAlgorithm algorithm = DeconvAlgorithm::Default;
};

// The first of the five seeds of a case's random data (input, weights, bias, the wider input and
// output), so that each suite keeps data of its own; `prepared_on`: the weights prepared once for
// that backend, as a network prepares them (none: conv_transpose2d prepares them itself, on the
// device's plan), with the input's shape where `knowing_input` (as a network's graph: the size
// rules apply).
struct DeconvRun {
  std::uint32_t first_seed = 201;
  std::optional<GemmBackend> prepared_on = std::nullopt;
  bool knowing_input = false;
};

// Returns whether the Winograd form computed the output (and set the bound).
inline bool expect_deconv_matches(const DeconvCase& c, const DeconvPlacement& p, const DeconvRun& run = {}) {
  SCOPED_TRACE(c.name);
  Queue& queue = test_queue();
  const reference::ConvShape s{p.batch, c.ci, c.h, c.w, c.co, c.k, c.k, c.stride, c.padding};
  const int oh = s.deconv_out_h(), ow = s.deconv_out_w();
  const LayerOperands o = layer_operands(queue, run.first_seed, {p.batch, c.ci, c.h, c.w}, {c.ci, c.co, c.k, c.k},
                                         {p.batch, c.co, oh, ow}, c.bias, p.in_before, p.in_after, p.out_before,
                                         p.out_after);
  const auto expected = reference::conv_transpose2d(s, o.input, o.weight, o.bias, c.activation);
  ConvTranspose2dOptions options{c.stride, c.padding, c.activation, p.max_column_floats};
  options.algorithm = p.algorithm;
  GemmWeights prepared;
  if (run.prepared_on) {
    prepared = prepare_conv_transpose2d_weights(queue, o.w, *run.prepared_on,
                                                run.knowing_input ? o.in.view.shape() : Shape{}, c.stride, c.padding);
    options.prepared = &prepared;
    expect_winograd_matrices(prepared, c.ci, 4 * c.co);  // the 3×3 layer's 4·co phase rows
  }
  conv_transpose2d(queue, o.in.view, o.w, o.b, o.out.view, options);
  EXPECT_TRUE(untouched_outside(queue, o.out)) << "elements outside the output slice were written";
  // Each output sums at most ci·ceil(k/s)² float32 products of magnitude ≲ 1 (ci per GEMM entry,
  // then the taps that land on the pixel): as for conv2d, an absolute floor of sqrt(K) for that
  // reduction length K and 1e-5 relative to it. The Winograd form runs a 3×3 convolution of ci
  // inputs whose rounding does not know that a phase's 5 of 9 taps are zero (its transformed
  // weights are not): that layer's bound (op_testing.hpp) and floor sqrt(9·ci). Measured on PoCL
  // (test_winograd_deconv): at most 2.2e-5 (flownetc.deconv3, ci = 770; 3.2e-5 against sqrt(4·ci)).
  const bool plan_winograd = p.algorithm == DeconvAlgorithm::Default &&
                             gemm_backend(queue.device().info()) == GemmBackend::Winograd &&
                             detail::winograd_deconv_preferred(o.in.view.shape(), o.w.shape(), c.stride, c.padding);
  const bool winograd = run.prepared_on ? !prepared.winograd.empty() : plan_winograd;
  const int taps = winograd ? 3 : (c.k + c.stride - 1) / c.stride;
  const double floor = std::sqrt(static_cast<double>(c.ci) * taps * taps);
  EXPECT_TRUE(all_close(view_values(queue, o.out), expected, winograd ? kWinogradRelativeTolerance : 1e-5, floor));
  return winograd;
}

}  // namespace inertialnet::testing
