// SPDX-License-Identifier: Apache-2.0
#include "io/bag/message_fields.hpp"

#include <cstring>

#include "inertialnet/runtime/error.hpp"

namespace inertialnet::bag {

MessageFields::MessageFields(const std::uint8_t* data, std::size_t size, MessageEncoding encoding, std::string where)
    : data_(data), size_(size), encoding_(encoding), where_(std::move(where)) {
  if (encoding_ == MessageEncoding::Cdr) {
    if (size_ < 4) throw invalid_input(where_ + ": a CDR message of " + std::to_string(size_) + " bytes has no encapsulation header");
    // 0x00 0x00: CDR big-endian, 0x00 0x01: CDR little-endian (the PL_CDR kinds carry parameter
    // lists, which ROS 2 does not write for its messages).
    if (data_[0] != 0 || data_[1] > 1) {
      throw invalid_input(where_ + ": the CDR encapsulation header " + std::to_string(data_[0]) + " " + std::to_string(data_[1]) +
                          " is not plain CDR (0 0 big-endian or 0 1 little-endian)");
    }
    big_endian_ = data_[1] == 0;
    at_ = origin_ = 4;
  }
}

const std::uint8_t* MessageFields::take(std::size_t n, std::size_t alignment, const char* what) {
  if (encoding_ == MessageEncoding::Cdr && alignment > 1) {
    const std::size_t misaligned = (at_ - origin_) % alignment;
    if (misaligned) at_ += alignment - misaligned;
  }
  if (at_ > size_ || n > size_ - at_) {
    throw invalid_input(where_ + ": the message ends (" + std::to_string(size_) + " bytes) before its " + what + " at byte " +
                        std::to_string(at_) + " (" + std::to_string(n) + " bytes): it is cut short or not of its declared type");
  }
  const std::uint8_t* p = data_ + at_;
  at_ += n;
  return p;
}

std::uint64_t MessageFields::unsigned_of(const std::uint8_t* p, std::size_t n) const {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t byte = big_endian_ ? i : n - 1 - i;
    value = value << 8 | p[byte];
  }
  return value;
}

std::uint8_t MessageFields::u8() { return *take(1, 1, "uint8"); }
std::uint32_t MessageFields::u32() { return static_cast<std::uint32_t>(unsigned_of(take(4, 4, "uint32"), 4)); }
std::int32_t MessageFields::i32() { return static_cast<std::int32_t>(unsigned_of(take(4, 4, "int32"), 4)); }

double MessageFields::f64() {
  const std::uint64_t bits = unsigned_of(take(8, 8, "float64"), 8);
  double value = 0;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

std::string MessageFields::string() {
  const std::uint32_t n = u32();
  const char* p = reinterpret_cast<const char*>(take(n, 1, "string"));
  if (encoding_ == MessageEncoding::Cdr) {
    // CDR counts the terminating NUL.
    if (n == 0 || p[n - 1] != '\0') throw invalid_input(where_ + ": a CDR string without its terminating NUL at byte " + std::to_string(at_));
    return std::string(p, n - 1);
  }
  return std::string(p, n);
}

std::pair<const std::uint8_t*, std::size_t> MessageFields::byte_sequence() {
  const std::uint32_t n = u32();
  return {take(n, 1, "uint8[] data"), n};
}

std::vector<double> MessageFields::f64_sequence(std::size_t limit) {
  const std::uint32_t n = u32();
  if (n > limit) throw invalid_input(where_ + ": a float64 sequence of " + std::to_string(n) + " values (at most " + std::to_string(limit) + " expected)");
  std::vector<double> values(n);
  for (double& v : values) v = f64();
  return values;
}

std::int64_t MessageFields::header_stamp_ns() {
  std::int64_t stamp = 0;
  if (encoding_ == MessageEncoding::Ros1) {
    u32();  // seq
    const std::uint32_t sec = u32(), nsec = u32();
    stamp = static_cast<std::int64_t>(sec) * 1000000000 + nsec;
  } else {
    const std::int32_t sec = i32();
    const std::uint32_t nanosec = u32();
    stamp = static_cast<std::int64_t>(sec) * 1000000000 + nanosec;
  }
  string();  // frame_id
  return stamp;
}

}  // namespace inertialnet::bag
