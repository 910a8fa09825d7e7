// Known-answer tests of the longest straight stretch (ringdown_straight_span.h).
#include "cvg_bench/core/single_mode/ringdown_straight_span.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cvg_bench {
namespace {

constexpr double kNeperPerDb = 2.302585092994046 / 20.0;

struct Rec {
  std::vector<double> t, y;
  std::vector<bool> skip;
};

/// level(t) in dB at 1 sample/s plus white noise of sd_db; a Rayleigh-like floor where asked.
template <class F>
Rec make(int n, F level, double sd_db, unsigned seed = 2) {
  std::mt19937 g(seed);
  std::normal_distribution<double> e(0.0, sd_db);
  Rec r;
  for (int i = 0; i < n; ++i) {
    r.t.push_back(i);
    r.y.push_back((level(double(i)) + e(g)) * kNeperPerDb);
    r.skip.push_back(false);
  }
  return r;
}

TEST(RingdownStraightSpan, ADecayIntoAWanderingFloorEndsAtTheFloorWithItsSlope) {
  // Plateau to 50 s, decay 0.25 dB/s to a floor at -60 dB that wanders +-8 dB slowly.
  const Rec r = make(
      800,
      [](double t) {
        const double decay = t < 50 ? 0.0 : -0.25 * (t - 50);
        const double floor = -60.0 + 8.0 * std::sin(t / 23.0);
        return 10.0 * std::log10(std::pow(10.0, decay / 10.0) + std::pow(10.0, floor / 10.0));
      },
      0.3);
  const StraightSpan s = findStraightSpan(r.t, r.y, r.skip);
  ASSERT_TRUE(s.ok);
  EXPECT_NEAR(s.slope_db_s, -0.25, 0.01);
  EXPECT_GE(s.i_start, 50u);
  EXPECT_LE(s.i_start, 60u);
  // The stretch ends where the wandering floor comes within 4 dB of the line (a 1.5 dB rise of the
  // sum of powers, the tolerance), give or take the 8-sample run that confirms a departure.
  int meet = 50;
  while (meet < 800 && -60.0 + 8.0 * std::sin(meet / 23.0) < -0.25 * (meet - 50) - 4.0) ++meet;
  EXPECT_NEAR(double(s.i_end), double(meet), 15.0);
  EXPECT_EQ(s.end, StraightSpanEnd::kFloor);
}

TEST(RingdownStraightSpan, AShortSwitchOffTransientDoesNotWin) {
  // A 20 dB fall in 5 samples at switch-off, then a 0.1 dB/s decay over 400 s.
  const Rec r = make(
      500,
      [](double t) {
        if (t < 50) return 0.0;
        if (t < 55) return -4.0 * (t - 50);
        return -20.0 - 0.1 * (t - 55);
      },
      0.1);
  const StraightSpan s = findStraightSpan(r.t, r.y, r.skip);
  ASSERT_TRUE(s.ok);
  EXPECT_NEAR(s.slope_db_s, -0.1, 0.005);
  EXPECT_GE(s.i_start, 55u);
}

TEST(RingdownStraightSpan, NoDecayIsNoStretch) {
  const Rec r = make(
      300, [](double) { return -40.0; }, 1.0);
  EXPECT_FALSE(findStraightSpan(r.t, r.y, r.skip).ok);
}

// A decay followed by the drive on again to the record's end (the development set's D309 shape):
// from the highest peak (the last stretch) nothing falls; all_peaks finds the decay after the
// first stretch.
TEST(RingdownStraightSpan, AllPeaksFindsADecayBeforeARexcitation) {
  const Rec r = make(
      600,
      [](double t) {
        if (t < 100) return 0.0;
        if (t >= 300) return 0.5;  // drive on again, a little higher
        return std::max(-0.4 * (t - 100), -60.0);
      },
      0.3);
  const StraightSpan top = findStraightSpan(r.t, r.y, r.skip);
  EXPECT_FALSE(top.ok && top.span_db >= 10.0);
  StraightSpanOptions o;
  o.all_peaks = true;
  const StraightSpan s = findStraightSpan(r.t, r.y, r.skip, o);
  ASSERT_TRUE(s.ok);
  EXPECT_NEAR(s.slope_db_s, -0.4, 0.01);
  EXPECT_GE(s.i_start, 100u);
  EXPECT_LE(s.i_start, 115u);
  EXPECT_LE(s.i_end, 255u);
  EXPECT_GT(s.span_db, 40.0);
}

}  // namespace
}  // namespace cvg_bench
