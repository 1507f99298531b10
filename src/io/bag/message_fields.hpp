// SPDX-License-Identifier: Apache-2.0
// Inside the library only: the fields of one serialised ROS message, read in declaration order,
// for both encodings a bag holds (bag.hpp's MessageEncoding):
//   - ROS 1: packed little-endian, no alignment; a string is a u32 length and its bytes (no NUL);
//     std_msgs/Header is u32 seq, time (u32 sec, u32 nsec), frame_id.
//   - CDR (ROS 2): a 4-byte encapsulation header (0x00 0x00 big-endian, 0x00 0x01 little-endian,
//     then two option bytes); each primitive aligned to its size, counted from the end of that
//     header; a string is a u32 length that includes its NUL; std_msgs/Header is
//     builtin_interfaces/Time (int32 sec, uint32 nanosec) and frame_id, without seq.
// Variable-length sequences are a u32 count, then the elements, in both. Every read is checked
// against the message's size: a short or damaged message is invalid_input naming `where`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "inertialnet/io/bag.hpp"

namespace inertialnet::bag {

class MessageFields {
 public:
  MessageFields(const std::uint8_t* data, std::size_t size, MessageEncoding encoding, std::string where);

  std::uint8_t u8();
  std::uint32_t u32();
  std::int32_t i32();
  double f64();
  std::string string();
  // uint8[]: a u32 count, then the bytes (a view into the message: valid while it lives).
  std::pair<const std::uint8_t*, std::size_t> byte_sequence();
  // float64[]: a u32 count, then the values; at most `limit` values (a count beyond it is damage).
  std::vector<double> f64_sequence(std::size_t limit);
  // std_msgs/Header: its stamp in nanoseconds (seq, in ROS 1, and frame_id are read and dropped).
  std::int64_t header_stamp_ns();

  bool big_endian() const { return big_endian_; }
  const std::string& where() const { return where_; }

 private:
  const std::uint8_t* take(std::size_t n, std::size_t alignment, const char* what);
  std::uint64_t unsigned_of(const std::uint8_t* p, std::size_t n) const;

  const std::uint8_t* data_;
  std::size_t size_;
  MessageEncoding encoding_;
  std::string where_;
  std::size_t at_ = 0;
  std::size_t origin_ = 0;  // where CDR's alignment counts from (after the encapsulation header)
  bool big_endian_ = false;
};

}  // namespace inertialnet::bag
