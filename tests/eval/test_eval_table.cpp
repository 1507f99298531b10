// SPDX-License-Identifier: Apache-2.0
// The batch table's total row (eval/eval_table.hpp) pools the pairs: the RMSE over every pair of
// every sequence, not the mean of the rows' RMSE.
#include <gtest/gtest.h>

#include <cmath>

#include "inertialnet/eval/eval_table.hpp"

using namespace inertialnet;

TEST(EvalTable, TotalPoolsEveryPair) {
  // One pair with error 3 on x, three pairs with error 1: pooled sqrt((9 + 3) / 4) = sqrt(3),
  // where the mean of the rows would say 2.
  EvalTableRow a, b;
  a.name = "a";
  a.evaluated = 1;
  a.images = 2;
  a.imu_samples = 20;
  a.rmse_deg_s = {3, 0, 0};
  a.zero_rmse_deg_s = {4, 0, 0};
  a.truth = "gyro - bias";
  b.name = "b";
  b.evaluated = 3;
  b.images = 4;
  b.imu_samples = 40;
  b.not_ok = 2;
  b.rmse_deg_s = {1, 0, 0};
  b.zero_rmse_deg_s = {0, 0, 0};
  b.truth = "raw gyro";
  const EvalTable table = eval_table({a, b});
  EXPECT_NEAR(table.total.rmse_deg_s[0], std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(table.total.zero_rmse_deg_s[0], 2.0, 1e-12);  // sqrt(16 / 4)
  EXPECT_EQ(table.total.evaluated, 4u);
  EXPECT_EQ(table.total.images, 6u);
  EXPECT_EQ(table.total.imu_samples, 60u);
  EXPECT_EQ(table.total.not_ok, 2u);
  EXPECT_EQ(table.total.truth, "mixed");
  const std::string csv = table.csv();
  EXPECT_NE(csv.find("\ntotal,6,60,4,1.73205081,0,0,2,0,0,2,mixed\n"), std::string::npos) << csv;
  EXPECT_NE(table.json().find("\"schema\": \"inertialnet.eval_table/1\""), std::string::npos);
  EXPECT_NE(table.text().find("not a mean of the rows"), std::string::npos);
}
