// SPDX-License-Identifier: Apache-2.0
// The rates CSV (schema inertialnet.rates/4 (3 before σ): timestamp_ns,wx,wy,wz,status[,…] and its sidecar):
// round trip, statuses, schema-1 and -2 files, the sidecar, the journal a run writes, and errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <functional>

#include "eval/synthetic_euroc.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "support/testing.hpp"

using namespace inertialnet;
namespace te = inertialnet::testing_euroc;

namespace {

using inertialnet::testing::contains;
using inertialnet::testing::invalid_input_message;

std::filesystem::path write_text(const te::TempDir& dir, const std::string& text) {
  const auto p = dir.path() / "rates.csv";
  std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
  return p;
}

}  // namespace

TEST(RatesCsv, RoundTripIsExactForFloats) {
  te::TempDir dir("rates_rt");
  RatesTable t;
  t.extra_names = {"wx_geometric", "wy_geometric", "wz_geometric"};
  t.extra.resize(3);
  for (int i = 0; i < 50; ++i) {
    t.t_ns.push_back(te::kStartNs + 50'000'000LL * (i + 1));
    // Float values (what the network produces) with awkward mantissas and exponents.
    const float a = 0.1f * static_cast<float>(i) - 1.234567f, b = 1e-7f * static_cast<float>(i * i + 1);
    const float c = -3.0e3f / static_cast<float>(i + 3);
    t.w.push_back({a, b, c});
    t.extra[0].push_back(static_cast<float>(a * 0.5f));
    t.extra[1].push_back(static_cast<float>(b + 1));
    t.extra[2].push_back(static_cast<float>(-c));
  }
  const auto path = dir.path() / "rates.csv";
  write_rates_csv(path, t);
  const RatesTable r = read_rates_csv(path);
  ASSERT_EQ(r.size(), t.size());
  ASSERT_EQ(r.extra_names, t.extra_names);
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(r.t_ns[i], t.t_ns[i]);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(static_cast<float>(r.w[i][k]), static_cast<float>(t.w[i][k]));  // %.9g round-trips float
      EXPECT_EQ(static_cast<float>(r.extra[k][i]), static_cast<float>(t.extra[k][i]));
    }
  }
  const auto geo = r.rates("_geometric");
  EXPECT_EQ(static_cast<float>(geo[3][2]), static_cast<float>(t.extra[2][3]));
  EXPECT_EQ(r.column("wy")[4], r.w[4][1]);
  EXPECT_TRUE(contains(invalid_input_message([&] { r.rates("_other"); }), "no column wx_other"));

  std::ifstream in(path);
  std::string header;
  std::getline(in, header);  // the first line is the header (schema 3: metadata in the sidecar)
  EXPECT_EQ(header, "timestamp_ns,wx,wy,wz,status,wx_geometric,wy_geometric,wz_geometric");
}

TEST(RatesCsv, TolerantReading) {
  te::TempDir dir("rates_tol");
  // Comments, spaces after commas, CRLF, columns in another order, a '#' header, blank lines.
  const auto p = write_text(dir,
      "# produced by a test\r\n#timestamp_ns, wz, wy, wx, conf\r\n"
      "100, 3, 2, 1, 0.5\r\n\r\n200,6,5,4,0.25\r\n");
  const RatesTable r = read_rates_csv(p);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r.w[1][0], 4.0);
  EXPECT_EQ(r.w[1][2], 6.0);
  EXPECT_EQ(r.extra_names, std::vector<std::string>{"conf"});
  EXPECT_EQ(r.extra[0][0], 0.5);
}

