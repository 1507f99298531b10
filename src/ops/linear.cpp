#include "inertialnet/ops/linear.hpp"

#include <cstdint>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/gemm.hpp"

namespace inertialnet {

namespace {

void require_defined(const Tensor& t, const char* what) {
  if (!t.defined()) throw invalid_input(std::string("linear: the ") + what + " tensor is undefined (empty)");
}

}  // namespace

Shape linear_output_shape(const Shape& input, const Shape& weight) {
  if (input.size() < 2) {
    throw invalid_input("linear: the input must be [N, features…] (rank 2 or more), got shape " + to_string(input));
  }
  if (weight.size() != 2) throw invalid_input("linear: the weight must be [out, in], got shape " + to_string(weight));
  for (const auto d : input) {
    if (d <= 0) throw invalid_input("linear: the input shape " + to_string(input) + " has a zero or negative size");
  }
  for (const auto d : weight) {
    if (d <= 0) throw invalid_input("linear: the weight shape " + to_string(weight) + " has a zero or negative size");
  }
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
  require_defined(input, "input");
  require_defined(weight, "weight");
  require_defined(output, "output");
  const Shape expected = linear_output_shape(input.shape(), weight.shape());
  if (!weight.contiguous()) throw invalid_input("linear: the weight " + to_string(weight.shape()) + " must be contiguous");
  if (bias.defined() && (bias.rank() != 1 || bias.dim(0) != weight.dim(0))) {
    throw invalid_input("linear: the bias has shape " + to_string(bias.shape()) + ", expected [" +
                        std::to_string(weight.dim(0)) + "] for the weight " + to_string(weight.shape()));
  }
  if (output.shape() != expected) {
    throw invalid_input("linear: the output has shape " + to_string(output.shape()) + " but the input " +
                        to_string(input.shape()) + " with weight " + to_string(weight.shape()) + " gives " +
                        to_string(expected));
  }
  const auto batch = static_cast<std::size_t>(expected[0]);
  const auto out_features = static_cast<std::size_t>(expected[1]);
  const auto in_features = static_cast<std::size_t>(weight.dim(1));
  // Row i of A is sample i (contiguous within the sample, batch_stride apart), row i of C the
  // output sample (possibly a slice of wider rows); B = Wᵀ with W stored [out, in].
  gemm(queue, Transpose::No, Transpose::Yes, batch, out_features, in_features, 1.0f,
       MatrixView::of(input, input.batch_stride()), MatrixView::of(weight, in_features), 0.0f,
       MatrixView::of(output, output.batch_stride()));
  add_bias_activation(queue, output, bias, activation);
}

Tensor linear(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
              const ActivationSpec& activation) {
  require_defined(input, "input");
  require_defined(weight, "weight");
  Tensor output = Tensor::empty(queue, linear_output_shape(input.shape(), weight.shape()));
  linear(queue, input, weight, bias, output, activation);
  return output;
}

}  // namespace inertialnet
