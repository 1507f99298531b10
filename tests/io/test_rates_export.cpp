// SPDX-License-Identifier: Apache-2.0
// The rates in other tools' formats (io/rates_export.hpp): Gyroflow's .gcsv, EuRoC's imu0/data.csv
// and a TUM orientation trajectory, checked against hand-computed lines and values, with rows
// that have no answer left out (gcsv, EuRoC) or held (TUM).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/io/rates_export.hpp"
#include "inertialnet/runtime/error.hpp"
#include "support/testing.hpp"

using namespace inertialnet;
namespace te = inertialnet::testing_euroc;

namespace {

using inertialnet::testing::contains;
using inertialnet::testing::expect_invalid_input;

// A rates table as predict writes it (read back through the library's own reader).
RatesTable table_from(const te::TempDir& dir, const std::string& text) {
  const auto path = dir.path() / "rates.csv";
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
  return read_rates_csv(path);
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> fields(const std::string& line, char separator) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, separator)) out.push_back(field);
  if (!line.empty() && line.back() == separator) out.push_back("");
  return out;
}

const char* kThreeRows =
    "# schema: inertialnet.rates/2\n"
    "# frame: body\n"
    "# estimator: inter_frame\n"
    "timestamp_ns,wx,wy,wz,status\n"
    "1403715273312143104,0.0123,-0.0456,0.0789,ok\n"
    "1403715273362143604,,,,no_texture\n"
    "1403715273412143499,-1.5,2.25e-05,3,ok\n";

}  // namespace

TEST(RatesExport, FormatNames) {
  EXPECT_EQ(rates_export_format_from_string("gyroflow"), RatesExportFormat::Gyroflow);
  EXPECT_EQ(rates_export_format_from_string("gcsv"), RatesExportFormat::Gyroflow);  // predict --format's word
  EXPECT_EQ(rates_export_format_from_string("euroc-imu"), RatesExportFormat::EurocImu);
  EXPECT_EQ(rates_export_format_from_string("tum"), RatesExportFormat::Tum);
  EXPECT_STREQ(to_string(RatesExportFormat::EurocImu), "euroc-imu");
  expect_invalid_input([] { rates_export_format_from_string("csv"); }, "'csv'; expected one of gcsv, gyroflow, euroc-imu, tum");
}

TEST(RatesExport, GcsvHeaderAndOkRowsInMicroseconds) {
  te::TempDir dir("export_gcsv");
  const RatesTable table = table_from(dir, kThreeRows);
  RatesExportSummary summary;
  const auto lines = lines_of(rates_to_gcsv(table, {}, "in/rates.csv", summary));
  ASSERT_EQ(lines.size(), 11u);
  EXPECT_EQ(lines[0], "GYROFLOW IMU LOG");
  EXPECT_EQ(lines[1], "version,1.3");
  EXPECT_EQ(lines[2], "id,inertialnet");
  EXPECT_EQ(lines[3], "orientation,XYZ");
  EXPECT_EQ(lines[4], "note,inertialnet rates wx wy wz of rates.csv; frame body; estimator inter_frame");
  EXPECT_EQ(lines[5], "tscale,0.000001");
  EXPECT_EQ(lines[6], "gscale,1");
  EXPECT_EQ(lines[7], "ascale,1");
  EXPECT_EQ(lines[8], "t,gx,gy,gz");
  // ...143104 ns → ...143 µs; ...143499 ns → ...143 µs (rounded to the nearest); the no_texture row is left out.
  EXPECT_EQ(lines[9], "1403715273312143,0.0123,-0.0456,0.0789");
  EXPECT_EQ(lines[10], "1403715273412143,-1.5,2.25e-05,3");
  // tscale × t gives seconds, and the integer is exact in a double (what Gyroflow reads it into).
  EXPECT_EQ(static_cast<double>(1403715273312143LL), std::strtod("1403715273312143", nullptr));
  EXPECT_EQ(summary.rows_written, 2u);
  EXPECT_EQ(summary.pairs_left_out, 1u);
  EXPECT_EQ(summary.left_out_by_status.at("no_texture"), 1u);
  ASSERT_EQ(summary.notes.size(), 1u);
  EXPECT_EQ(summary.notes[0], "pairs without an answer, left out: 1 (no_texture 1)");
}

