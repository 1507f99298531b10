// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/upsample.hpp"

#include <algorithm>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

void check_nchw(const Tensor& t, const std::string& what) {
  if (!t.defined()) throw invalid_input(what + " is an undefined tensor");
  if (t.rank() != 4) throw invalid_input(what + " must be NCHW, got shape " + to_string(t.shape()));
}

void check_size(std::int64_t height, std::int64_t width, const std::string& what) {
  if (height <= 0 || width <= 0) {
    throw invalid_input(what + ": the target size " + std::to_string(height) + "×" + std::to_string(width) +
                        " is empty");
  }
}

// Resamples input into output with out = value · (channel 1 ? scale1 : scale0).
void resample(Queue& queue, const Tensor& input, const Tensor& output, Interpolation mode, float scale0,
              float scale1, const std::string& what) {
  check_nchw(input, what + " input");
  check_nchw(output, what + " output");
  if (output.n() != input.n() || output.c() != input.c()) {
    throw invalid_input(what + ": the output of shape " + to_string(output.shape()) +
                        " must have the batch and channels of the input of shape " + to_string(input.shape()));
  }
  if (output.overlaps(input)) throw invalid_input(what + ": the output overlaps the input");

  const int in_h = static_cast<int>(input.h()), in_w = static_cast<int>(input.w());
  const int out_h = static_cast<int>(output.h()), out_w = static_cast<int>(output.w());
  // in/out in float32, as PyTorch's area_pixel_compute_scale; exactly 1/f for a factor f.
  const float ratio_y = static_cast<float>(in_h) / static_cast<float>(out_h);
  const float ratio_x = static_cast<float>(in_w) / static_cast<float>(out_w);
  Kernel& kernel =
      queue.kernel("upsample", "resample", KernelDefines().add("NEAREST", mode == Interpolation::Nearest));
  kernel.set_args(input, input.batch_stride(), output, output.batch_stride(), input.c(), in_h, in_w, out_h, out_w,
                  ratio_y, ratio_x, scale0, scale1);
  const std::size_t local =
      detail::work_group_size(queue.device(), 64);
  queue.launch(kernel, Range(static_cast<std::size_t>(out_w), static_cast<std::size_t>(out_h),
                             static_cast<std::size_t>(input.n() * input.c())),
               Range(local, 1, 1));
}

const char* name(Interpolation mode) { return mode == Interpolation::Bilinear ? "bilinear" : "nearest"; }

}  // namespace

Shape upsample_output_shape(const Shape& input, int factor) {
  if (input.size() != 4) throw invalid_input("upsample input must be NCHW, got shape " + to_string(input));
  for (const auto d : input) {
    if (d <= 0) throw invalid_input("upsample input shape " + to_string(input) + " has an empty dimension");
  }
  if (factor < 1) throw invalid_input("upsample factor " + std::to_string(factor) + " must be at least 1");
  return {input[0], input[1], input[2] * factor, input[3] * factor};
}

void resize(Queue& queue, const Tensor& input, const Tensor& output, const ResizeOptions& options) {
  resample(queue, input, output, options.mode, options.scale, options.scale, std::string(name(options.mode)) + " resize");
}

Tensor resize(Queue& queue, const Tensor& input, std::int64_t height, std::int64_t width, const ResizeOptions& options) {
  const std::string what = std::string(name(options.mode)) + " resize";
  check_nchw(input, what + " input");
  check_size(height, width, what);
  Tensor output = Tensor::empty(queue, {input.n(), input.c(), height, width});
  resample(queue, input, output, options.mode, options.scale, options.scale, what);
  return output;
}

Tensor upsample(Queue& queue, const Tensor& input, int factor, const ResizeOptions& options) {
  const std::string what = std::string(name(options.mode)) + " upsample";
  check_nchw(input, what + " input");
  Tensor output = Tensor::empty(queue, upsample_output_shape(input.shape(), factor));
  resample(queue, input, output, options.mode, options.scale, options.scale, what + " ×" + std::to_string(factor));
  return output;
}

void resize_flow(Queue& queue, const Tensor& flow, const Tensor& output, float scale) {
  check_nchw(flow, "flow resize input");
  check_nchw(output, "flow resize output");
  if (flow.c() != 2) {
    throw invalid_input("flow resize: the flow must have 2 channels (u, v), got shape " + to_string(flow.shape()));
  }
  // Vectors measured in input pixels become output pixels: u · W'/W, v · H'/H.
  const double su = static_cast<double>(output.w()) / static_cast<double>(flow.w()) * scale;
  const double sv = static_cast<double>(output.h()) / static_cast<double>(flow.h()) * scale;
  resample(queue, flow, output, Interpolation::Bilinear, static_cast<float>(su), static_cast<float>(sv),
           "flow resize");
}

Tensor resize_flow(Queue& queue, const Tensor& flow, std::int64_t height, std::int64_t width, float scale) {
  check_nchw(flow, "flow resize input");
  check_size(height, width, "flow resize");
  Tensor output = Tensor::empty(queue, {flow.n(), flow.c(), height, width});
  resize_flow(queue, flow, output, scale);
  return output;
}

}  // namespace inertialnet
