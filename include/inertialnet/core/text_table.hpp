// SPDX-License-Identifier: Apache-2.0
// Plain-text tables with aligned columns, as the command line prints them (eval's batch table,
// bench's GEMM references): the columns are laid out once and serve the titles and every row.
// Widths count bytes, as printf's "%-*s" does (a "×" counts two), so a table that was printed
// with printf reads the same to the byte.
#pragma once

#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace inertialnet {

struct TextColumn {
  std::string title;
  std::size_t width = 0;  // at least this many bytes; a longer cell is not cut
  bool left = false;      // left-aligned (names, words); numbers right-aligned
  std::size_t gap = 2;    // spaces before the column (none before the first)
};

class TextTable {
 public:
  explicit TextTable(std::vector<TextColumn> columns) : columns_(std::move(columns)) {}

  // The titles as a row.
  std::string header() const {
    std::vector<std::string> titles;
    for (const auto& c : columns_) titles.push_back(c.title);
    return row(titles);
  }

  // One line, '\n'-terminated: cells[i] in column i (missing cells are empty).
  std::string row(const std::vector<std::string>& cells) const {
    std::string out;
    for (std::size_t i = 0; i < columns_.size(); ++i) {
      const TextColumn& c = columns_[i];
      const std::string cell = i < cells.size() ? cells[i] : std::string();
      if (i > 0) out.append(c.gap, ' ');
      const std::string fill(cell.size() < c.width ? c.width - cell.size() : 0, ' ');
      out += c.left ? cell + fill : fill + cell;
    }
    return out + "\n";
  }

 private:
  std::vector<TextColumn> columns_;
};

// printf into a string, for a cell: text_cell("%.2f", rmse).
inline std::string text_cell(const char* format, ...) __attribute__((format(printf, 1, 2)));
inline std::string text_cell(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string out(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (size > 0) std::vsnprintf(&out[0], out.size() + 1, format, again);
  va_end(again);
  return out;
}

}  // namespace inertialnet
