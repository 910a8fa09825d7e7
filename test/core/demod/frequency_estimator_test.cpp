// Reference-frequency estimation on noisy tones, uniform and irregular: the error is consistent
// with the reported standard error (Monte Carlo), which is near the Cramer-Rao bound.
#include "cvg_bench/core/demod/frequency_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

struct Tone {
  std::vector<double> t, f, g;
};

/// f = A cos(W t + phi) decaying with time constant tau, g = 0.4 A sin(...), noise sigma; uniform
/// at fs or camera-like (uniform jitter +-30 % of the sample period, 10 % dropped).
Tone makeTone(double w, double fs, size_t n, double sigma, bool irregular, unsigned seed,
              double tau = INFINITY) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::uniform_real_distribution<double> jitter(-0.3 / fs, 0.3 / fs);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Tone s;
  for (size_t i = 0; i < n; ++i) {
    double t = 12.5 + i / fs;
    if (irregular) {
      t += jitter(rng);
      if (u(rng) < 0.1) continue;
    }
    const double a = std::exp(-(t - 12.5) / tau);
    s.t.push_back(t);
    s.f.push_back(a * std::cos(w * t + 0.3) + noise(rng));
    s.g.push_back(0.4 * a * std::sin(w * t + 0.3) + noise(rng));
  }
  return s;
}

void checkCalibrated(bool irregular) {
  const double w = 2.0 * M_PI * 87.3, fs = 1000.0, sigma = 0.3;
  const size_t n = 8000;
  double sum_z2 = 0.0;
  const int runs = 20;
  for (int r = 0; r < runs; ++r) {
    const Tone s = makeTone(w, fs, n, sigma, irregular, 100 + r);
    const FrequencyEstimate e = estimateFrequency(s.t, s.f, s.g);
    // Cramer-Rao for real sinusoids: var(W) = 24 sigma^2 / (N T^2 sum A^2) (f and g, A = 1, 0.4).
    const double span = s.t.back() - s.t.front();
    const double crb = std::sqrt(24.0 * sigma * sigma / (s.t.size() * span * span * (1 + 0.16)));
    EXPECT_GT(e.std_rad_s, 0.9 * crb);
    EXPECT_LT(e.std_rad_s, 1.15 * crb);
    const double z = (e.omega_rad_s - w) / e.std_rad_s;
    EXPECT_LT(std::abs(z), 4.5) << e.method;
    sum_z2 += z * z;
    EXPECT_NEAR(e.residual_rms, sigma, 0.05 * sigma);
  }
  // 20 runs: RMS of z within [0.6, 1.45] unless the reported std is wrong (chi2 with 20 dof).
  const double rms = std::sqrt(sum_z2 / runs);
  EXPECT_GT(rms, 0.6);
  EXPECT_LT(rms, 1.45);
}

TEST(FrequencyEstimator, UniformNoisyToneCalibrated) {
  checkCalibrated(false);
}
TEST(FrequencyEstimator, IrregularNoisyToneCalibrated) {
  checkCalibrated(true);
}

TEST(FrequencyEstimator, LongDecayingRecordRefinedBeyondTheFftSegment) {
  // 5 s of a decaying 5 kHz (HRG-like) tone at 40 kHz, FFT restricted to 0.1 s: the staged
  // refinement must reach far below the FFT resolution (2.5 Hz = 16 rad/s per bin here).
  const double w = 2.0 * M_PI * 5123.4567, fs = 40000.0;
  const Tone s = makeTone(w, fs, 200000, 0.05, false, 7, 4.0);
  FrequencyEstimatorOptions o;
  o.max_fft_samples = 1 << 14;
  const FrequencyEstimate e = estimateFrequency(s.t, s.f, s.g, o);
  EXPECT_LT(std::abs(e.omega_rad_s - w), 5.0 * e.std_rad_s);
  EXPECT_LT(e.std_rad_s, 1e-3);
  EXPECT_GT(std::abs(e.coarse_rad_s - w), std::abs(e.omega_rad_s - w));
  EXPECT_FALSE(e.method.empty());
}

TEST(FrequencyEstimator, BadInputIsInputError) {
  const Tone s = makeTone(10.0, 100.0, 200, 0.0, false, 1);
  std::vector<double> t = s.t;
  t[50] = t[49];
  EXPECT_THROW(estimateFrequency(t, s.f, s.g), InputError);
  std::vector<double> f = s.f;
  f[3] = NAN;
  EXPECT_THROW(estimateFrequency(s.t, f, s.g), InputError);
  EXPECT_THROW(estimateFrequency({0.0, 1.0}, {0.0, 1.0}, {0.0, 1.0}), InputError);
  FrequencyEstimatorOptions o;
  o.oversampling = 0;
  EXPECT_THROW(estimateFrequency(s.t, s.f, s.g, o), InputError);
}

}  // namespace
}  // namespace cvg_bench
