// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/kernel_defines.hpp"

#include <cstdio>

namespace inertialnet {

KernelDefines& KernelDefines::add(const std::string& name, float value) {
  char literal[48];
  std::snprintf(literal, sizeof literal, "%af", static_cast<double>(value));
  return append(name, literal);
}

KernelDefines& KernelDefines::add(const KernelDefines& other) {
  if (other.text_.empty()) return *this;
  if (!text_.empty()) text_ += ' ';
  text_ += other.text_;
  return *this;
}

KernelDefines& KernelDefines::append(const std::string& name, const std::string& value) {
  if (!text_.empty()) text_ += ' ';
  text_ += "-D" + name + "=" + value;
  return *this;
}

}  // namespace inertialnet
