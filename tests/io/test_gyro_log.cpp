// SPDX-License-Identifier: Apache-2.0
// The gyro logs `--imu` reads (gyro_log.hpp): EuRoC's CSV, a gyro-only CSV in seconds or another
// named unit, Gyroflow's .gcsv with its scales; every bad number named by file, line and value.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/io/gyro_log.hpp"
#include "support/testing.hpp"

namespace fs = std::filesystem;
using namespace inertialnet;
namespace te = inertialnet::testing_euroc;
using inertialnet::testing::contains;
using inertialnet::testing::invalid_input_message;

namespace {

fs::path write(const te::TempDir& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir.path() / name;
  std::ofstream(p) << text;
  return p;
}

bool has_note(const GyroLog& log, const std::string& part) {
  for (const auto& n : log.notes) {
    if (contains(n, part)) return true;
  }
  return false;
}

}  // namespace

TEST(GyroLog, EurocCsvAsBefore) {
  te::TempDir dir("gyro_euroc");
  const auto p = write(dir, "data.csv",
                       "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                       "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n"
                       "1403715273262142976,0.1,-0.2,0.3,9.8,0.1,0.2\n"
                       "1403715273267142976,0.2,-0.3,0.4,9.7,0.1,0.2\n");
  const GyroLog log = read_gyro_log(p);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_EQ(log.samples[1].t_ns, 1403715273267142976);
  EXPECT_DOUBLE_EQ(log.samples[1].gyro[2], 0.4);
  EXPECT_DOUBLE_EQ(log.samples[0].accel[0], 9.8);
  EXPECT_TRUE(log.notes.empty());  // the header names nanoseconds
}

