// SPDX-License-Identifier: Apache-2.0
// The -D build options of a kernel program, assembled from typed values:
//   KernelDefines().add("KH", 3).add("HAS_BIAS", true).add("NEGATIVE_SLOPE", 0.1f)
// gives "-DKH=3 -DHAS_BIAS=1 -DNEGATIVE_SLOPE=0x1.99999ap-4f". The string is part of the program
// cache key, so one spelling per value keeps equal programs from compiling twice.
#pragma once

#include <string>
#include <type_traits>

namespace inertialnet {

class KernelDefines {
 public:
  // Integers in decimal.
  template <class T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>, int> = 0>
  KernelDefines& add(const std::string& name, T value) {
    return append(name, std::to_string(value));
  }
  // 1 or 0.
  KernelDefines& add(const std::string& name, bool value) { return append(name, value ? "1" : "0"); }
  // A float literal written as a hex float, so the kernel uses exactly the float the host holds.
  KernelDefines& add(const std::string& name, float value);
  // Every option of `other`, after this one's.
  KernelDefines& add(const KernelDefines& other);

  const std::string& str() const noexcept { return text_; }
  bool empty() const noexcept { return text_.empty(); }

 private:
  KernelDefines& append(const std::string& name, const std::string& value);

  std::string text_;
};

}  // namespace inertialnet