TEST(RatesCsv, ReadingErrors) {
  te::TempDir dir("rates_err");
  auto msg = [&](const std::string& text) { return invalid_input_message([&] { read_rates_csv(write_text(dir, text)); }); };
  EXPECT_TRUE(contains(msg(""), "empty"));
  EXPECT_TRUE(contains(msg("time,wx,wy,wz\n1,0,0,0\n"), "expected the header"));
  EXPECT_TRUE(contains(msg("timestamp_ns,wx,wy\n1,0,0\n"), "no column wz"));
  EXPECT_TRUE(contains(msg("timestamp_ns,wx,wy,wz,wx\n1,0,0,0,0\n"), "appears twice"));
  EXPECT_TRUE(contains(msg("timestamp_ns,wx,wy,wz\n"), "no rows"));
  std::string m = msg("timestamp_ns,wx,wy,wz\n1,0,0,0\n2,0,0\n");
  EXPECT_TRUE(contains(m, "line 3")) << m;
  EXPECT_TRUE(contains(m, "expected 4 fields")) << m;
  m = msg("timestamp_ns,wx,wy,wz\n1,0,0,0\n2,0,abc,0\n");
  EXPECT_TRUE(contains(m, "line 3: wy should be a number, found \"abc\"")) << m;
  m = msg("timestamp_ns,wx,wy,wz\n1,0,0,nan\n");
  EXPECT_TRUE(contains(m, "finite")) << m;
  m = msg("timestamp_ns,wx,wy,wz\n1.5,0,0,0\n");
  EXPECT_TRUE(contains(m, "timestamp_ns should be an integer")) << m;
  m = msg("timestamp_ns,wx,wy,wz\n5,0,0,0\n4,0,0,0\n");
  EXPECT_TRUE(contains(m, "line 3")) << m;
  EXPECT_TRUE(contains(m, "line 2")) << m;
  m = msg("timestamp_ns,wx,wy,wz\n5,0,0,0\n5,0,0,0\n");
  EXPECT_TRUE(contains(m, "repeats")) << m;
  EXPECT_TRUE(contains(invalid_input_message([&] { read_rates_csv(dir.path() / "absent.csv"); }), "does not exist"));
}

// Timestamps near the int64 limits: their interval overflows a signed subtraction (undefined
// behaviour, then nonsense gaps); the reader refuses a span that does not fit, naming both lines.
TEST(RatesCsv, TimestampSpanThatOverflowsIsRefused) {
  te::TempDir dir("rates_overflow");
  const std::string m = invalid_input_message([&] {
    read_rates_csv(write_text(dir, "timestamp_ns,wx,wy,wz\n-9223372036854775807,0,0,0\n0,0,0,0\n"
                                   "9223372036854775807,0,0,0\n"));
  });
  EXPECT_TRUE(contains(m, "-9223372036854775807 (line 2)")) << m;
  EXPECT_TRUE(contains(m, "9223372036854775807 (line 4)")) << m;
  EXPECT_TRUE(contains(m, "64-bit")) << m;
  // The largest span that fits is accepted.
  EXPECT_EQ(read_rates_csv(write_text(dir, "timestamp_ns,wx,wy,wz\n0,0,0,0\n9223372036854775807,0,0,0\n")).size(), 2u);
}

TEST(RatesCsv, WriterRefusesBadTables) {
  te::TempDir dir("rates_w");
  const auto p = dir.path() / "out.csv";
  RatesTable t;
  t.t_ns = {1, 2};
  t.w = {{0, 0, 0}, {0, std::nan(""), 0}};
  EXPECT_TRUE(contains(invalid_input_message([&] { write_rates_csv(p, t); }), "not finite"));
  t.w[1][1] = 0;
  t.t_ns[1] = 1;
  EXPECT_TRUE(contains(invalid_input_message([&] { write_rates_csv(p, t); }), "does not follow"));
  t.t_ns[1] = 2;
  t.extra_names = {"a,b"};
  t.extra = {{0, 0}};
  EXPECT_TRUE(contains(invalid_input_message([&] { write_rates_csv(p, t); }), "commas"));
  t.extra_names = {"wx"};
  EXPECT_TRUE(contains(invalid_input_message([&] { write_rates_csv(p, t); }), "appears twice"));
  t.extra_names = {"conf"};
  t.extra = {{0}};
  EXPECT_TRUE(contains(invalid_input_message([&] { write_rates_csv(p, t); }), "1 values for 2 rows"));
  EXPECT_TRUE(contains(invalid_input_message([&] { write_rates_csv(dir.path() / "no" / "dir.csv", RatesTable{}); }),
                       "Cannot open"));
}

