// SPDX-License-Identifier: Apache-2.0
// Text tables (core/text_table.hpp) lay their columns out as printf's widths would: bytes counted,
// names left, numbers right, a cell wider than its column not cut.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "inertialnet/core/text_table.hpp"

using namespace inertialnet;

TEST(TextTable, AlignsAsPrintfWould) {
  // bench's GEMM references: "%-22s %9.1f %8.0f%%  %-24s %s\n".
  const TextTable table({{"kind", 22, true, 0}, {"GFLOP/s", 9, false, 1}, {"of GEMM", 9, false, 1},
                         {"M×N×K", 24, true, 2}, {"layer", 0, true, 1}});
  char expected[256];
  std::snprintf(expected, sizeof expected, "%-22s %9s %9s  %-24s %s\n", "kind", "GFLOP/s", "of GEMM", "M×N×K", "layer");
  EXPECT_EQ(table.header(), expected);
  std::snprintf(expected, sizeof expected, "%-22s %9.1f %8.0f%%  %-24s %s\n", "conv 3×3", 123.456, 87.5, "64×128×576",
                "flownetc.conv3");
  EXPECT_EQ(table.row({"conv 3×3", text_cell("%.1f", 123.456), text_cell("%.0f%%", 87.5), "64×128×576",
                       "flownetc.conv3"}),
            expected);
  // Wider than its column: printed whole, the next column pushed on.
  std::snprintf(expected, sizeof expected, "%-22s %9.1f %8.0f%%  %-24s %s\n", "a_kind_name_longer_than_22",
                123456789.0, 123456789.0, "1×2×3", "x");
  EXPECT_EQ(table.row({"a_kind_name_longer_than_22", text_cell("%.1f", 123456789.0), text_cell("%.0f%%", 123456789.0),
                       "1×2×3", "x"}),
            expected);
}

TEST(TextTable, TextCellHasNoLengthLimit) {
  const std::string long_name(1000, 'x');
  EXPECT_EQ(text_cell("%s/%d", long_name.c_str(), 7), long_name + "/7");
  EXPECT_EQ(text_cell("%s", ""), "");
}
