// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/normalize.hpp"

#include <algorithm>
#include <cmath>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {
namespace {

const std::string kOp = "normalize_frames";

void check_frames(const Tensor& frame1, const Tensor& frame2) {
  detail::require_rank4(frame1, kOp, "first frame");
  detail::require_rank4(frame2, kOp, "second frame");
  if (frame1.shape() != frame2.shape()) {
    throw invalid_input(kOp + ": the frames differ in shape: " + to_string(frame1.shape()) + " and " +
                        to_string(frame2.shape()));
  }
  frame1.offset_int();
  frame2.offset_int();
}

// Enough groups per (n, c) that each work-item adds about eight 8-pixel chunks per frame (short
// float32 running sums in each of its eight lanes), at most 64 and at most one group's worth so
// that the final pass is a single tree. Measured on PoCL at 512×384: fewer, fuller work-items
// beat many short ones (the kernel is bound by loads, not by the tree).
int partial_groups(std::int64_t plane, std::size_t local) {
  const std::int64_t chunks_per_group = static_cast<std::int64_t>(local) * 8;
  const std::int64_t wanted = (plane / 8 + chunks_per_group - 1) / chunks_per_group;
  const std::int64_t most = std::min<std::int64_t>(64, static_cast<std::int64_t>(local));
  return static_cast<int>(std::clamp<std::int64_t>(wanted, 1, most));
}

void enqueue_means(Queue& queue, const Tensor& frame1, const Tensor& frame2, const Tensor& means) {
  const std::size_t local = detail::work_group_size(queue.device(), 256);
  const std::int64_t channels = frame1.c();
  const std::int64_t rows = frame1.n() * frame1.c();
  const std::int64_t plane64 = frame1.h() * frame1.w();
  const int groups = partial_groups(plane64, local);
  const KernelDefines defines = KernelDefines().add("WG_SIZE", local);

  // The partial sums live only until the means pass, which this in-order queue runs next; the
  // buffer goes back to the pool on return, and a later user on this queue runs after us.
  Tensor partial = Tensor::empty(queue, {rows * groups});
  Kernel& sums = queue.kernel("normalize", "channel_partial_sums", defines);
  sums.set_args(frame1, frame1.batch_stride(), frame2, frame2.batch_stride(), channels, plane64, groups, partial);
  queue.launch(sums, Range(static_cast<std::size_t>(groups) * local, static_cast<std::size_t>(rows)), Range(local, 1));

  Kernel& finish = queue.kernel("normalize", "channel_means", defines);
  // 2·H·W is exact in float up to 2^24 (8 M pixels per frame); beyond that it rounds by less
  // than 1e-7 relative, below the sum's own error.
  const float count = static_cast<float>(2 * plane64);
  finish.set_args(partial, groups, count, means);
  queue.launch(finish, Range(static_cast<std::size_t>(rows) * local), Range(local));
}

}  // namespace

Shape normalize_output_shape(const Tensor& frame1, const Tensor& frame2) {
  check_frames(frame1, frame2);
  return {frame1.n(), 2 * frame1.c(), frame1.h(), frame1.w()};
}

void frame_channel_means(Queue& queue, const Tensor& frame1, const Tensor& frame2, const Tensor& means) {
  check_frames(frame1, frame2);
  detail::require_defined(means, kOp, "means");
  const Shape expected{frame1.n(), frame1.c()};
  if (means.shape() != expected) {
    throw invalid_input(kOp + ": the means tensor has shape " + to_string(means.shape()) + ", expected " +
                        to_string(expected) + " for frames " + to_string(frame1.shape()));
  }
  if (means.overlaps(frame1) || means.overlaps(frame2)) {
    throw invalid_input(kOp + ": the means tensor overlaps a frame");
  }
  means.offset_int();
  enqueue_means(queue, frame1, frame2, means);
}

void normalize_frames(Queue& queue, const Tensor& frame1, const Tensor& frame2, const Tensor& output, float rgb_max) {
  const Shape expected = normalize_output_shape(frame1, frame2);
  detail::require_rank4(output, kOp, "output");
  if (output.shape() != expected) {
    throw invalid_input(kOp + ": the output has shape " + to_string(output.shape()) + " but frames " +
                        to_string(frame1.shape()) + " normalise to " + to_string(expected) +
                        " (frame 1 in the first half of the channels, frame 2 in the second)");
  }
  if (!(rgb_max > 0.0f) || !std::isfinite(rgb_max)) {
    throw invalid_input(kOp + ": rgb_max must be positive and finite, got " + std::to_string(rgb_max));
  }
  const std::int64_t channels = frame1.c();
  // In place only where each work-item reads exactly the elements it then overwrites.
  const Tensor first_half = output.channels(0, channels);
  const Tensor second_half = output.channels(channels, channels);
  auto check_alias = [&](const Tensor& frame, const std::string& role, const Tensor& slot) {
    if (output.overlaps(frame) && !detail::same_view(frame, slot)) {
      throw invalid_input(kOp + ": the output overlaps the " + role +
                          " (in place, the frames must be exactly the two channel halves of the output)");
    }
  };
  check_alias(frame1, "first frame", first_half);
  check_alias(frame2, "second frame", second_half);
  output.offset_int();

  Tensor means = Tensor::empty(queue, {frame1.n(), channels});
  enqueue_means(queue, frame1, frame2, means);

  // The same build options as the reduction kernels: one program for the whole family.
  const std::size_t local = detail::work_group_size(queue.device(), 256);
  Kernel& kernel = queue.kernel("normalize", "normalize_pair", KernelDefines().add("WG_SIZE", local));
  const std::int64_t plane = frame1.h() * frame1.w();
  kernel.set_args(output, output.batch_stride(), frame1, frame1.batch_stride(), frame2, frame2.batch_stride(), means,
                  channels, plane, rgb_max);
  queue.launch(kernel,
               Range(static_cast<std::size_t>(plane), static_cast<std::size_t>(channels),
                     static_cast<std::size_t>(frame1.n())),
               Range(local, 1, 1));
}

Tensor normalize_frames(Queue& queue, const Tensor& frame1, const Tensor& frame2, float rgb_max) {
  Tensor output = Tensor::empty(queue, normalize_output_shape(frame1, frame2));
  normalize_frames(queue, frame1, frame2, output, rgb_max);
  return output;
}

}  // namespace inertialnet