// "# key: value" lines before the header state what the columns are; other comments stay comments,
// and files without them (written before they existed) read as before.
TEST(RatesCsv, MetadataRoundTripAndOldFiles) {
  te::TempDir dir("rates_meta");
  RatesTable t;
  t.t_ns = {10, 20};
  t.w = {{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}};
  t.metadata = {{"frame", "body"}, {"estimator", "inter_frame"}, {"time_offset_s", "0.04"}};
  const auto path = dir.path() / "meta.csv";
  write_rates_csv(path, t);
  const RatesTable back = read_rates_csv(path);
  auto expected = t.metadata;
  expected.insert(expected.begin(), {"schema", "inertialnet.rates/4"});
  EXPECT_EQ(back.metadata, expected);
  EXPECT_EQ(back.meta("frame").value_or(""), "body");
  EXPECT_FALSE(back.meta("readout_time_s").has_value());
  EXPECT_NEAR(back.meta_number("time_offset_s").value_or(0), 0.04, 1e-15);
  EXPECT_EQ(rates_csv_header(rates_layout({"", "_g"})),
            "timestamp_ns,wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz,wx_g,wy_g,wz_g,status_g,sigma_wx_g,sigma_wy_g,"
            "sigma_wz_g\n");
  EXPECT_THROW(rates_sidecar_text({{"two words", "x"}}), Error);
  // Schema 2 (today's files before the sidecar): the metadata in comment lines, read as before.
  const auto two = write_text(dir, "# schema: inertialnet.rates/2\n# frame: camera\ntimestamp_ns,wx,wy,wz,status\n5,1,2,3,ok\n");
  EXPECT_EQ(read_rates_csv(two).metadata,
            (std::vector<std::pair<std::string, std::string>>{{"schema", "inertialnet.rates/2"}, {"frame", "camera"}}));

  const auto old = write_text(dir, "# written by an older predict\ntimestamp_ns,wx,wy,wz\n5,1,2,3\n");
  const RatesTable o = read_rates_csv(old);
  EXPECT_TRUE(o.metadata.empty());
  EXPECT_EQ(o.size(), 1u);
  const auto bad = write_text(dir, "# time_offset_s: soon\ntimestamp_ns,wx,wy,wz\n5,1,2,3\n");
  EXPECT_THROW(read_rates_csv(bad).meta_number("time_offset_s"), Error);
}

// Every pair has a row: a pair without an answer has empty rates and a status saying why, for
// each estimator on its own (issue: one bad pair ended the whole run).
TEST(RatesCsv, StatusesRoundTripWithEmptyRates) {
  te::TempDir dir("rates_status");
  const auto path = dir.path() / "status.csv";
  {
    RatesCsvWriter writer(path, rates_layout({"", "_geometric"}), {{"frame", "body"}});
    const double nan = std::nan("");
    // Extras in layout order: the first group's σ, then the second group's rates and σ.
    writer.write({100, {0.1, 0.2, 0.3}, "ok", {nan, nan, nan, 1, 2, 3, 0.01, 0.02, 0.03}, {"ok"}});
    writer.write({200, {nan, nan, nan}, "no_texture", {nan, nan, nan, nan, nan, nan, nan, nan, nan}, {"no_texture"}});
    writer.write({300, {0.4, 0.5, 0.6}, "ok", {nan, nan, nan, nan, 5, nan, nan, nan, nan}, {"too_few_vectors"}});
    // Schema 4: an uncertain pair keeps its σ (why it is uncertain) and loses its rates.
    writer.write({400, {0.4, 0.5, 0.6}, "ok", {nan, nan, nan, 7, 8, 9, 0.2, 0.3, 0.4}, {"uncertain"}});
    writer.close();
  }
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(contains(text, "timestamp_ns,wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz,wx_geometric,wy_geometric,"
                             "wz_geometric,status_geometric,sigma_wx_geometric,sigma_wy_geometric,sigma_wz_geometric\n"))
      << text;
  EXPECT_TRUE(contains(text, "\n100,0.1,0.2,0.3,ok,,,,1,2,3,ok,0.01,0.02,0.03\n")) << text;
  EXPECT_TRUE(contains(text, "\n200,,,,no_texture,,,,,,,no_texture,,,\n")) << text;
  EXPECT_TRUE(contains(text, "\n300,0.4,0.5,0.6,ok,,,,,,,too_few_vectors,,,\n")) << text;  // a rate without an answer is not written
  EXPECT_TRUE(contains(text, "\n400,0.4,0.5,0.6,ok,,,,,,,uncertain,0.2,0.3,0.4\n")) << text;
  const RatesTable r = read_rates_csv(path);
  ASSERT_EQ(r.size(), 4u);
  EXPECT_EQ(r.status(), (std::vector<std::string>{"ok", "no_texture", "ok", "ok"}));
  EXPECT_EQ(r.status("_geometric"), (std::vector<std::string>{"ok", "no_texture", "too_few_vectors", "uncertain"}));
  EXPECT_EQ(r.column("sigma_wy_geometric")[0], 0.02);
  EXPECT_EQ(r.column("sigma_wz_geometric")[3], 0.4);
  EXPECT_TRUE(std::isnan(r.column("sigma_wx")[0]));  // σ not known: an empty cell, whatever the status
  EXPECT_TRUE(std::isnan(r.column("wx_geometric")[3]));
  EXPECT_TRUE(std::isnan(r.w[1][0]));
  EXPECT_TRUE(std::isnan(r.rates("_geometric")[2][1]));
  const RatesTable ok = r.ok_rows("_geometric");
  ASSERT_EQ(ok.size(), 1u);
  EXPECT_EQ(ok.t_ns[0], 100);
  EXPECT_EQ(r.ok_rows().t_ns, (std::vector<std::int64_t>{100, 300, 400}));
  // A schema-1 file (no status column) reads as all ok.
  const RatesTable old = read_rates_csv(write_text(dir, "timestamp_ns,wx,wy,wz\n5,1,2,3\n"));
  EXPECT_EQ(old.status(), std::vector<std::string>{"ok"});
}

