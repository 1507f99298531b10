// SPDX-License-Identifier: Apache-2.0
// CRC-32 as zlib, PNG and MCAP compute it (polynomial 0xEDB88320, reflected, inverted), shared by
// the readers that check one (PNG chunks in image_io.cpp, MCAP chunks in bag/mcap.cpp). A table
// of our own rather than zlib's crc32(): the library does not otherwise link zlib. Not part of
// the public API.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace inertialnet::io_detail {

inline std::uint32_t crc32_of(const unsigned char* data, std::size_t size) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

}  // namespace inertialnet::io_detail
