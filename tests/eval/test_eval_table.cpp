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

TEST(EvalTable, TextColumnsStayAligned) {
  // The text table to the byte, as it was printed with printf before the columns were laid out
  // once (core/text_table.hpp): a long name widens the first column, numbers align right.
  EvalTableRow a, b;
  a.name = "MH_01_easy_long_name";
  a.evaluated = 1;
  a.images = 2;
  a.imu_samples = 20;
  a.rmse_deg_s = {3, 0.125, 12.5};
  a.zero_rmse_deg_s = {4, 0, 123.456};
  a.truth = "gyro - bias";
  b.name = "b";
  b.evaluated = 3;
  b.images = 4;
  b.imu_samples = 40;
  b.not_ok = 2;
  b.rmse_deg_s = {1, 0, 0};
  b.zero_rmse_deg_s = {0, 0, 0};
  b.truth = "raw gyro";
  const std::string text = eval_table({a, b}).text();
  EXPECT_EQ(text.substr(0, text.find("RMSE in deg/s")),
            "sequence               images  IMU samples  evaluated  wx [deg/s]  wy [deg/s]  wz [deg/s]      zero "
            "predictor x/y/z  non-ok  truth\n"
            "MH_01_easy_long_name        2           20          1        3.00        0.12       12.50          "
            "4.00/0.00/123.46       0  gyro - bias\n"
            "b                           4           40          3        1.00        0.00        0.00            "
            "0.00/0.00/0.00       2  raw gyro\n"
            "total                       6           60          4        1.73        0.06        6.25           "
            "2.00/0.00/61.73       2  mixed\n");
}
