// One-mode response files: named columns (units in brackets ignored), headerless instrument files
// with and without --columns, comment lines, sweep splitting, and bad input naming file, line and
// field.
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/response_record.h"

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

/// The instrument text with one column left out (0-based index `drop`).
std::string withoutColumn(const std::string& text, size_t drop) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    if (line[0] == '#' || line[0] == '%') continue;
    std::istringstream cells(line);
    std::string c;
    size_t i = 0;
    std::string row;
    while (cells >> c)
      if (i++ != drop) row += (row.empty() ? "" : " ") + c;
    out << row << "\n";
  }
  return out.str();
}

TEST(ResponseReader, FourHeaderlessColumnsAreReadByWhatTheyHold) {
  // t, F, X, Y: the first column is a clock, the second turns round.
  const ResponseRecord a = readResponseText(withoutColumn(instrumentText(' '), 4), "in.txt");
  ASSERT_EQ(a.size(), 15u);
  EXPECT_TRUE(a.has_time);
  EXPECT_DOUBLE_EQ(a.frequency_hz[3], 1633.0);
  EXPECT_DOUBLE_EQ(a.drive[14], 1.0);
  EXPECT_NE(a.notes[0].find("t, frequency_hz, x, y"), std::string::npos);
  // F, X, Y, drive: the fourth holds two levels in 15 rows.
  const ResponseRecord b = readResponseText(withoutColumn(instrumentText(' '), 0), "in.txt");
  ASSERT_EQ(b.size(), 15u);
  EXPECT_FALSE(b.has_time);
  EXPECT_DOUBLE_EQ(b.frequency_hz[3], 1633.0);
  EXPECT_DOUBLE_EQ(b.drive[14], 2e-8);
  EXPECT_NE(b.notes[0].find("2 levels"), std::string::npos);
  // F, X, Y, drive of one up sweep per level: the first column never decreases within a level
  // and Y turns with the noise, yet the fourth's few levels decide.
  std::string up_sweeps;
  for (int level = 1; level <= 2; ++level)
    for (int i = 0; i < 10; ++i)
      up_sweeps += std::to_string(1630 + i) + " 0.1 " + (i % 2 ? "0.2" : "0.3") + " " +
                   std::to_string(level) + "e-8\n";
  const ResponseRecord c = readResponseText(up_sweeps, "in.txt");
  EXPECT_FALSE(c.has_time);
  EXPECT_DOUBLE_EQ(c.frequency_hz[9], 1639.0);
  EXPECT_DOUBLE_EQ(c.drive[19], 2e-8);
  // Neither: nothing is guessed.
  std::string neither;
  for (int i = 0; i < 10; ++i)
    neither += std::to_string(9 - i) + " " + std::to_string(i) + " 1 " + std::to_string(i) + "\n";
  EXPECT_NE(errorOf(neither).find("give --columns"), std::string::npos);
}

TEST(ResponseReader, InstrumentHeaderNamesAndCoarseClock) {
  std::ostringstream s;
  s << "Time F X Y D\n";
  for (int i = 0; i < 10; ++i) s << (i / 2) << " " << 1630 + i << " 1 2 0.5\n";
  const ResponseRecord r = readResponseText(s.str(), "in.txt");
  ASSERT_EQ(r.size(), 10u);
  EXPECT_DOUBLE_EQ(r.t_s[9], 4.0);
  EXPECT_DOUBLE_EQ(r.frequency_hz[9], 1639.0);
  EXPECT_DOUBLE_EQ(r.drive[0], 0.5);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("5 points share the time stamp"), std::string::npos);
}

TEST(ResponseReader, AMeasuredDriveKeepsItsSetLevels) {
  // A current read back with 0.2 % noise at two set levels 30 % apart: two levels, and the sweeps
  // split only where the set level changes or the frequency turns.
  std::vector<double> drive;
  ResponseRecord r;
  for (int i = 0; i < 40; ++i) {
    const double set = i < 20 ? 1.0 : 1.3;
    r.t_s.push_back(i);
    r.frequency_hz.push_back(100.0 + (i % 20 < 10 ? i % 20 : 19 - i % 20));
    r.x.push_back(1);
    r.y.push_back(0);
    r.drive.push_back(set * (1.0 + 0.002 * ((i * 7919) % 5 - 2)));
  }
  const std::vector<int> level = driveLevels(r.drive);
  EXPECT_EQ(level[0], 0);
  EXPECT_EQ(level[19], 0);
  EXPECT_EQ(level[20], 1);
  EXPECT_EQ(*std::max_element(level.begin(), level.end()), 1);
  const std::vector<int> sweep = splitSweeps(r);
  EXPECT_EQ(*std::max_element(sweep.begin(), sweep.end()), 3);  // up, down at each level
}

}  // namespace
}  // namespace cvg_bench