TEST(RatesCsv, StatusErrorsNameTheLine) {
  te::TempDir dir("rates_status_err");
  auto msg = [&](const std::string& text) { return invalid_input_message([&] { read_rates_csv(write_text(dir, text)); }); };
  std::string m = msg("timestamp_ns,wx,wy,wz,status\n1,0,0,0,ok\n2,,,,ok\n");
  EXPECT_TRUE(contains(m, "line 3: wx is empty but status is ok")) << m;
  m = msg("timestamp_ns,wx,wy,wz,status\n1,0,0,0,OK!\n");
  EXPECT_TRUE(contains(m, "line 2: status is \"OK!\"")) << m;
  m = msg("timestamp_ns,wx,wy,wz,status\n1,0,0,0,\n");
  EXPECT_TRUE(contains(m, "line 2: status is \"\"")) << m;
  m = msg("timestamp_ns,wx,wy,wz\n1,,0,0\n");  // schema 1: no status to explain an empty rate
  EXPECT_TRUE(contains(m, "line 2")) << m;
  m = msg("# schema: inertialnet.rates/5\ntimestamp_ns,wx,wy,wz,status\n1,0,0,0,ok\n");
  EXPECT_TRUE(contains(m, "newer than this version reads")) << m;
  m = msg("# schema: something/else\ntimestamp_ns,wx,wy,wz,status\n1,0,0,0,ok\n");
  EXPECT_TRUE(contains(m, "expected inertialnet.rates/4")) << m;
}

// Schema 4's σ columns: a standard deviation is never negative and is bounded as the rates are
// (both were read as given, to be squared into weights).
TEST(RatesCsv, SigmaColumnsAreStandardDeviations) {
  te::TempDir dir("rates_sigma_err");
  auto msg = [&](const std::string& text) { return invalid_input_message([&] { read_rates_csv(write_text(dir, text)); }); };
  const std::string header = "timestamp_ns,wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz\n";
  std::string m = msg(header + "1,0,0,0,ok,0.1,-0.2,0.1\n");
  EXPECT_TRUE(contains(m, "line 2: sigma_wy is \"-0.2\"; a standard deviation cannot be negative")) << m;
  m = msg(header + "1,0,0,0,ok,0.1,0.1,1e300\n");
  EXPECT_TRUE(contains(m, "line 2: sigma_wz is \"1e300\", beyond ±1000 rad/s")) << m;
  m = msg(header + "1,0,0,0,ok,nan,0.1,0.1\n");
  EXPECT_TRUE(contains(m, "line 2: sigma_wx is \"nan\", expected a finite number")) << m;
  // An empty σ (not known) and a σ of 0 are values.
  const RatesTable r = read_rates_csv(write_text(dir, header + "1,0,0,0,ok,,0,0.5\n"));
  EXPECT_TRUE(std::isnan(r.column("sigma_wx")[0]));
  EXPECT_EQ(r.column("sigma_wy")[0], 0.0);
}

