// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/flow_consistency.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

int mark_inconsistent_flow(FlowField& forward, const FlowField& backward, double threshold_px) {
  if (forward.width != backward.width || forward.height != backward.height) {
    throw invalid_input("flow consistency: the forward flow is " + std::to_string(forward.width) + "x" +
                        std::to_string(forward.height) + " but the backward flow is " + std::to_string(backward.width) +
                        "x" + std::to_string(backward.height));
  }
  if (!(threshold_px > 0) || !std::isfinite(threshold_px)) {
    throw invalid_input("flow consistency: the threshold must be a positive number of pixels");
  }
  const int w = forward.width, h = forward.height;
  if (w < 2 || h < 2) return 0;
  const double limit = threshold_px * threshold_px;
  int marked = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float u = forward.u[i], v = forward.v[i];
      if (is_unknown_flow(u, v)) continue;
      const float qx = static_cast<float>(x) + u, qy = static_cast<float>(y) + v;
      if (!(qx >= 0 && qx <= static_cast<float>(w - 1) && qy >= 0 && qy <= static_cast<float>(h - 1))) continue;
      const int x0 = std::min(static_cast<int>(qx), w - 2), y0 = std::min(static_cast<int>(qy), h - 2);
      const double fx = qx - static_cast<float>(x0), fy = qy - static_cast<float>(y0);
      const std::size_t j = static_cast<std::size_t>(y0) * w + x0;
      double bu = 0, bv = 0;
      bool known = true;
      const std::size_t corner[4] = {j, j + 1, j + w, j + w + 1};
      const double weight[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
      for (int k = 0; k < 4; ++k) {
        if (is_unknown_flow(backward.u[corner[k]], backward.v[corner[k]])) known = false;
        bu += weight[k] * backward.u[corner[k]];
        bv += weight[k] * backward.v[corner[k]];
      }
      if (!known) continue;
      const double eu = u + bu, ev = v + bv;
      if (eu * eu + ev * ev > limit) {
        forward.u[i] = kUnknownFlowValue;
        forward.v[i] = kUnknownFlowValue;
        ++marked;
      }
    }
  }
  return marked;
}

int mark_flow_edge_band(FlowField& flow, int band_px) {
  if (band_px < 0) throw invalid_input("flow edge band: the band must be 0 or more pixels, got " + std::to_string(band_px));
  const int w = flow.width, h = flow.height;
  int marked = 0;
  for (int y = 0; y < h; ++y) {
    const bool edge_row = y < band_px || y > h - 1 - band_px;
    for (int x = 0; x < w; ++x) {
      if (!edge_row && x >= band_px && x <= w - 1 - band_px) continue;
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (!is_unknown_flow(flow.u[i], flow.v[i])) ++marked;
      flow.u[i] = kUnknownFlowValue;
      flow.v[i] = kUnknownFlowValue;
    }
  }
  return marked;
}

void require_flow_check_setting(double px_at_752_columns, const char* name) {
  // The upper bound: a round trip missing by more than kMaxFlowCheckPx pixels at 752 columns is
  // no flow at all, so a larger value only switches the check off silently (1e300 did) while
  // the backward pass is still paid for; 0 is the way to switch it off.
  if (!std::isfinite(px_at_752_columns) || px_at_752_columns < 0 || px_at_752_columns > kMaxFlowCheckPx) {
    std::ostringstream value;  // 1e+300 as such (std::to_string wrote 301 digits)
    value << px_at_752_columns;
    throw invalid_input(std::string(name) + " should be from 0 (off) to " + std::to_string(kMaxFlowCheckPx) +
                        " pixels at 752 columns, got " + value.str());
  }
}

}  // namespace inertialnet
