// Bad single samples in raw records (raw_glitches.h): a spike is left out, a start-up glitch is
// cut, a jump in the middle is kept and reported, and a clean noisy record loses nothing; the one
// raw path (raw_record_demodulation.h) gives the clean record's slow samples when a glitch is
// added.
#include "cvg_bench/core/demod/raw_glitches.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/demod/raw_record_demodulation.h"

namespace cvg_bench {
namespace {

constexpr double kW = 2.2372;  // rad/s: a pendulum of 2.81 s period, sampled like a camera

/// A slowly decaying ellipse (pixels about a centre of 300, 200) at ~8.6 Hz with jitter and noise.
RawRecord pendulum(double sigma, unsigned seed, int n = 6000) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma), jitter(0.0, 0.01);
  RawRecord r;
  for (int i = 0; i < n; ++i) {
    const double t = i * 0.116 + jitter(rng);
    const double a = 150.0 * std::exp(-t / 4000.0);
    r.t_s.push_back(t);
    r.f.push_back(300.0 + a * std::cos(kW * t) + noise(rng));
    r.g.push_back(200.0 + 0.1 * a * std::sin(kW * t) + noise(rng));
  }
  r.source = "pendulum";
  return r;
}

TEST(RawGlitches, CleanNoisyRecordLosesNothing) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    RawRecord r = pendulum(3.0, seed);
    const RawGlitchReport rep = removeRawGlitches(r, kW);
    EXPECT_FALSE(rep.any()) << rep.describe();
    EXPECT_EQ(r.size(), 6000u);
  }
}

TEST(RawGlitches, SpikeLeftOutHeadCutJumpKept) {
  RawRecord r = pendulum(3.0, 7);
  r.f[3000] += 900.0;  // a misread frame: 6x the swing
  r.g[3000] -= 400.0;
  r.f[2] = 20.0;  // start-up: frames 0..2 from elsewhere
  r.f[1] = 25.0;
  r.f[0] = 22.0;
  for (size_t i = 4500; i < 4600; ++i) r.f[i] += 800.0;  // tracking off for 100 frames
  const double t_spike = r.t_s[3000], t_out = r.t_s[4499], t_back = r.t_s[4599];
  const RawGlitchReport rep = removeRawGlitches(r, kW);
  ASSERT_EQ(rep.spike_times_s.size(), 1u);
  EXPECT_DOUBLE_EQ(rep.spike_times_s[0], t_spike);
  EXPECT_EQ(rep.head_dropped, 3);
  EXPECT_EQ(rep.tail_dropped, 0);
  ASSERT_EQ(rep.jump_times_s.size(), 2u);
  EXPECT_DOUBLE_EQ(rep.jump_times_s[0], t_out);
  EXPECT_DOUBLE_EQ(rep.jump_times_s[1], t_back);
  EXPECT_EQ(r.size(), 6000u - 4u);
  EXPECT_NE(rep.describe().find("start-up glitch"), std::string::npos);
}

TEST(RawGlitches, ShortOrUnknownFrequencyRecordsAreLeftAlone) {
  RawRecord r = pendulum(3.0, 3, 15);
  r.f[7] += 1e4;
  EXPECT_FALSE(removeRawGlitches(r, kW).any());
  RawRecord s = pendulum(3.0, 3);
  s.f[100] += 1e4;
  EXPECT_FALSE(removeRawGlitches(s, 0.0).any());
}

TEST(RawRecordDemodulation, GlitchDoesNotMoveTheSlowRecord) {
  const RawRecord clean = pendulum(3.0, 11);
  RawRecord bad = clean;
  bad.f[2000] += 1200.0;
  std::vector<std::string> n1, n2;
  const SlowRecord a = demodulateRawRecord(clean, kW, n1);
  const SlowRecord b = demodulateRawRecord(bad, kW, n2);
  ASSERT_EQ(n2.size(), 2u);  // the glitch's note, then the demodulation's
  EXPECT_NE(n2[0].find("1 isolated spike"), std::string::npos) << n2[0];
  // One output a period (slow oscillator, irregular times), window two periods.
  EXPECT_NEAR(a.size(), 6000 * 0.116 * kW / (2 * M_PI), 3.0);
  ASSERT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 4; ++k) worst = std::max(worst, std::abs(a.q[i](k) - b.q[i](k)));
  // Leaving one of ~48 samples of a window out moves q by about the noise's share (3 px /
  // sqrt(48)).
  EXPECT_LT(worst, 2.0);
}

}  // namespace
}  // namespace cvg_bench