// A run's rows go to <name>.partial, one write each, and replace <name> only when the run
// completes: a run that fails (or is killed) leaves a complete earlier file untouched and its
// own rows readable in the journal (issue: a failed rerun replaced a good CSV).
TEST(RatesCsv, WriterJournalLeavesGoodOutputUntilClosed) {
  te::TempDir dir("rates_journal");
  const auto path = dir.path() / "rates.csv";
  std::ofstream(path) << "# schema: inertialnet.rates/2\ntimestamp_ns,wx,wy,wz,status\n1,0.5,0.5,0.5,ok\n";
  {
    RatesCsvWriter writer(path);
    EXPECT_EQ(writer.journal(), partial_rates_path(path));
    writer.write({10, {0.1, 0.2, 0.3}, "ok", {}, {}});
    writer.write({20, {0.1, 0.2, 0.3}, "ok", {}, {}});
    // Every row is on the disk as it is written: what a SIGKILL would leave.
    EXPECT_EQ(read_rates_csv(writer.journal()).size(), 2u);
    // Destroyed without close(): an error or an interruption.
  }
  EXPECT_EQ(read_rates_csv(path).t_ns, std::vector<std::int64_t>{1});  // the earlier run's output, intact
  EXPECT_EQ(read_rates_csv(partial_rates_path(path)).size(), 2u);
  {
    RatesCsvWriter writer(path);  // a rerun replaces the stale journal
    writer.write({30, {0.1, 0.2, 0.3}, "ok", {}, {}});
    writer.close();
  }
  EXPECT_EQ(read_rates_csv(path).t_ns, std::vector<std::int64_t>{30});
  EXPECT_FALSE(std::filesystem::exists(partial_rates_path(path)));
  // Nothing else is left beside it but its sidecar.
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) files += entry.is_regular_file();
  EXPECT_EQ(files, 2u);
  EXPECT_TRUE(std::filesystem::exists(rates_sidecar_path(path)));
}

namespace {
std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
}  // namespace

// Schema 3: the CSV's first line is its header (pandas' and numpy's defaults read it), the
// metadata are in the sidecar <file>.json, which states the CSV's row count and hash (issue 21:
// the "# key: value" lines stood before the header).
TEST(RatesCsv, SidecarHoldsTheMetadata) {
  te::TempDir dir("rates_sidecar");
  const auto path = dir.path() / "rates.csv";
  {
    RatesCsvWriter writer(path, {}, {{"frame", "body"}, {"time_offset_s", "0.04"}});
    EXPECT_TRUE(writer.has_sidecar());
    writer.write({10, {0.1, 0.2, 0.3}, "ok", {}, {}});
    // The journal has its own sidecar from its first row on: eval reads a stopped run's rows
    // with their frame.
    const RatesTable journal = read_rates_csv(writer.journal());
    EXPECT_EQ(journal.meta("frame").value_or(""), "body");
    EXPECT_TRUE(journal.notes.empty());
    writer.write({20, {0.4, 0.5, 0.6}, "ok", {}, {}});
    writer.close();
  }
  const std::string csv = file_text(path);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "timestamp_ns,wx,wy,wz,status");
  const std::string sidecar = file_text(rates_sidecar_path(path));
  EXPECT_TRUE(contains(sidecar, "\"schema\": \"inertialnet.rates/4\"")) << sidecar;
  EXPECT_TRUE(contains(sidecar, "\"rows\": 2")) << sidecar;
  EXPECT_TRUE(contains(sidecar, "\"time_offset_s\": \"0.04\"")) << sidecar;
  EXPECT_FALSE(std::filesystem::exists(rates_sidecar_path(partial_rates_path(path))));
  const RatesTable r = read_rates_csv(path);
  EXPECT_EQ(r.metadata, (std::vector<std::pair<std::string, std::string>>{
                            {"schema", "inertialnet.rates/4"}, {"frame", "body"}, {"time_offset_s", "0.04"}}));
  EXPECT_TRUE(r.notes.empty());

  // A run killed between the sidecar's rename and the CSV's: the new sidecar beside the old CSV
  // is refused by its row count and hash, naming both files.
  const std::string good_sidecar = sidecar;
  std::ofstream(rates_sidecar_path(path)) << rates_sidecar_text({{"frame", "camera"}}, 2, 12345);
  std::string m = invalid_input_message([&] { read_rates_csv(path); });
  EXPECT_TRUE(contains(m, "rates.csv.json (the sidecar of")) << m;
  EXPECT_TRUE(contains(m, "describes another CSV")) << m;
  // An edit of the CSV (same rows, other bytes) is caught by the hash.
  std::ofstream(rates_sidecar_path(path)) << good_sidecar;
  std::ofstream(path) << "timestamp_ns,wx,wy,wz,status\n10,0.1,0.2,0.3,ok\n20,0.4,0.5,0.7,ok\n";
  m = invalid_input_message([&] { read_rates_csv(path); });
  EXPECT_TRUE(contains(m, "describes another CSV (2 rows")) << m;
  // Newer sidecars, other documents and broken JSON: refused with the sidecar's name.
  std::ofstream(rates_sidecar_path(path)) << "{\"schema\": \"inertialnet.rates/5\"}";
  EXPECT_TRUE(contains(invalid_input_message([&] { read_rates_csv(path); }), "newer than this version reads"));
  std::ofstream(rates_sidecar_path(path)) << "{\"schema\": \"inertialnet.rates/3\", \"metadata\": {\"frame\": [1]}}";
  EXPECT_TRUE(contains(invalid_input_message([&] { read_rates_csv(path); }), "neither a string nor a number"));
  std::ofstream(rates_sidecar_path(path)) << "{\"schema\": ";
  EXPECT_TRUE(contains(invalid_input_message([&] { read_rates_csv(path); }), "is not valid JSON"));
  // A number beyond a double is the JSON library's out_of_range, not its parse_error: it escaped
  // as exit 1 with the library's own text.
  std::ofstream(rates_sidecar_path(path)) << "{\"schema\": \"inertialnet.rates/4\", \"metadata\": {\"x\": 1e400}}";
  EXPECT_TRUE(contains(invalid_input_message([&] { read_rates_csv(path); }), "beyond the range of a double"));
  // Without a sidecar: no metadata, and a note saying so.
  std::filesystem::remove(rates_sidecar_path(path));
  const RatesTable bare = read_rates_csv(path);
  EXPECT_TRUE(bare.metadata.empty());
  ASSERT_EQ(bare.notes.size(), 1u);
  EXPECT_TRUE(contains(bare.notes[0], "states no metadata (no sidecar rates.csv.json")) << bare.notes[0];
  // A file that states its metadata itself (schema 2) does not read a sidecar beside it.
  std::ofstream(rates_sidecar_path(path)) << "{\"schema\": \"inertialnet.rates/5\"}";
  const RatesTable two = read_rates_csv(write_text(dir, "# schema: inertialnet.rates/2\n# frame: camera\ntimestamp_ns,wx,wy,wz\n5,1,2,3\n"));
  EXPECT_EQ(two.meta("frame").value_or(""), "camera");
}

