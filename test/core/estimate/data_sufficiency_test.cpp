// Known answers of the data-sufficiency checks: records that cannot carry the estimate are refused
// with the reason, good records pass; and identifyFreeDecay / identifyForced refuse them (exit 1 of
// the tool) instead of returning full-rank numbers fitted to noise.
#include "cvg_bench/core/estimate/data_sufficiency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/identification.h"

namespace cvg_bench {
namespace {

/// A free decay at 2 kHz: the (q1, p1) and (q2, p2) pairs rotate at 12 rad/s and decay at
/// gamma / 2 = 21.5 1/s (amplitudes a_f, a_g), plus white noise sigma on each channel.
SlowRecord decay(double a_f, double a_g, double sigma, size_t n = 400, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  SlowRecord r;
  r.omega_rad_s = 85732.0;
  for (size_t i = 0; i < n; ++i) {
    const double t = i / 2000.0, e = std::exp(-21.5 * t), c = std::cos(12.0 * t),
                 s = std::sin(12.0 * t);
    r.t_s.push_back(t);
    r.q.emplace_back(a_f * e * c + noise(rng), a_f * e * s + noise(rng), a_g * e * s + noise(rng),
                     -a_g * e * c + noise(rng));
  }
  return r;
}

SweepRecord sweep(const std::vector<double>& omega0) {
  SweepRecord s;
  s.omega_rad_s = 85732.0;
  for (double w : omega0) {
    const double l = w - s.omega_rad_s;
    const double a = 1.0 / std::sqrt(1.0 + (l / 21.5) * (l / 21.5));
    s.omega0_rad_s.push_back(w);
    s.q.emplace_back(a, 0.3 * a, 0.2 * a, -0.1 * a);
  }
  return s;
}

TEST(DataSufficiency, CleanDecayPasses) {
  const DataSufficiency d = assessFreeDecay(decay(1.0, 0.5, 1e-3), 8);
  EXPECT_TRUE(d.sufficient) << d.reason;
  // Mean square of an exponential over 4 decay times vs 2 sigma^2: well above 1e4.
  EXPECT_GT(d.snr_f, 1e4);
  EXPECT_GT(d.snr_g, 1e3);
}

TEST(DataSufficiency, PureNoiseIsRefused) {
  const DataSufficiency d = assessFreeDecay(decay(0.0, 0.0, 1e-3), 8);
  EXPECT_FALSE(d.sufficient);
  EXPECT_NE(d.reason.find("pure noise"), std::string::npos) << d.reason;
  // White noise: signal power = noise power (ratio 1 up to the MAD scale's sampling error).
  EXPECT_NEAR(d.snr_f, 1.0, 0.3);
  EXPECT_NEAR(d.snr_g, 1.0, 0.3);
}

TEST(DataSufficiency, SilentSecondCoordinateIsNamedNotRefused) {
  const DataSufficiency d = assessFreeDecay(decay(1.0, 0.0, 1e-3), 8);
  EXPECT_FALSE(d.sufficient);
  EXPECT_TRUE(d.coupling_only);  // identification goes on; collinearity reports the coupling
  EXPECT_NO_THROW(requireSufficientData(decay(1.0, 0.0, 1e-3), 8));
  EXPECT_NE(d.reason.find("g coordinate"), std::string::npos) << d.reason;
  EXPECT_NE(d.reason.find("not identified"), std::string::npos) << d.reason;
  EXPECT_NEAR(d.snr_g, 1.0, 0.3);
}

TEST(DataSufficiency, WeakButRealSignalPasses) {
  // Amplitude RMS about 10x the noise RMS in each pair: decays at moderate SNR are accepted.
  const DataSufficiency d = assessFreeDecay(decay(0.03, 0.03, 1e-3), 8);
  EXPECT_TRUE(d.sufficient) << d.reason;
}

TEST(DataSufficiency, TooFewSamplesForTheModel) {
  const DataSufficiency d = assessFreeDecay(decay(1.0, 0.5, 1e-3, 5), 8);
  EXPECT_FALSE(d.sufficient);  // 4 x 3 = 12 equations < 2 x 8
  EXPECT_NE(d.reason.find("12 equations for 8 parameters"), std::string::npos) << d.reason;
  EXPECT_TRUE(assessFreeDecay(decay(1.0, 0.5, 1e-3, 6), 8).sufficient);  // 16 equations
}

TEST(DataSufficiency, SweepAtOneFrequencyIsRefused) {
  const DataSufficiency d = assessSweep(sweep(std::vector<double>(61, 85740.0)), 12);
  EXPECT_FALSE(d.sufficient);
  EXPECT_NE(d.reason.find("1 distinct excitation frequency"), std::string::npos) << d.reason;
  std::vector<double> two(30, 85740.0);
  two.insert(two.end(), 31, 85760.0);
  EXPECT_FALSE(assessSweep(sweep(two), 12).sufficient);
  two.push_back(85700.0);
  EXPECT_TRUE(assessSweep(sweep(two), 12).sufficient);
}

TEST(DataSufficiency, FourPointSweepIsTooShort) {
  const DataSufficiency d = assessSweep(sweep({85700.0, 85720.0, 85740.0, 85760.0}), 12);
  EXPECT_FALSE(d.sufficient);  // 16 equations < 24
  EXPECT_NE(d.reason.find("16 equations for 12 parameters"), std::string::npos) << d.reason;
  EXPECT_TRUE(
      assessSweep(sweep({85680.0, 85700.0, 85720.0, 85740.0, 85760.0, 85780.0}), 12).sufficient);
}

TEST(DataSufficiency, IdentificationRefusesWithTheReason) {
  IdentificationOptions o;
  o.model = "linear";
  try {
    identifyFreeDecay(decay(0.0, 0.0, 1e-3), o);
    FAIL() << "pure noise was identified";
  } catch (const AnalysisError& e) {
    EXPECT_NE(std::string(e.what()).find("pure noise"), std::string::npos) << e.what();
  }
  EXPECT_THROW(identifyForced(sweep(std::vector<double>(61, 85740.0)), o), AnalysisError);
  EXPECT_NO_THROW(identifyFreeDecay(decay(1.0, 0.5, 1e-3), o));
}

}  // namespace
}  // namespace cvg_bench
