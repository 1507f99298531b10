// SPDX-License-Identifier: Apache-2.0
// Plain C++ loops of FlowNet2's flow-specific layers, written from docs/model_spec.md
// (Correlation, Warp, ChannelNorm, the FlowNet2 up-sampling steps, "Any input size"): the
// references for kernels_cl/{correlation,warp,channel_norm,upsample}.cl. Tensors are
// contiguous NCHW vectors.
#pragma once

#include <cstddef>
#include <ostream>
#include <vector>

#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet::reference {

struct Dims {
  int n, c, h, w;
  int count() const { return n * c * h * w; }
};
inline std::ostream& operator<<(std::ostream& out, Dims d) {
  return out << '[' << d.n << ", " << d.c << ", " << d.h << ", " << d.w << ']';
}
inline Shape shape_of(Dims d) { return {d.n, d.c, d.h, d.w}; }

// flownet2-pytorch's Correlation; accumulated in double. Returns [n, D², h_out, w_out] and sets
// `out` to those dimensions.
std::vector<float> correlation(const std::vector<float>& f1, const std::vector<float>& f2, Dims in, int pad,
                               int kernel_size, int max_displacement, int stride1, int stride2, Dims& out);

// Resample2d (kernel 1): bilinear sample at (x + u, y + v) with clamped corner indices.
std::vector<float> warp(const std::vector<float>& image, const std::vector<float>& flow, Dims in);

// sqrt(Σ_c in²) → [n, 1, h, w].
std::vector<float> channel_norm(const std::vector<float>& input, Dims in);

// PyTorch interpolate(size = (out_h, out_w), mode = 'bilinear', align_corners = False) and
// mode = 'nearest', times `scale`.
std::vector<float> upsample_bilinear(const std::vector<float>& input, Dims in, int out_h, int out_w, float scale = 1);
std::vector<float> upsample_nearest(const std::vector<float>& input, Dims in, int out_h, int out_w, float scale = 1);

// Bilinear resize of a flow [n, 2, h, w] to out_h × out_w with u · out_w/w and v · out_h/h.
std::vector<float> resize_flow(const std::vector<float>& flow, Dims in, int out_h, int out_w, float scale = 1);

}  // namespace inertialnet::reference
