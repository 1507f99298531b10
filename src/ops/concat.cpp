// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/concat.hpp"

#include "inertialnet/ops/elementwise.hpp"
#include "ops/op_support.hpp"

namespace inertialnet {
namespace {

// Same rank, batch and spatial sizes as `reference`; any channel count.
void require_matching(const Tensor& t, const Tensor& reference, const std::string& op, const std::string& role,
                      const std::string& reference_role) {
  detail::require_defined(t, op, role);
  if (t.rank() < 2) {
    throw invalid_input(op + ": the " + role + " needs a channel axis (rank ≥ 2), got shape " + to_string(t.shape()));
  }
  bool same = t.rank() == reference.rank();
  for (int axis = 0; same && axis < t.rank(); ++axis) same = axis == 1 || t.dim(axis) == reference.dim(axis);
  if (!same) {
    throw invalid_input(op + ": the " + role + " has shape " + to_string(t.shape()) + " but the " + reference_role +
                        " has shape " + to_string(reference.shape()) + "; only the channel axis may differ");
  }
}

}  // namespace

void copy_into_channels(Queue& queue, const Tensor& src, const Tensor& dst, std::int64_t first_channel) {
  const std::string op = "copy_into_channels";
  detail::require_defined(dst, op, "destination");
  require_matching(src, dst, op, "source", "destination");
  if (first_channel < 0 || first_channel + src.dim(1) > dst.dim(1)) {
    throw invalid_input(op + ": channels [" + std::to_string(first_channel) + ", " +
                        std::to_string(first_channel + src.dim(1)) + ") of the source " + to_string(src.shape()) +
                        " do not fit the destination " + to_string(dst.shape()));
  }
  copy(queue, src, dst.channels(first_channel, src.dim(1)));
}

Shape concat_output_shape(const std::vector<Tensor>& inputs) {
  const std::string op = "concat_channels";
  if (inputs.empty()) throw invalid_input(op + ": no input tensors");
  const Tensor& first = inputs.front();
  detail::require_defined(first, op, "input 0");
  std::int64_t channels = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    require_matching(inputs[i], first, op, "input " + std::to_string(i), "input 0");
    channels += inputs[i].dim(1);
  }
  Shape shape = first.shape();
  shape[1] = channels;
  return shape;
}

void concat_channels(Queue& queue, const std::vector<Tensor>& inputs, const Tensor& output) {
  const std::string op = "concat_channels";
  const Shape expected = concat_output_shape(inputs);
  detail::require_defined(output, op, "output");
  if (output.shape() != expected) {
    throw invalid_input(op + ": the output has shape " + to_string(output.shape()) + " but the inputs concatenate to " +
                        to_string(expected));
  }
  // Check every input before copying any, so a refused call leaves the output as it was.
  std::int64_t first = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const Tensor part = output.channels(first, inputs[i].dim(1));
    // An input may already sit in its own slot (produced in place); any other overlap with the
    // output would be overwritten before or while it is read.
    if (!detail::same_view(part, inputs[i]) && output.overlaps(inputs[i])) {
      throw invalid_input(op + ": input " + std::to_string(i) + " overlaps the output outside its own slot");
    }
    first += inputs[i].dim(1);
  }
  first = 0;
  for (const Tensor& input : inputs) {
    // An input already produced in place (the same view) costs nothing.
    copy(queue, input, output.channels(first, input.dim(1)));
    first += input.dim(1);
  }
}

Tensor concat_channels(Queue& queue, const std::vector<Tensor>& inputs) {
  Tensor output = Tensor::empty(queue, concat_output_shape(inputs));
  concat_channels(queue, inputs, output);
  return output;
}

}  // namespace inertialnet
