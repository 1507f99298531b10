#include "inertialnet/ops/conv2d.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "inertialnet/ops/gemm.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

std::string kernel_defines(int kh, int kw, int stride, int padding) {
  return "-DKH=" + std::to_string(kh) + " -DKW=" + std::to_string(kw) + " -DSTRIDE=" + std::to_string(stride) +
         " -DPAD=" + std::to_string(padding);
}

void require_defined(const Tensor& t, const char* what) {
  if (!t.defined()) throw invalid_input(std::string("conv2d: the ") + what + " tensor is undefined (empty)");
}

}  // namespace

Shape conv2d_output_shape(const Shape& input, const Shape& weight, int stride, int padding) {
  if (input.size() != 4) throw invalid_input("conv2d: the input must be NCHW (rank 4), got shape " + to_string(input));
  if (weight.size() != 4) {
    throw invalid_input("conv2d: the weight must be [co, ci, kh, kw] (rank 4), got shape " + to_string(weight));
  }
  for (const auto d : input) {
    if (d <= 0) throw invalid_input("conv2d: the input shape " + to_string(input) + " has a zero or negative size");
  }
  for (const auto d : weight) {
    if (d <= 0) throw invalid_input("conv2d: the weight shape " + to_string(weight) + " has a zero or negative size");
  }
  if (stride < 1) throw invalid_input("conv2d: the stride must be at least 1, got " + std::to_string(stride));
  if (padding < 0) throw invalid_input("conv2d: the padding must not be negative, got " + std::to_string(padding));
  if (input[1] != weight[1]) {
    throw invalid_input("conv2d: the input has " + std::to_string(input[1]) + " channels (shape " + to_string(input) +
                        ") but the weight " + to_string(weight) + " expects " + std::to_string(weight[1]));
  }
  const std::int64_t padded_h = input[2] + 2 * std::int64_t{padding};
  const std::int64_t padded_w = input[3] + 2 * std::int64_t{padding};
  if (padded_h < weight[2] || padded_w < weight[3]) {
    throw invalid_input("conv2d: the " + std::to_string(weight[2]) + "×" + std::to_string(weight[3]) +
                        " kernel does not fit the input " + to_string(input) + " padded by " + std::to_string(padding) +
                        " (the output would be empty)");
  }
  return {input[0], weight[0], (padded_h - weight[2]) / stride + 1, (padded_w - weight[3]) / stride + 1};
}

