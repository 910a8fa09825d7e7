// One-mode response files: named columns (units in brackets ignored), headerless instrument files
// with and without --columns, comment lines, sweep splitting, and bad input naming file, line and
// field.
#include <gtest/gtest.h>

#include <sstream>

#include "cvg_bench/core/io/response_record.h"
#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace {

std::string errorOf(const std::string& text, const std::string& columns = "") {
  try {
    readResponseText(text, "in.txt", columns);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// n rows of t,F,X,Y,drive: an up sweep then a down sweep at drive d1, then an up sweep at d2.
std::string instrumentText(char sep) {
  std::ostringstream s;
  s << "# t1=1673187108\n% a lock-in export\n";
  double t = 100.0;
  auto row = [&](double f, double d) {
    s << t << sep << f << sep << 1e-7 << sep << -2e-7 << sep << d << "\n";
    t += 2.25;
  };
  for (int i = 0; i < 5; ++i) row(1630 + i, 1e-8);
  for (int i = 4; i >= 0; --i) row(1630 + i, 1e-8);
  for (int i = 0; i < 5; ++i) row(1630 + i, 2e-8);
  return s.str();
}

TEST(ResponseReader, HeaderlessInstrumentFileReadsAsTFXYDriveWithANote) {
  const ResponseRecord r = readResponseText(instrumentText(' '), "in.txt");
  ASSERT_EQ(r.size(), 15u);
  EXPECT_TRUE(r.has_time);
  EXPECT_DOUBLE_EQ(r.frequency_hz[3], 1633.0);
  EXPECT_DOUBLE_EQ(r.x[0], 1e-7);
  EXPECT_DOUBLE_EQ(r.y[0], -2e-7);
  EXPECT_DOUBLE_EQ(r.drive[14], 2e-8);
  EXPECT_EQ(r.comments.size(), 2u);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("t, frequency_hz, x, y, drive"), std::string::npos);
}

TEST(ResponseReader, SweepsSplitAtReversalsAndDriveChanges) {
  const ResponseRecord r = readResponseText(instrumentText('\t'), "in.txt");
  const std::vector<int> s = splitSweeps(r);
  // Up 0..4 (the turning point 1634 stays with the up sweep), down from the next point, up at d2.
  EXPECT_EQ(s[0], 0);
  EXPECT_EQ(s[4], 0);
  EXPECT_EQ(s[5], 0);  // 1634 again: no step yet
  EXPECT_EQ(s[6], 1);
  EXPECT_EQ(s[9], 1);
  EXPECT_EQ(s[10], 2);
  EXPECT_EQ(s[14], 2);
}

TEST(ResponseReader, ColumnMapPicksAnyOrder) {
  std::ostringstream s;  // frequency first, time second
  for (int i = 0; i < 10; ++i)
    s << 1630 + i << "," << i << "," << 0.1 * i << "," << 0.2 << "," << 9 << "\n";
  const ResponseRecord r =
      readResponseText(s.str(), "in.csv", "frequency_hz=1,t=2,x=3,y=4,drive=5");
  ASSERT_EQ(r.size(), 10u);
  EXPECT_DOUBLE_EQ(r.t_s[9], 9.0);
  EXPECT_DOUBLE_EQ(r.x[5], 0.5);
  EXPECT_TRUE(r.notes.empty());
}

TEST(ResponseReader, NamedColumnsWithUnitsAndDirection) {
  std::ostringstream s;
  s << "t [s],frequency_hz [Hz],x [V],y [V],drive [A],direction\n";
  for (int i = 0; i < 10; ++i)
    s << i << "," << 100 + (i < 5 ? i : 9 - i) << ",1,2,0.5," << (i < 5 ? "up" : "down") << "\n";
  const ResponseRecord r = readResponseText(s.str(), "in.csv");
  ASSERT_EQ(r.size(), 10u);
  ASSERT_EQ(r.direction.size(), 10u);
  EXPECT_EQ(r.direction[0], 1);
  EXPECT_EQ(r.direction[9], -1);
  EXPECT_EQ(splitSweeps(r)[5], 1);  // the direction column starts the second sweep
}

TEST(ResponseReader, BadInputNamesLineAndField) {
  std::string text = instrumentText(' ');
  std::string bad = text;
  bad.replace(bad.find("1632"), 4, "abcd");
  EXPECT_NE(errorOf(bad).find("in.txt:5: field 2 (frequency_hz)"), std::string::npos)
      << errorOf(bad);
  EXPECT_NE(errorOf("t,frequency_hz,x\n1,2,3\n").find("no column 'y'"), std::string::npos);
  EXPECT_NE(errorOf("1 2 3 4\n").find("give --columns"), std::string::npos);
  EXPECT_NE(errorOf(text, "t=1,x=3").find("'frequency_hz' is required"), std::string::npos);
  EXPECT_NE(errorOf(text, "t=1,frequency_hz=2,x=3,y=4,drive=0").find("number from 1"),
            std::string::npos);
  EXPECT_NE(errorOf(text, "t=1,frequency_hz=2,x=3,y=4,foo=5").find("unknown key 'foo'"),
            std::string::npos);
  std::string backwards = "3 1630 1 1 1\n2 1631 1 1 1\n";
  for (int i = 0; i < 8; ++i) backwards += std::to_string(10 + i) + " 1632 1 1 1\n";
  EXPECT_NE(errorOf(backwards).find("time must increase"), std::string::npos);
  std::string zero_drive = text;
  zero_drive.replace(zero_drive.find("1e-08"), 5, "0.000");
  EXPECT_NE(errorOf(zero_drive).find("drive must be > 0"), std::string::npos)
      << errorOf(zero_drive);
  EXPECT_NE(errorOf("# only comments\n").find("at least 8"), std::string::npos);
}

}  // namespace
}  // namespace cvg_bench
