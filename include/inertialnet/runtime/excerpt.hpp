// SPDX-License-Identifier: Apache-2.0
// What a message quotes of a value the user gave: the text itself when short, else its first
// characters and "…", so that a pasted 300-digit number or a whole file pasted into an option does
// not flood the terminal (issue 20, item 9). One rule for the CLI's parsers and the library's.
#pragma once

#include <cstddef>
#include <string>

namespace inertialnet {

inline constexpr std::size_t kExcerptLength = 40;

// `text` when at most `limit` bytes, else its first `limit` bytes (never cutting a UTF-8
// character) followed by "…".
inline std::string excerpt(const std::string& text, std::size_t limit = kExcerptLength) {
  if (text.size() <= limit) return text;
  std::size_t cut = limit;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // a continuation byte
  return text.substr(0, cut) + "\xE2\x80\xA6";
}

}  // namespace inertialnet