// A run that fails keeps the previous CSV and its sidecar as they were (issue 21: the pair must
// never be mixed).
TEST(RatesCsv, FailedRunKeepsThePreviousPair) {
  te::TempDir dir("rates_sidecar_keep");
  const auto path = dir.path() / "rates.csv";
  {
    RatesCsvWriter writer(path, {}, {{"frame", "body"}});
    writer.write({10, {0.1, 0.2, 0.3}, "ok", {}, {}});
    writer.close();
  }
  const std::string csv = file_text(path), sidecar = file_text(rates_sidecar_path(path));
  {
    RatesCsvWriter writer(path, {}, {{"frame", "camera"}});
    writer.write({10, {0.7, 0.8, 0.9}, "ok", {}, {}});
    // Destroyed without close().
  }
  EXPECT_EQ(file_text(path), csv);
  EXPECT_EQ(file_text(rates_sidecar_path(path)), sidecar);
  EXPECT_EQ(read_rates_csv(path).meta("frame").value_or(""), "body");
  EXPECT_EQ(read_rates_csv(partial_rates_path(path)).meta("frame").value_or(""), "camera");
  {
    RatesCsvWriter writer(path, {}, {{"frame", "camera"}});  // fails before its first row
  }
  EXPECT_FALSE(std::filesystem::exists(partial_rates_path(path)));
  EXPECT_FALSE(std::filesystem::exists(rates_sidecar_path(partial_rates_path(path))));
  EXPECT_EQ(file_text(rates_sidecar_path(path)), sidecar);
}

// Schema 4 added the σ columns; a schema-3 CSV with its sidecar (what predict wrote before) still
// reads, without σ columns.
TEST(RatesCsv, SchemaThreeFilesStillRead) {
  te::TempDir dir("rates_schema3");
  const auto path = write_text(dir, "timestamp_ns,wx,wy,wz,status\n10,0.1,0.2,0.3,ok\n20,,,,no_texture\n");
  std::ofstream(rates_sidecar_path(path)) << "{\"schema\": \"inertialnet.rates/3\", \"metadata\": {\"frame\": \"body\"}}";
  const RatesTable r = read_rates_csv(path);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r.meta("schema").value_or(""), "inertialnet.rates/3");
  EXPECT_EQ(r.meta("frame").value_or(""), "body");
  EXPECT_TRUE(r.extra_names.empty());
  EXPECT_EQ(r.status()[1], "no_texture");
}