TEST(RatesExport, GcsvRatesRoundTripFloats) {
  te::TempDir dir("export_gcsv_rt");
  std::string text = "# schema: inertialnet.rates/2\n# frame: camera\ntimestamp_ns,wx,wy,wz,status\n";
  std::vector<float> values;
  for (int i = 0; i < 40; ++i) {
    const float a = 0.1f * static_cast<float>(i) - 1.234567f, b = 1e-7f * static_cast<float>(i * i + 1), c = -3e3f / static_cast<float>(i + 3);
    values.insert(values.end(), {a, b, c});
    char row[160];
    std::snprintf(row, sizeof row, "%lld,%.9g,%.9g,%.9g,ok\n", 1000000000LL + 50'000'000LL * i, a, b, c);
    text += row;
  }
  RatesExportSummary summary;
  const auto lines = lines_of(rates_to_gcsv(table_from(dir, text), {}, "rates.csv", summary));
  ASSERT_EQ(lines.size(), 9u + 40u);
  for (int i = 0; i < 40; ++i) {
    const auto f = fields(lines[9 + static_cast<std::size_t>(i)], ',');
    ASSERT_EQ(f.size(), 4u);
    EXPECT_EQ(std::strtoll(f[0].c_str(), nullptr, 10), 1000000LL + 50'000LL * i);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(static_cast<float>(std::strtod(f[1 + static_cast<std::size_t>(k)].c_str(), nullptr)),
                values[static_cast<std::size_t>(3 * i + k)]);
    }
  }
  EXPECT_TRUE(contains(lines[4], "frame camera"));
}

TEST(RatesExport, EurocImuGyroOnlyBodyFrame) {
  te::TempDir dir("export_euroc");
  RatesExportSummary summary;
  const auto lines = lines_of(rates_to_euroc_imu(table_from(dir, kThreeRows), {}, "rates.csv", summary));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0],
            "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
            "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]");
  // Nanoseconds as they are; the accelerometer cells empty (no measurement, not free fall).
  EXPECT_EQ(lines[1], "1403715273312143104,0.0123,-0.0456,0.0789,,,");
  EXPECT_EQ(lines[2], "1403715273412143499,-1.5,2.25e-05,3,,,");
  EXPECT_EQ(fields(lines[1], ',').size(), 7u);
  EXPECT_EQ(summary.rows_written, 2u);
  EXPECT_EQ(summary.pairs_left_out, 1u);
}

TEST(RatesExport, EurocImuRefusesCameraFrameUnlessAllowed) {
  te::TempDir dir("export_euroc_cam");
  std::string camera = kThreeRows;
  camera.replace(camera.find("frame: body"), 11, "frame: camera");
  const RatesTable table = table_from(dir, camera);
  RatesExportSummary summary;
  expect_invalid_input([&] { rates_to_euroc_imu(table, {}, "cam/rates.csv", summary); },
                       "cam/rates.csv: the rates are not stated to be in the body (IMU) frame (frame: camera)");
  RatesExportOptions allow;
  allow.allow_camera_frame = true;
  RatesExportSummary allowed;
  const auto lines = lines_of(rates_to_euroc_imu(table, allow, "cam/rates.csv", allowed));
  EXPECT_EQ(lines.size(), 3u);
  ASSERT_FALSE(allowed.notes.empty());
  EXPECT_TRUE(contains(allowed.notes[0], "not the IMU frame"));
  // A schema-1 file states no frame: not body either.
  const RatesTable old = table_from(dir, "timestamp_ns,wx,wy,wz\n1000,0.1,0.2,0.3\n");
  RatesExportSummary s1;
  expect_invalid_input([&] { rates_to_euroc_imu(old, {}, "old.csv", s1); }, "no frame stated");
}

