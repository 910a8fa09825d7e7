// CSV records: round trips at full precision, kind detection, and every kind of bad input giving an
// InputError that names file, line and column. The real Foucault pendulum record (shared data, not
// in the repository) is read when present.
#include "cvg_bench/core/io/record_io.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "record_io_test_" + name;
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

/// The InputError message of reading text, or "" when it reads fine.
std::string errorOf(const std::string& text, const RecordReadOptions& o = {}) {
  try {
    readRecordCsvText(text, "in.csv", o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RecordIo, SlowRecordRoundTripsAtFullPrecision) {
  SlowRecord r;
  r.omega_rad_s = 85732.0;
  r.metadata["truth_gamma"] = "0.1";
  for (int i = 0; i < 5; ++i) {
    r.t_s.push_back(0.1 * i + 1e-17 * i);
    r.q.emplace_back(1.0 / 3.0 + i, -2.0 / 7.0, 1e-300 * i, -M_PI * i);
  }
  r.extra["temperature"] = {1, 2, 3, 4, 5};
  const std::string path = tempPath("slow.csv");
  writeSlowRecordCsv(r, path);
  const AnyRecord back = readRecordCsv(path);
  ASSERT_EQ(back.kind, RecordKind::kFreeDecay);
  EXPECT_EQ(back.slow.omega_rad_s, 85732.0);
  EXPECT_EQ(back.slow.metadata.at("mode"), "free_decay");
  EXPECT_EQ(back.slow.metadata.at("truth_gamma"), "0.1");
  ASSERT_EQ(back.slow.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(back.slow.t_s[i], r.t_s[i]);
    EXPECT_EQ(back.slow.q[i], r.q[i]);  // bit-identical with %.17g
  }
  EXPECT_EQ(back.slow.extra.at("temperature"), r.extra.at("temperature"));
}

TEST(RecordIo, SweepRecordRoundTripsWithFlags) {
  SweepRecord s;
  s.omega_rad_s = 100.0;
  s.omega0_rad_s = {99.0, 100.0, 101.0};
  s.q = {Eigen::Vector4d(0.1, 0.2, 0.3, 0.4), Eigen::Vector4d(0.5, 0.6, 0.7, 0.8),
         Eigen::Vector4d(-1, -2, -3, -4)};
  s.direction = {1, 1, -1};
  s.jump = {0, 1, 0};
  std::stringstream out;
  writeSweepRecordCsv(s, out);
  const AnyRecord back = readRecordCsvText(out.str(), "sweep.csv");
  ASSERT_EQ(back.kind, RecordKind::kForcedSweep);
  EXPECT_EQ(back.sweep.metadata.at("mode"), "forced");
  EXPECT_EQ(back.sweep.omega0_rad_s, s.omega0_rad_s);
  EXPECT_EQ(back.sweep.direction, s.direction);
  EXPECT_EQ(back.sweep.jump, s.jump);
  EXPECT_EQ(back.sweep.q[2], s.q[2]);
  EXPECT_EQ(back.omegaRadS(), 100.0);
}

TEST(RecordIo, RawRecordWithSemicolonsCommentsAndMappedColumns) {
  const std::string text =
      "# omega: 2.236\n#   just a note\n# mode: free_decay\n"
      "time ; x ; y ; extra\n0;1;2;9\n 0.5 ; 1.5 ; 2.5 ;9\n\n1.0;-1e-3;+4;9\n";
  RecordReadOptions o;
  o.raw_columns = parseRawColumnMap("t=time,f=x,g=y");
  const AnyRecord rec = readRecordCsvText(text, "raw.csv", o);
  ASSERT_EQ(rec.kind, RecordKind::kRaw);
  EXPECT_EQ(rec.raw.omega_rad_s, 2.236);
  EXPECT_EQ(rec.raw.t_s, (std::vector<double>{0, 0.5, 1.0}));
  EXPECT_EQ(rec.raw.f, (std::vector<double>{1, 1.5, -1e-3}));
  EXPECT_EQ(rec.raw.g, (std::vector<double>{2, 2.5, 4}));
  EXPECT_EQ(rec.raw.extra.at("extra").size(), 3u);
  // Without the mapping a position track of exactly time, x, y is read as t, f, g, and the
  // record says so; with a fourth column nothing is guessed.
  const AnyRecord track = readRecordCsvText("time;x;y\n0;1;2\n0.5;1.5;2.5\n1.0;-1e-3;4\n",
                                            "raw.csv", RecordReadOptions());
  ASSERT_EQ(track.kind, RecordKind::kRaw);
  EXPECT_EQ(track.raw.f, rec.raw.f);
  EXPECT_EQ(track.raw.g, rec.raw.g);
  EXPECT_NE(track.raw.metadata.at("columns_read_as").find("time, x, y read as t, f, g"),
            std::string::npos);
  EXPECT_NE(errorOf(text).find("--columns"), std::string::npos);
}

TEST(RecordIo, BadCellsNameFileLineAndColumn) {
  const std::string head = "t,q1,p1,q2,p2\n0,1,2,3,4\n";
  EXPECT_NE(errorOf(head + "1,1,abc,3,4\n").find("in.csv:3:3: column 'p1': 'abc' is not a number"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "1,1,2,nan,4\n").find("in.csv:3:4:"), std::string::npos);
  EXPECT_NE(errorOf(head + "1,1,2,3,inf\n").find("not finite"), std::string::npos);
  EXPECT_NE(errorOf(head + "1,1,2,,4\n").find("in.csv:3:4: column 'q2': empty cell"),
            std::string::npos);
  EXPECT_NE(errorOf(head + "1,1,2,3\n").find("in.csv:3: expected 5 fields"), std::string::npos);
  EXPECT_NE(errorOf(head + "0,1,2,3,4\n").find("in.csv:3:1: time 0 repeats"), std::string::npos);
  EXPECT_NE(errorOf(head + "-1,1,2,3,4\n").find("is before"), std::string::npos);
  EXPECT_NE(errorOf("t,q1,p1,q2\n0,1,2,3\n").find("none of the known column sets"),
            std::string::npos);
  EXPECT_NE(errorOf("").find("empty file"), std::string::npos);
  EXPECT_NE(errorOf("# omega: 3\n\n").find("empty file"), std::string::npos);
  EXPECT_NE(errorOf("t,q1,p1,q2,p2\n").find("no data rows"), std::string::npos);
  EXPECT_NE(errorOf("# omega: -3\nt,q1,p1,q2,p2\n0,1,2,3,4\n").find("in.csv:1: # omega"),
            std::string::npos);
  EXPECT_NE(errorOf("t,q1,q1,q2,p2\n0,1,2,3,4\n").find("appears twice"), std::string::npos);
  EXPECT_NE(errorOf("omega0,q1,p1,q2,p2\n0,1,2,3,4\n").find("must be > 0"), std::string::npos);
  EXPECT_NE(errorOf("omega0,q1,p1,q2,p2,jump\n1,1,2,3,4,2\n").find("allowed flags"),
            std::string::npos);
  EXPECT_THROW(readRecordCsv(tempPath("does_not_exist.csv")), InputError);
  EXPECT_THROW(parseRawColumnMap("x=time"), InputError);
  EXPECT_THROW(parseRawColumnMap("t=a,t=b"), InputError);
}

TEST(RecordIo, RawTimestampsStrictOrRepairedWithCounts) {
  const std::string text = "t,f,g\n0,0,0\n0.2,2,2\n0.1,1,1\n0.2,9,9\n0.3,3,3\n";
  EXPECT_NE(errorOf(text).find("in.csv:4:1: time 0.10000000000000001 is before"),
            std::string::npos);
  RecordReadOptions o;
  o.repair_raw_timestamps = true;
  const RawRecord r = readRecordCsvText(text, "in.csv", o).raw;
  EXPECT_EQ(r.t_s, (std::vector<double>{0, 0.1, 0.2, 0.3}));
  EXPECT_EQ(r.f, (std::vector<double>{0, 1, 2, 3}));  // the first of the duplicated rows is kept
  EXPECT_EQ(r.n_reordered, 1);                        // 0.1 came after 0.2
  EXPECT_EQ(r.n_duplicates_dropped, 1);
}

TEST(RecordIo, PerKindReadersRefuseOtherKinds) {
  const std::string path = tempPath("kind.csv");
  writeText(path, "t,f,g\n0,1,2\n");
  EXPECT_NO_THROW(readRawRecordCsv(path));
  EXPECT_THROW(readSlowRecordCsv(path), InputError);
  EXPECT_THROW(readSweepRecordCsv(path), InputError);
}

TEST(RecordIo, ReadsTheRealFoucaultPendulumRecord) {
  const std::string path = "/work/shared/data/foucault_florence_2021/2021_09_17_14_57_N.csv";
  if (!std::ifstream(path)) GTEST_SKIP() << path << " not present";
  RecordReadOptions o;
  o.raw_columns = parseRawColumnMap("t=time,f=x,g=y");
  o.repair_raw_timestamps = true;
  const RawRecord r = readRawRecordCsv(path, o);
  // README: 12,594 rows over 1,456.7 s, irregular sampling.
  EXPECT_EQ(r.size() + r.n_duplicates_dropped, 12594u);
  EXPECT_NEAR(r.t_s.back() - r.t_s.front(), 1456.7, 0.1);
  for (size_t i = 1; i < r.size(); ++i) ASSERT_GT(r.t_s[i], r.t_s[i - 1]);
  EXPECT_EQ(r.f.front(), 171.0);
  EXPECT_EQ(r.g.front(), 447.0);
}

}  // namespace
}  // namespace cvg_bench
