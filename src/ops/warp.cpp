// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/warp.hpp"

#include <algorithm>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

const std::string kOp = "warp";

}  // namespace

Shape warp_output_shape(const Shape& image, const Shape& flow) {
  if (image.size() != 4) throw invalid_input("warp image must be NCHW, got shape " + to_string(image));
  for (const auto d : image) {
    if (d <= 0) throw invalid_input("warp image shape " + to_string(image) + " has an empty dimension");
  }
  if (flow.size() != 4) throw invalid_input("warp flow must be [N, 2, H, W], got shape " + to_string(flow));
  if (flow[1] != 2) {
    throw invalid_input("warp flow must have 2 channels (u, v), got shape " + to_string(flow));
  }
  if (flow[0] != image[0] || flow[2] != image[2] || flow[3] != image[3]) {
    throw invalid_input("warp flow of shape " + to_string(flow) + " does not match the image of shape " +
                        to_string(image) + " (batch, height and width must be equal)");
  }
  return image;
}

void warp(Queue& queue, const Tensor& image, const Tensor& flow, const Tensor& output) {
  detail::require_defined(image, kOp, "image");
  detail::require_defined(flow, kOp, "flow");
  detail::require_defined(output, kOp, "output");
  const Shape expected = warp_output_shape(image.shape(), flow.shape());
  if (output.shape() != expected) {
    throw invalid_input("warp output must have the image's shape " + to_string(expected) + ", got " +
                        to_string(output.shape()));
  }
  if (output.overlaps(image) || output.overlaps(flow)) {
    throw invalid_input("warp output overlaps its image or flow; it must be a separate tensor");
  }
  const std::int64_t height = image.h(), width = image.w();
  Kernel& kernel = queue.kernel("warp", "warp_bilinear");
  kernel.set_args(image, image.batch_stride(), flow, flow.batch_stride(), output, output.batch_stride(), image.c(),
                  height, width);
  // Rows of up to 64 pixels per group: contiguous flow reads, vectorisable on CPUs.
  const std::size_t local =
      detail::work_group_size(queue.device(), 64);
  queue.launch(kernel, Range(static_cast<std::size_t>(width), static_cast<std::size_t>(height),
                             static_cast<std::size_t>(image.n())),
               Range(local, 1, 1));
}

Tensor warp(Queue& queue, const Tensor& image, const Tensor& flow) {
  detail::require_defined(image, kOp, "image");
  detail::require_defined(flow, kOp, "flow");
  Tensor output = Tensor::empty(queue, warp_output_shape(image.shape(), flow.shape()));
  warp(queue, image, flow, output);
  return output;
}

}  // namespace inertialnet