TEST(RatesExport, TumConstantYawOfOneRadian) {
  te::TempDir dir("export_tum");
  // 1 rad/s about z, rows every 0.1 s from t = 2 s to 3 s: the first row starts the trajectory,
  // the ten after it integrate 0.1 rad each.
  std::string text = "# schema: inertialnet.rates/2\n# frame: body\ntimestamp_ns,wx,wy,wz,status\n";
  for (int i = 0; i <= 10; ++i) text += std::to_string(2'000'000'000LL + 100'000'000LL * i) + ",0,0,1,ok\n";
  RatesExportSummary summary;
  const auto lines = lines_of(rates_to_tum(table_from(dir, text), {}, "rates.csv", summary));
  ASSERT_EQ(lines.size(), 12u);
  EXPECT_EQ(lines[0], "# timestamp tx ty tz qx qy qz qw");
  EXPECT_EQ(lines[1], "2.000000000 0 0 0 0 0 0 1");
  const auto last = fields(lines[11], ' ');
  ASSERT_EQ(last.size(), 8u);
  EXPECT_EQ(last[0], "3.000000000");
  EXPECT_EQ(last[1] + last[2] + last[3], "000");
  EXPECT_NEAR(std::stod(last[4]), 0.0, 1e-12);
  EXPECT_NEAR(std::stod(last[5]), 0.0, 1e-12);
  EXPECT_NEAR(std::stod(last[6]), std::sin(0.5), 1e-8);  // a 1-rad yaw: (0, 0, sin ½, cos ½)
  EXPECT_NEAR(std::stod(last[7]), std::cos(0.5), 1e-8);
  EXPECT_EQ(summary.rows_written, 11u);
  EXPECT_EQ(summary.intervals_held, 0u);
}

TEST(RatesExport, TumHoldsTheOrientationOverAGap) {
  te::TempDir dir("export_tum_gap");
  std::string text = "# schema: inertialnet.rates/2\n# frame: body\ntimestamp_ns,wx,wy,wz,status\n";
  for (int i = 0; i <= 10; ++i) {
    text += std::to_string(100'000'000LL * i) + (i == 4 ? ",,,,unreliable\n" : ",0,0,1,ok\n");
  }
  RatesExportSummary summary;
  const auto lines = lines_of(rates_to_tum(table_from(dir, text), {}, "rates.csv", summary));
  ASSERT_EQ(lines.size(), 12u);  // every row has a pose, the gap's too
  const auto at_gap = fields(lines[5], ' '), before = fields(lines[4], ' ');
  EXPECT_EQ(at_gap[0], "0.400000000");
  EXPECT_EQ(at_gap[6], before[6]);  // held
  EXPECT_NEAR(std::stod(fields(lines[11], ' ')[6]), std::sin(0.45), 1e-8);  // 0.9 rad, not 1
  EXPECT_EQ(summary.intervals_held, 1u);
  bool noted = false;
  for (const auto& n : summary.notes) noted = noted || contains(n, "intervals without a rate, orientation held: 1");
  EXPECT_TRUE(noted);
}

TEST(RatesExport, TumComposesBodyRatesOnTheRight) {
  te::TempDir dir("export_tum_order");
  // A quarter turn about x, then a quarter turn about z (body rates): q = Exp(x π/2) ⊗ Exp(z π/2)
  // = (w, x, y, z) = (½, ½, −½, ½); the other order would give y = +½.
  const double quarter = std::acos(0.0);  // π/2 rad over 1 s
  char text[400];
  std::snprintf(text, sizeof text,
                "# schema: inertialnet.rates/2\n# frame: body\ntimestamp_ns,wx,wy,wz,status\n"
                "0,0,0,0,ok\n1000000000,%.17g,0,0,ok\n2000000000,0,0,%.17g,ok\n",
                quarter, quarter);
  RatesExportSummary summary;
  const auto last = fields(lines_of(rates_to_tum(table_from(dir, text), {}, "rates.csv", summary)).back(), ' ');
  EXPECT_NEAR(std::stod(last[4]), 0.5, 1e-7);
  EXPECT_NEAR(std::stod(last[5]), -0.5, 1e-7);
  EXPECT_NEAR(std::stod(last[6]), 0.5, 1e-7);
  EXPECT_NEAR(std::stod(last[7]), 0.5, 1e-7);
}

TEST(RatesExport, SecondHeadAndTimestampsBeforeTheEpoch) {
  te::TempDir dir("export_head");
  const RatesTable table = table_from(dir,
      "# schema: inertialnet.rates/2\n# frame: camera\n# frame_geometric: body\n"
      "timestamp_ns,wx,wy,wz,status,wx_geometric,wy_geometric,wz_geometric,status_geometric\n"
      "-1500000001,1,2,3,ok,,,,too_few_vectors\n"
      "-499999999,4,5,6,ok,0.5,0.25,0.125,ok\n");
  RatesExportOptions geometric;
  geometric.head_suffix = "_geometric";
  RatesExportSummary summary;
  const auto lines = lines_of(rates_to_euroc_imu(table, geometric, "both.csv", summary));  // frame_geometric: body
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[1], "-499999999,0.5,0.25,0.125,,,");
  EXPECT_EQ(summary.left_out_by_status.at("too_few_vectors"), 1u);
  RatesExportSummary s2;
  const auto gcsv = lines_of(rates_to_gcsv(table, geometric, "both.csv", s2));
  EXPECT_EQ(gcsv.back(), "-500000,0.5,0.25,0.125");
  EXPECT_TRUE(contains(gcsv[4], "wx_geometric"));
  RatesExportSummary s3;
  const auto tum = lines_of(rates_to_tum(table, {}, "both.csv", s3));
  EXPECT_EQ(tum[1].substr(0, 13), "-1.500000001 ");
  EXPECT_EQ(tum[2].substr(0, 13), "-0.499999999 ");
  RatesExportOptions nosuch;
  nosuch.head_suffix = "_network";
  RatesExportSummary s4;
  expect_invalid_input([&] { rates_to_tum(table, nosuch, "both.csv", s4); }, "both.csv: Rates table has no column wx_network");
}

