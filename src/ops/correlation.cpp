// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/correlation.hpp"

#include <algorithm>
#include <string>

#include "inertialnet/runtime/device.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {

namespace {

std::string describe(const CorrelationOptions& p) {
  return "correlation (pad " + std::to_string(p.pad) + ", kernel " + std::to_string(p.kernel_size) +
         ", max displacement " + std::to_string(p.max_displacement) + ", stride1 " + std::to_string(p.stride1) +
         ", stride2 " + std::to_string(p.stride2) + ")";
}

void check_options(const CorrelationOptions& p) {
  const std::string what = describe(p);
  if (p.kernel_size < 1 || p.kernel_size % 2 == 0) {
    throw invalid_input(what + ": the kernel size must be a positive odd number");
  }
  if (p.stride1 < 1 || p.stride2 < 1) throw invalid_input(what + ": strides must be at least 1");
  if (p.pad < 0 || p.max_displacement < 0) {
    throw invalid_input(what + ": pad and max displacement must not be negative");
  }
  // flownet2-pytorch accepts it, but the output grid is then cropped and shifted against the
  // input's; no FlowNet variant does that, so it is refused as a configuration error.
  if (p.max_displacement > p.pad) {
    throw invalid_input(what + ": the max displacement exceeds the padding");
  }
  if (p.vector_width != 0 && p.vector_width != 1 && p.vector_width != 4 && p.vector_width != 8 &&
      p.vector_width != 16) {
    throw invalid_input(what + ": vector width " + std::to_string(p.vector_width) + " is not 0, 1, 4, 8 or 16");
  }
  if (p.vector_width > 1 && p.stride1 != 1) {
    throw invalid_input(what + ": a vector width above 1 needs stride1 1");
  }
}

std::int64_t output_extent(std::int64_t size, const CorrelationOptions& p) {
  const std::int64_t span = size + 2 * p.pad - 2 * (p.max_displacement + p.kernel_radius());
  return span <= 0 ? 0 : (span + p.stride1 - 1) / p.stride1;  // ceil(span / stride1)
}

void check_tensor(const Tensor& t, const char* name) {
  detail::require_defined(t, "correlation", name);
  if (t.rank() != 4) {
    throw invalid_input(std::string("correlation ") + name + " must be NCHW, got shape " + to_string(t.shape()));
  }
}

}  // namespace

Shape correlation_output_shape(const Shape& input, const CorrelationOptions& options) {
  check_options(options);
  if (input.size() != 4) throw invalid_input(describe(options) + ": inputs must be NCHW, got shape " + to_string(input));
  for (const auto d : input) {
    if (d <= 0) throw invalid_input(describe(options) + ": input shape " + to_string(input) + " has an empty dimension");
  }
  const std::int64_t h = output_extent(input[2], options), w = output_extent(input[3], options);
  if (h <= 0 || w <= 0) {
    throw invalid_input(describe(options) + ": an input of " + std::to_string(input[2]) + "×" +
                        std::to_string(input[3]) + " pixels is too small for any output");
  }
  return {input[0], options.output_channels(), h, w};
}

