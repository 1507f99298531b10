// SPDX-License-Identifier: Apache-2.0
// The batch table's total row (eval/eval_table.hpp) pools the pairs: the RMSE over every pair of
// every sequence, not the mean of the rows' RMSE.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "inertialnet/eval/eval_table.hpp"

using namespace inertialnet;

namespace {

EvalTableRow row(const std::string& name, std::size_t images, std::size_t imu_samples, std::size_t evaluated,
                 std::size_t not_ok, const Vec3& rmse, const Vec3& zero_rmse, const std::string& truth) {
  EvalTableRow r;
  r.name = name;
  r.images = images;
  r.imu_samples = imu_samples;
  r.evaluated = evaluated;
  r.not_ok = not_ok;
  r.rmse_deg_s = rmse;
  r.zero_rmse_deg_s = zero_rmse;
  r.truth = truth;
  return r;
}

}  // namespace

TEST(EvalTable, TotalPoolsEveryPair) {
  // One pair with error 3 on x, three pairs with error 1: pooled sqrt((9 + 3) / 4) = sqrt(3),
  // where the mean of the rows would say 2.
  const EvalTableRow a = row("a", 2, 20, 1, 0, {3, 0, 0}, {4, 0, 0}, "gyro - bias");
  const EvalTableRow b = row("b", 4, 40, 3, 2, {1, 0, 0}, {0, 0, 0}, "raw gyro");
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
  const EvalTableRow a = row("MH_01_easy_long_name", 2, 20, 1, 0, {3, 0.125, 12.5}, {4, 0, 123.456}, "gyro - bias");
  const EvalTableRow b = row("b", 4, 40, 3, 2, {1, 0, 0}, {0, 0, 0}, "raw gyro");
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