TEST(RatesExport, NoOkRowIsRefusedAndTheOutputLeftAsItWas) {
  te::TempDir dir("export_none");
  const auto rates = dir.path() / "none.csv";
  std::ofstream(rates) << "# schema: inertialnet.rates/2\n# frame: body\ntimestamp_ns,wx,wy,wz,status\n"
                          "1000,,,,no_texture\n2000,,,,no_texture\n3000,,,,decode_error\n";
  const auto out = dir.path() / "out.txt";
  std::ofstream(out) << "before\n";
  for (const auto format : {RatesExportFormat::Gyroflow, RatesExportFormat::EurocImu, RatesExportFormat::Tum}) {
    expect_invalid_input([&] { export_rates(rates, out, format); },
                         rates.string() + ": no pair has an answer (status ok) in its 3 rows (decode_error 1, no_texture 2)");
  }
  std::ifstream in(out);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(content, "before\n");
  // And a good file replaces it whole.
  std::ofstream(rates, std::ios::trunc) << kThreeRows;
  const RatesExportSummary summary = export_rates(rates, out, RatesExportFormat::EurocImu);
  EXPECT_EQ(summary.rows_written, 2u);
  std::ifstream again(out);
  std::string first;
  std::getline(again, first);
  EXPECT_EQ(first.rfind("#timestamp [ns]", 0), 0u);
}