void correlation(Queue& queue, const Tensor& input1, const Tensor& input2, const Tensor& output,
                 const CorrelationOptions& options) {
  check_tensor(input1, "input 1");
  check_tensor(input2, "input 2");
  check_tensor(output, "output");
  if (input1.c() != input2.c()) {
    throw invalid_input("correlation inputs have " + std::to_string(input1.c()) + " and " +
                        std::to_string(input2.c()) + " channels; they must match");
  }
  if (input1.shape() != input2.shape()) {
    throw invalid_input("correlation inputs have shapes " + to_string(input1.shape()) + " and " +
                        to_string(input2.shape()) + "; they must match");
  }
  const Shape expected = correlation_output_shape(input1.shape(), options);
  if (output.shape() != expected) {
    throw invalid_input(describe(options) + " of inputs " + to_string(input1.shape()) + " needs an output of shape " +
                        to_string(expected) + ", got " + to_string(output.shape()));
  }
  if (output.overlaps(input1) || output.overlaps(input2)) {
    throw invalid_input("correlation output overlaps one of its inputs");
  }

  const DeviceInfo& info = queue.device().info();
  const int k = options.kernel_size, kr = options.kernel_radius(), s1 = options.stride1, s2 = options.stride2;
  const int radius = options.displacement_radius(), size = options.displacement_size();
  const int out_h = static_cast<int>(expected[2]), out_w = static_cast<int>(expected[3]);
  // CPUs: a strip of 16 pixels per work-item, one AVX-512 register per accumulator (measured
  // against 8, 4 and 1 in bench/flow_ops_bench.cpp). Elsewhere one pixel per work-item, so
  // neighbouring work-items read neighbouring floats.
  int vx = options.vector_width;
  if (vx == 0) vx = (info.type == DeviceType::CPU && s1 == 1) ? 16 : 1;
  const int strips = (out_w + vx - 1) / vx;

  const KernelDefines defines = KernelDefines()
                                    .add("KS", k)
                                    .add("S1", s1)
                                    .add("S2", s2)
                                    .add("DS", size)
                                    .add("VX", vx)
                                    .add(activation_defines(options.activation));
  const std::size_t max_wg = std::max<std::size_t>(1, info.max_work_group_size);

  // Each input as a zero-padded frame [N, rows, C, columns] (see kernels_cl/correlation.cl).
  // `extra` is how far the frame reaches beyond the kernel windows on each side: the
  // displacements, for f2. The frames are pooled temporaries released on return; the in-order
  // queue runs the correlation before any later command can reuse their buffers.
  struct Frame {
    Tensor buffer;
    int height, row0;
  };
  const int centre = options.max_displacement - options.pad;  // input position of output 0
  const int channels = static_cast<int>(input1.c());
  auto frame = [&](const Tensor& input, int extra) {
    const int in_h = static_cast<int>(input.h()), in_w = static_cast<int>(input.w());
    const int left = kr + extra - centre;                     // frame column 0 is input column −left
    const int width = (strips * vx - 1) * s1 + k + 2 * extra;  // covers the last strip's overrun
    // KS == 1 reads one row per output row and tests it in the kernel: rows need no padding.
    const bool pad_rows = k > 1;
    const int top = pad_rows ? left : 0;
    const int height = pad_rows ? (out_h - 1) * s1 + k + 2 * extra : in_h;
    Frame f{Tensor::empty(queue, {input.n(), height, channels, width}), height,
            pad_rows ? 0 : centre - extra};
    Kernel& pad = queue.kernel("correlation", "correlation_pad", defines);
    pad.set_args(input, input.batch_stride(), channels, in_h, in_w, f.buffer, height, width, top, left);
    queue.launch(pad, Range(static_cast<std::size_t>(height), static_cast<std::size_t>(input.n()) * channels),
                 Range(std::min<std::size_t>(8, max_wg), 1));
    return f;
  };
  const Frame a = frame(input1, 0);
  const Frame b = frame(input2, radius * s2);
  auto row_stride = [](const Frame& f) { return f.buffer.dim(2) * f.buffer.dim(3); };
  auto channel_stride = [](const Frame& f) { return f.buffer.dim(3); };

  Kernel& kernel = queue.kernel("correlation", "correlation", defines);
  kernel.set_args(a.buffer, a.buffer.batch_stride(), a.height, row_stride(a), channel_stride(a), a.row0, b.buffer,
                  b.buffer.batch_stride(), b.height, row_stride(b), channel_stride(b), b.row0, channels, output,
                  output.batch_stride(), out_h, out_w);
  // Dimension 2 enumerates f2 frame rows with stride1 1 (the kernel's cache-friendly order),
  // output rows otherwise. CPUs: a group is one row of strips; GPUs: 64 pixels of a row.
  const std::size_t rows = s1 == 1 ? static_cast<std::size_t>(out_h + (size - 1) * s2 + s2 - 1) / s2 * s2
                                   : static_cast<std::size_t>(out_h);
  const std::size_t wg = vx > 1 ? std::min<std::size_t>({static_cast<std::size_t>(strips), 8, max_wg})
                                : std::min<std::size_t>(64, max_wg);
  queue.launch(kernel,
               Range(static_cast<std::size_t>(strips), static_cast<std::size_t>(size),
                     static_cast<std::size_t>(input1.n()) * rows),
               Range(wg, 1, 1));
}

Tensor correlation(Queue& queue, const Tensor& input1, const Tensor& input2, const CorrelationOptions& options) {
  check_tensor(input1, "input 1");
  Tensor output = Tensor::empty(queue, correlation_output_shape(input1.shape(), options));
  correlation(queue, input1, input2, output, options);
  return output;
}

}  // namespace inertialnet
