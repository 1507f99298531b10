// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/linear.hpp"

#include <cstdint>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/bias_activation.hpp"
#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

const std::string kOp = "linear";

// Up to this many samples the packed backend (and any backend on a GPU) runs one GEMV per sample
// (reading W once per sample); more go through the GEMM backend.
constexpr std::size_t kGemvMaxBatch = 4;

}  // namespace

Shape linear_output_shape(const Shape& input, const Shape& weight) {
  if (input.size() < 2) {
    throw invalid_input("linear: the input must be [N, features…] (rank 2 or more), got shape " + to_string(input));
  }
  if (weight.size() != 2) throw invalid_input("linear: the weight must be [out, in], got shape " + to_string(weight));
  detail::require_positive_sizes(input, kOp, "input");
  detail::require_positive_sizes(weight, kOp, "weight");
  const std::int64_t features = element_count(input) / input[0];
  if (features != weight[1]) {
    throw invalid_input("linear: the input " + to_string(input) + " has " + std::to_string(features) +
                        " features per sample but the weight " + to_string(weight) + " expects " +
                        std::to_string(weight[1]));
  }
  return {input[0], weight[0]};
}

void linear(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
            const ActivationSpec& activation) {
  detail::require_defined(input, kOp, "input");
  detail::require_defined(weight, kOp, "weight");
  detail::require_defined(output, kOp, "output");
  const Shape expected = linear_output_shape(input.shape(), weight.shape());
  detail::require_layer_parameters(weight, bias, weight.dim(0), kOp);
  if (output.shape() != expected) {
    throw invalid_input("linear: the output has shape " + to_string(output.shape()) + " but the input " +
                        to_string(input.shape()) + " with weight " + to_string(weight.shape()) + " gives " +
                        to_string(expected));
  }
  const auto batch = static_cast<std::size_t>(expected[0]);
  const auto out_features = static_cast<std::size_t>(expected[1]);
  const auto in_features = static_cast<std::size_t>(weight.dim(1));
  const GemmBackend backend = gemm_backend(queue.device().info());
  const bool gpu_like = queue.device().info().type != DeviceType::CPU;
  if ((uses_packed_kernels(backend) || gpu_like) && batch <= kGemvMaxBatch) {
    // A few samples: one pass over W per sample, W read in place, bias and activation fused.
    // Also under CLBlast on GPUs: a GEMM with one row is bound by reading W, and CLBlast's tiles
    // waste most of their work on it (the head's fc1 ran at 4 GFLOP/s through CLBlast on an H100).
    detail::report_backend(queue, "gemv");
    for (std::size_t n = 0; n < batch; ++n) {
      const auto i = static_cast<std::int64_t>(n);
      gemv(queue, out_features, in_features, MatrixView::of(weight, in_features), input.sample(i),
           output.sample(i), bias, activation);
    }
    return;
  }
  detail::report_backend(queue, to_string(without_winograd(backend)));
  // Row i of A is sample i (contiguous within the sample, batch_stride apart), row i of C the
  // output sample (possibly a slice of wider rows); B = Wᵀ with W stored [out, in].
  gemm(queue, backend, Transpose::No, Transpose::Yes, batch, out_features, in_features, 1.0f,
       MatrixView::of(input, input.batch_stride()), MatrixView::of(weight, in_features), 0.0f,
       MatrixView::of(output, output.batch_stride()));
  add_bias_activation(queue, output, bias, activation);
}

Tensor linear(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
              const ActivationSpec& activation) {
  detail::require_defined(input, kOp, "input");
  detail::require_defined(weight, kOp, "weight");
  Tensor output = Tensor::empty(queue, linear_output_shape(input.shape(), weight.shape()));
  linear(queue, input, weight, bias, output, activation);
  return output;
}

}  // namespace inertialnet
