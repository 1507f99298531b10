// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/dropout_backward.hpp"

namespace inertialnet {

void dropout_backward(Queue& queue, const Tensor& grad_output, const Tensor& grad_input, const DropoutOptions& options) {
  // The mask depends only on (seed, logical index, p): the forward op on the gradient keeps and
  // scales exactly the elements the forward pass kept.
  dropout(queue, grad_output, grad_input, options);
}

}  // namespace inertialnet