// A gyro-only CSV (the accelerometer is never used) in seconds, told by the header's column
// name: times exact to the nanosecond, however many digits a double would lose.
TEST(GyroLog, GyroOnlyCsvInSecondsByHeader) {
  te::TempDir dir("gyro_seconds");
  const auto p = write(dir, "gyro.csv", "t_s,gx,gy,gz\n1403715273.262142976,0.1,0.2,0.3\n1403715273.267142977,0.1,0.2,0.3\n");
  const GyroLog log = read_gyro_log(p);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_EQ(log.samples[0].t_ns, 1403715273262142976);
  EXPECT_EQ(log.samples[1].t_ns, 1403715273267142977);
  EXPECT_DOUBLE_EQ(log.samples[0].gyro[1], 0.2);
  EXPECT_EQ(log.samples[0].accel[0], 0.0);

  const auto ms = write(dir, "ms.csv", "time (ms),gx,gy,gz\n5.5,0,0,0\n10.25,0,0,0\n");
  EXPECT_EQ(read_gyro_log(ms).samples[1].t_ns, 10'250'000);
  const auto us = write(dir, "us.csv", "timestamp_us,gx,gy,gz\n5,0,0,0\n10,0,0,0\n");
  EXPECT_EQ(read_gyro_log(us).samples[1].t_ns, 10'000);
  // Gyro columns named in degrees per second are converted, with a note.
  const auto deg = write(dir, "deg.csv", "t [s],gx_deg_s,gy_deg_s,gz_deg_s\n0,180,0,0\n0.005,0,90,0\n");
  const GyroLog d = read_gyro_log(deg);
  EXPECT_NEAR(d.samples[0].gyro[0], M_PI, 1e-12);
  EXPECT_NEAR(d.samples[1].gyro[1], M_PI / 2, 1e-12);
  EXPECT_TRUE(has_note(d, "converted to rad/s"));
}

// The unit given as an option; a header that names another is refused; a file that names none
// is read in nanoseconds with a note, and a time with decimals is then refused, not guessed.
TEST(GyroLog, TimeUnitOptionAndUnnamedUnits) {
  te::TempDir dir("gyro_unit");
  const auto bare = write(dir, "bare.csv", "0.000,0.1,0.2,0.3\n0.005,0.1,0.2,0.3\n");
  const GyroLog s = read_gyro_log(bare, TimeUnit::s);
  EXPECT_EQ(s.samples[1].t_ns, 5'000'000);
  EXPECT_TRUE(s.notes.empty());
  const std::string guessed = invalid_input_message([&] { read_gyro_log(bare); });
  EXPECT_TRUE(contains(guessed, "bare.csv line 1: the timestamp [ns] is \"0.000\", a time with decimals in a file "
                                "that does not name its unit: give --imu-time-unit"))
      << guessed;

  const auto named = write(dir, "named.csv", "t,gx,gy,gz\n1000,0,0,0\n2000,0,0,0\n");
  const GyroLog ns = read_gyro_log(named);
  EXPECT_EQ(ns.samples[1].t_ns, 2000);
  EXPECT_TRUE(has_note(ns, "names no unit: its times are read as nanoseconds"));
  EXPECT_EQ(read_gyro_log(named, TimeUnit::us).samples[1].t_ns, 2'000'000);

  const auto t_s = write(dir, "ts.csv", "t_s,gx,gy,gz\n0,0,0,0\n1,0,0,0\n");
  const std::string clash = invalid_input_message([&] { read_gyro_log(t_s, TimeUnit::ns); });
  EXPECT_TRUE(contains(clash, "ts.csv line 1: the time column \"t_s\" is in s, but --imu-time-unit says ns")) << clash;
  EXPECT_EQ(parse_time_unit("ms"), TimeUnit::ms);
  EXPECT_FALSE(parse_time_unit("sec"));
}

TEST(GyroLog, BadNumbersNameFileLineAndValue) {
  te::TempDir dir("gyro_bad");
  const auto nan = write(dir, "nan.csv", "t_s,gx,gy,gz\n0,0,0,0\n0.005,0,nan,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(nan); }), "nan.csv line 3: gy is \"nan\""));
  const auto huge = write(dir, "huge.csv", "t_s,gx,gy,gz\n0,0,0,1e308\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(huge); }), "huge.csv line 2: gz is \"1e308\", beyond ±1000 rad/s"));
  const auto time = write(dir, "time.csv", "t_s,gx,gy,gz\n0,0,0,0\n1e12,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(time); }), "time.csv line 3: t_s is \"1e12\", beyond the int64"));
  const auto digits = write(dir, "digits.csv", "t_s,gx,gy,gz\n99999999999,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(digits); }), "digits.csv line 2: t_s is \"99999999999\", beyond"));
  const auto text = write(dir, "text.csv", "t_s,gx,gy,gz\n0,0,0,0\n0.0x5,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(text); }), "text.csv line 3: t_s is \"0.0x5\", expected a number"));
  const auto fields = write(dir, "fields.csv", "t_s,gx,gy,gz\n0,0,0,0\n0.005,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(fields); }),
                       "fields.csv line 3: expected 4 comma-separated fields (as the header on line 1 names), found 3"));
  // Five columns whose names say nothing of time or gyro: neither by name nor EuRoC's order.
  const auto five = write(dir, "five.csv", "a,b,c,d,e\n0,0,0,0,20\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(five); }),
                       "five.csv line 1: the header names 5 columns (a, b, c, d, e), and no time, gx, gy, gz among them"));
  const auto back = write(dir, "back.csv", "t_s,gx,gy,gz\n0.010,0,0,0\n0.005,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(back); }), "goes back in time"));
  const auto empty = write(dir, "empty.csv", "t_s,gx,gy,gz\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(empty); }), "has no data rows"));
}

// Gyroflow's .gcsv (docs.gyroflow.xyz, "GCSV format"): seconds = t · tscale, rad/s = raw · gscale;
// the accelerometer columns are not used; an orientation other than XYZ is not applied (a note).
TEST(GyroLog, GyroflowGcsvWithItsScales) {
  te::TempDir dir("gyro_gcsv");
  const std::string head =
      "GYROFLOW IMU LOG\nversion,1.3\nid,custom_logger_name\norientation,YxZ\nnote,development_test\n"
      "vendor,potatocam\nvideofilename,videofilename.mp4\nframe_readout_time,15.23\n";
  const auto p = write(dir, "clip.gcsv",
                       head + "tscale,0.001\ngscale,0.00122173047\nascale,0.00048828125\nt,gx,gy,gz,ax,ay,az\n"
                              "0,39,86,183,-1137,-15689,-2986\n1,56,100,202,-1179,-15694,-2887\n");
  const GyroLog log = read_gyro_log(p);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_EQ(log.samples[0].t_ns, 0);
  EXPECT_EQ(log.samples[1].t_ns, 1'000'000);
  EXPECT_NEAR(log.samples[1].gyro[0], 56 * 0.00122173047, 1e-15);
  EXPECT_NEAR(log.samples[1].gyro[2], 202 * 0.00122173047, 1e-15);
  EXPECT_TRUE(has_note(log, "orientation YxZ (Gyroflow's IMU orientation) is not applied"));

  const auto gyro_only = write(dir, "cam.gcsv", "CAMERA IMU LOG\nversion,1.3\nid,x\norientation,XYZ\ntscale,0.000001\n"
                                                "gscale,1\nt,gx,gy,gz\n1000000,0.5,0,0\n1005000,0.5,0,0\n");
  const GyroLog g = read_gyro_log(gyro_only);
  EXPECT_EQ(g.samples[1].t_ns, 1'005'000'000);
  EXPECT_DOUBLE_EQ(g.samples[1].gyro[0], 0.5);
  EXPECT_TRUE(g.notes.empty());
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(gyro_only, TimeUnit::s); }), "its tscale line gives the time unit"));

  const auto no_tscale = write(dir, "a.gcsv", head + "gscale,1\nt,gx,gy,gz\n0,1,2,3\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(no_tscale); }), "a.gcsv (a Gyroflow .gcsv) has no tscale line"));
  const auto zero = write(dir, "b.gcsv", head + "tscale,0\ngscale,1\nt,gx,gy,gz\n0,1,2,3\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(zero); }), "b.gcsv line 9: tscale is \"0\", expected a positive number"));
  const auto nan = write(dir, "c.gcsv", head + "tscale,0.001\ngscale,nan\nt,gx,gy,gz\n0,1,2,3\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(nan); }), "c.gcsv line 10: gscale is \"nan\""));
  const auto raw = write(dir, "d.gcsv", head + "tscale,0.001\ngscale,0.001\nt,gx,gy,gz\n0,1,2,3\n1,1,2e9,3\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(raw); }), "d.gcsv line 13: gy is \"2e9\" (times gscale), beyond ±1000 rad/s"));
  const auto columns = write(dir, "e.gcsv", head + "tscale,0.001\ngscale,1\nt,ax,ay,az\n0,1,2,3\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(columns); }), "e.gcsv line 11: the columns should begin t,gx,gy,gz"));
  const auto no_columns = write(dir, "f.gcsv", head + "tscale,0.001\ngscale,1\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(no_columns); }), "without its column line"));
  const auto not_gcsv = write(dir, "g.gcsv", "t,gx,gy,gz\n0,1,2,3\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(not_gcsv); }), "g.gcsv line 1: a Gyroflow .gcsv starts with GYROFLOW IMU LOG"));
  const auto short_row = write(dir, "h.gcsv", head + "tscale,0.001\ngscale,1\nt,gx,gy,gz\n0,1,2\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(short_row); }), "h.gcsv line 12: expected 4 comma-separated fields"));
}

// Other layouts by name: extra columns, another order, the unit in the name; the same samples.
TEST(GyroLog, ColumnsFoundByName) {
  te::TempDir dir("gyro_named");
  const auto p = write(dir, "reordered.csv", "temp,gz,t_s,gx,accel,gy\n20,0.3,1.5,0.1,9.8,0.2\n21,0.6,1.505,0.4,9.8,0.5\n");
  const GyroLog log = read_gyro_log(p);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_EQ(log.samples[1].t_ns, 1'505'000'000);
  EXPECT_DOUBLE_EQ(log.samples[0].gyro[0], 0.1);
  EXPECT_DOUBLE_EQ(log.samples[0].gyro[1], 0.2);
  EXPECT_DOUBLE_EQ(log.samples[1].gyro[2], 0.6);
  EXPECT_TRUE(has_note(log, "time from column \"t_s\", gyro x, y, z from \"gx\", \"gy\", \"gz\" (found by name"));

  // Sensor Logger's Gyroscope.csv: nanoseconds named `time`, then seconds_elapsed, axes z, y, x.
  const auto phone = write(dir, "Gyroscope.csv", "time,seconds_elapsed,z,y,x\n1700000000000000000,0,0.3,0.2,0.1\n"
                                                 "1700000000010000000,0.01,0.3,0.2,0.1\n");
  const GyroLog s = read_gyro_log(phone);
  EXPECT_EQ(s.samples[1].t_ns, 1700000000010000000);
  EXPECT_DOUBLE_EQ(s.samples[1].gyro[0], 0.1);
  EXPECT_DOUBLE_EQ(s.samples[1].gyro[2], 0.3);

  // phyphox: quoted names with units in parentheses.
  const auto phyphox = write(dir, "phyphox.csv", "\"Time (s)\",\"Gyroscope x (rad/s)\",\"Gyroscope y (rad/s)\","
                                                 "\"Gyroscope z (rad/s)\"\n0.5,0.1,0.2,0.3\n0.51,0.1,0.2,0.3\n");
  EXPECT_EQ(read_gyro_log(phyphox).samples[1].t_ns, 510'000'000);

  // Betaflight: blackbox_decode's `time (us)` and Blackbox Explorer's plain `time` are µs; gyroADC deg/s.
  const auto decode = write(dir, "bf.csv", "loopIteration, time (us), axisP[0], gyroADC[0], gyroADC[1], gyroADC[2]\n"
                                           "0, 1000, 5, 180, -90, 0\n1, 1125, 5, 180, -90, 0\n");
  const GyroLog b = read_gyro_log(decode);
  EXPECT_EQ(b.samples[1].t_ns, 1'125'000);
  EXPECT_NEAR(b.samples[0].gyro[0], 3.14159265358979, 1e-12);
  EXPECT_NEAR(b.samples[0].gyro[1], -1.5707963267949, 1e-12);
  EXPECT_TRUE(has_note(b, "Betaflight's gyroADC, in degrees per second"));
  const auto explorer = write(dir, "explorer.csv", "\"loopIteration\",\"time\",\"gyroADC[0]\",\"gyroADC[1]\",\"gyroADC[2]\"\n"
                                                   "0,1000,1,2,3\n1,1125,1,2,3\n");
  const GyroLog e = read_gyro_log(explorer);
  EXPECT_EQ(e.samples[1].t_ns, 1'125'000);
  EXPECT_TRUE(has_note(e, "is read as microseconds, as Betaflight logs it"));

  // Two columns that could be one axis: refused, naming both.
  const auto twice = write(dir, "twice.csv", "t,gx,gyro_x,gy,gz\n0,0,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(twice); }),
                       "twice.csv line 1: two columns could be the gyro's x axis, \"gx\" and \"gyro_x\": choose with --imu-columns"));
}

// --imu-columns and --imu-units: any columns, by name or 0-based index, in seconds and deg/s.
TEST(GyroLog, ColumnsAndUnitsGiven) {
  te::TempDir dir("gyro_given");
  GyroLogOptions o;
  o.columns = {"stamp", "wx", "wy", "wz"};
  o.time_unit = TimeUnit::s;
  o.gyro_unit = GyroUnit::deg_s;
  o.time_unit_option = "--imu-units";
  const auto named = write(dir, "named.csv", "wz,stamp,wy,junk,wx\n90,2.25,-45,x,180\n90,2.255,-45,y,180\n");
  const GyroLog log = read_gyro_log(named, o);
  ASSERT_EQ(log.samples.size(), 2u);
  EXPECT_EQ(log.samples[1].t_ns, 2'255'000'000);
  EXPECT_NEAR(log.samples[0].gyro[0], 3.14159265358979, 1e-12);
  EXPECT_NEAR(log.samples[0].gyro[1], -0.785398163397448, 1e-12);
  EXPECT_NEAR(log.samples[0].gyro[2], 1.5707963267949, 1e-12);

  GyroLogOptions by_index = o;
  by_index.columns = {"1", "4", " 2", "0"};
  const auto bare = write(dir, "bare.csv", "90,2.25,-45,7,180\n90,2.255,-45,7,180\n");
  const GyroLog b = read_gyro_log(bare, by_index);
  EXPECT_EQ(b.samples[0].t_ns, 2'250'000'000);
  EXPECT_NEAR(b.samples[0].gyro[2], 1.5707963267949, 1e-12);

  GyroLogOptions missing = o;
  missing.columns = {"stamp", "wx", "wy", "omega"};
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(named, missing); }),
                       "--imu-columns: " + named.string() + " line 1: no column named \"omega\" among: wz, stamp, wy, junk, wx"));
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(bare, o); }),
                       "--imu-columns names the column \"stamp\", but " + bare.string() + " has no header line"));
  GyroLogOptions beyond = by_index;
  beyond.columns = {"1", "4", "2", "9"};
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(bare, beyond); }),
                       "bare.csv line 1: --imu-columns reads column 9 (0-based), but the row has 5 fields"));
  GyroLogOptions three = o;
  three.columns = {"stamp", "wx", "wy"};
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(named, three); }), "--imu-columns takes four columns"));
  // A value that is not a number: file, line, column and value.
  const auto bad = write(dir, "bad.csv", "wz,stamp,wy,junk,wx\n90,2.25,-45,x,180\n90,2.255,1e,y,180\n");
  const std::string not_number = invalid_input_message([&] { read_gyro_log(bad, o); });
  EXPECT_TRUE(contains(not_number, "bad.csv line 3: wy should be a number, found \"1e\"")) << not_number;
  // Units that contradict the names.
  const auto deg = write(dir, "deg.csv", "t_ms,gx_deg,gy_deg,gz_deg\n1,0,0,0\n");
  GyroLogOptions rad;
  rad.gyro_unit = GyroUnit::rad_s;
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(deg, rad); }),
                       "deg.csv line 1: the gyro column \"gx_deg\" is in deg/s, but --imu-units says rad/s"));
  GyroLogOptions seconds = o;
  seconds.columns.clear();
  seconds.gyro_unit.reset();
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(deg, seconds); }),
                       "deg.csv line 1: the time column \"t_ms\" is in ms, but --imu-units says s"));
  // A .gcsv states its own layout.
  const auto gcsv = write(dir, "g.gcsv", "GYROFLOW IMU LOG\ntscale,1\ngscale,1\nt,gx,gy,gz\n0,0,0,0\n");
  EXPECT_TRUE(contains(invalid_input_message([&] { read_gyro_log(gcsv, o); }), "do not apply to"));
}
