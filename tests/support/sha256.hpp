// SPDX-License-Identifier: Apache-2.0
// SHA-256 (FIPS 180-4) for tests that compare tensors with fixtures by digest; kept in the tests
// so the library itself needs no crypto dependency.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace inertialnet::testing {

class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t size);
  std::array<uint8_t, 32> finish();  // the object must not be updated afterwards

 private:
  void compress(const uint8_t* block);

  std::array<uint32_t, 8> state_;
  std::array<uint8_t, 64> buffer_{};
  std::size_t buffered_ = 0;
  uint64_t total_bytes_ = 0;
};

// Lower-case hex digest of `size` bytes.
std::string sha256_hex(const void* data, std::size_t size);

}  // namespace inertialnet::testing
