// Known-answer tests of the ring-down CSV reader (interfaces.md, "Single-channel ring-downs").
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/ringdown_record.h"

namespace cvg_bench {
namespace {

std::string rows(int n, const char* sep) {
  std::ostringstream s;
  for (int i = 0; i < n; ++i) s << i * 0.1 << sep << " " << -10.0 - i << "\n";
  return s.str();
}

TEST(RingdownReader, InstrumentHeaderWithUnitsAndPercentComments) {
  const std::string text =
      "% Zero span export\n% Frequency [Hz]: 1.55e6\n% note: ring-down 3\n"
      "time [s]; power [dBm]\n" +
      rows(10, ";");
  const RingdownRecord r = readRingdownCsvText(text, "x.csv");
  EXPECT_EQ(r.kind, RingdownValueKind::kPowerDb);
  EXPECT_DOUBLE_EQ(r.frequency_hz, 1.55e6);
  ASSERT_EQ(r.size(), 10u);
  EXPECT_DOUBLE_EQ(r.value[3], -13.0);
  EXPECT_DOUBLE_EQ(r.t_s[9], 0.9);
}

TEST(RingdownReader, HeaderOnlyInACommentAndOmegaKey) {
  const std::string text = "# omega: 6283.185307179586\n# t, amplitude\n" + rows(9, ",");
  const RingdownRecord r = readRingdownCsvText(text, "x.csv");
  EXPECT_EQ(r.kind, RingdownValueKind::kAmplitude);
  EXPECT_NEAR(r.frequency_hz, 1000.0, 1e-9);
}

TEST(RingdownReader, TabsRawWaveformAndNonFiniteDropOuts) {
  std::string text = "# frequency_hz: 50\nt\tf\n";
  for (int i = 0; i < 9; ++i)
    text += std::to_string(i * 0.001) + "\t" + (i == 4 ? "nan" : "0.5") + "\n";
  const RingdownRecord r = readRingdownCsvText(text, "w.csv");
  EXPECT_EQ(r.kind, RingdownValueKind::kRawWaveform);
  EXPECT_TRUE(std::isnan(r.value[4]));
  EXPECT_DOUBLE_EQ(r.frequency_hz, 50.0);
}

TEST(RingdownReader, BadFieldNamesFileLineAndColumn) {
  const std::string text = "t,power_db\n0,1\n0.1,2\n0.2,abc\n" + rows(8, ",");
  try {
    readRingdownCsvText(text, "bad.csv");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad.csv:4"), std::string::npos) << m;
    EXPECT_NE(m.find("column 2"), std::string::npos) << m;
    EXPECT_NE(m.find("abc"), std::string::npos) << m;
  }
}

TEST(RingdownReader, MissingValueColumnAndTimeGoingBackAreErrors) {
  EXPECT_THROW(readRingdownCsvText("t,q\n" + rows(9, ","), "a.csv"), InputError);
  EXPECT_THROW(readRingdownCsvText("t,amplitude\n0,1\n0,1\n" + rows(9, ","), "b.csv"), InputError);
  EXPECT_THROW(readRingdownCsvText("# frequency_hz: fast\nt,amplitude\n" + rows(9, ","), "c.csv"),
               InputError);
}

}  // namespace
}  // namespace cvg_bench