void conv2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias, const Tensor& output,
            const Conv2dOptions& options) {
  require_defined(input, "input");
  require_defined(weight, "weight");
  require_defined(output, "output");
  const Shape expected = conv2d_output_shape(input.shape(), weight.shape(), options.stride, options.padding);
  if (!weight.contiguous()) throw invalid_input("conv2d: the weight " + to_string(weight.shape()) + " must be contiguous");
  if (bias.defined() && (bias.rank() != 1 || bias.dim(0) != weight.dim(0))) {
    throw invalid_input("conv2d: the bias has shape " + to_string(bias.shape()) + ", expected [" +
                        std::to_string(weight.dim(0)) + "] for the weight " + to_string(weight.shape()));
  }
  if (output.shape() != expected) {
    throw invalid_input("conv2d: the output has shape " + to_string(output.shape()) + " but the input " +
                        to_string(input.shape()) + " with weight " + to_string(weight.shape()) + " (stride " +
                        std::to_string(options.stride) + ", padding " + std::to_string(options.padding) +
                        ") gives " + to_string(expected));
  }

  Device& device = queue.device();
  const auto batch = input.n();
  const auto channels = static_cast<std::size_t>(input.c());
  const auto kh = static_cast<std::size_t>(weight.dim(2)), kw = static_cast<std::size_t>(weight.dim(3));
  const auto out_channels = static_cast<std::size_t>(weight.dim(0));
  const auto out_h = static_cast<std::size_t>(expected[2]), out_w = static_cast<std::size_t>(expected[3]);
  const std::size_t reduction = channels * kh * kw;  // GEMM k
  const std::size_t pixels = out_h * out_w;          // GEMM n (per sample)
  const MatrixView weights = MatrixView::of(weight, reduction);

  const bool direct = kh == 1 && kw == 1 && options.stride == 1 && options.padding == 0;
  if (direct) {
    // The input sample is already the [ci, H·W] column matrix.
    for (std::int64_t n = 0; n < batch; ++n) {
      gemm(queue, Transpose::No, Transpose::No, out_channels, pixels, reduction, 1.0f, weights,
           MatrixView::of(input.sample(n), pixels), 0.0f, MatrixView::of(output.sample(n), pixels));
    }
  } else {
    const std::size_t chunk = std::clamp<std::size_t>(detail::column_budget(device, options.max_column_floats) / reduction, 1, pixels);
    const Tensor columns = Tensor::empty(queue, {static_cast<std::int64_t>(reduction), static_cast<std::int64_t>(chunk)});
    Kernel& unfold = queue.kernel("im2col", "im2col",
                                  kernel_defines(static_cast<int>(kh), static_cast<int>(kw), options.stride,
                                                 options.padding));
    const Range local(detail::work_group_size(device, 64), 1);
    for (std::int64_t n = 0; n < batch; ++n) {
      const Tensor in_n = input.sample(n);
      const Tensor out_n = output.sample(n);
      for (std::size_t first = 0; first < pixels; first += chunk) {
        const std::size_t count = std::min(chunk, pixels - first);
        unfold.set_args(in_n, columns, static_cast<int>(channels), static_cast<int>(input.h()),
                        static_cast<int>(input.w()), static_cast<int>(out_h), static_cast<int>(out_w),
                        static_cast<int>(first), static_cast<int>(count));
        queue.launch(unfold, Range(count, channels), local);
        // Output pixels [first, first + count) of every output channel: rows `pixels` apart.
        gemm(queue, Transpose::No, Transpose::No, out_channels, count, reduction, 1.0f, weights,
             MatrixView::of(columns, count), 0.0f, MatrixView::of(out_n, pixels, first));
      }
    }
  }
  add_bias_activation(queue, output, bias, options.activation);
}

Tensor conv2d(Queue& queue, const Tensor& input, const Tensor& weight, const Tensor& bias,
              const Conv2dOptions& options) {
  require_defined(input, "input");
  require_defined(weight, "weight");
  Tensor output = Tensor::empty(queue, conv2d_output_shape(input.shape(), weight.shape(), options.stride,
                                                                     options.padding));
  conv2d(queue, input, weight, bias, output, options);
  return output;
}

void add_bias_activation(Queue& queue, const Tensor& x, const Tensor& bias, const ActivationSpec& activation) {
  if (!x.defined()) throw invalid_input("bias/activation: the tensor is undefined (empty)");
  if (x.rank() < 2) throw invalid_input("bias/activation: expected [N, C, …], got shape " + to_string(x.shape()));
  const bool has_bias = bias.defined();
  if (has_bias && (bias.rank() != 1 || bias.dim(0) != x.dim(1))) {
    throw invalid_input("bias/activation: the bias has shape " + to_string(bias.shape()) + ", expected [" +
                        std::to_string(x.dim(1)) + "] for a tensor of shape " + to_string(x.shape()));
  }
  if (!has_bias && activation.kind == Activation::None) return;
  const std::size_t sample = x.sample_size();
  const std::size_t plane = sample / static_cast<std::size_t>(x.dim(1));
  Kernel& kernel = queue.kernel("bias_activation", "bias_activation",
                                std::string("-DHAS_BIAS=") + (has_bias ? "1 " : "0 ") + activation_defines(activation));
  // Without a bias the kernel never reads its bias argument; any valid buffer will do.
  const Tensor& bias_arg = has_bias ? bias : x;
  kernel.set_args(x, static_cast<int>(x.batch_stride()), static_cast<int>(x.dim(0)), static_cast<int>(x.dim(1)),
                  static_cast<int>(plane), bias_arg);
  queue.launch(kernel, Range(sample, static_cast<std::size_t>(x.dim(0))), Range(detail::work_group_size(queue.device(), 64), 1));
}

}  // namespace inertialnet
