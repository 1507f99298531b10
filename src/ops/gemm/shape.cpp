// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/shape.hpp"

#include <algorithm>

namespace inertialnet {

std::vector<GemmShape> heaviest_gemm_shapes(std::vector<GemmShape> shapes, std::size_t count) {
  std::stable_sort(shapes.begin(), shapes.end(),
                   [](const GemmShape& a, const GemmShape& b) { return a.total_flops() > b.total_flops(); });
  if (count > 0 && count < shapes.size()) shapes.resize(count);
  return shapes;
}

}  // namespace inertialnet
