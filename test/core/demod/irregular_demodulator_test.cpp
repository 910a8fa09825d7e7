// Windowed least-squares demodulation on jittered, gappy timestamps: errors consistent with the
// reported standard errors (derived from the noise), skipped windows reported, bad samples counted.
#include "cvg_bench/core/demod/irregular_demodulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

Eigen::Vector4d envelope(double t) {
  return Eigen::Vector4d(0.8 - 0.004 * t, 0.3 + 0.002 * t, -0.1 + 0.003 * t, 0.05);
}

/// A camera-tracked pendulum: nominal 30 Hz, 3 ms timestamp jitter, 10 % of frames dropped,
/// white noise sigma on f and g, optional dropout [gap_from, gap_to).
RawRecord cameraRecord(double w, double sigma, unsigned seed, double gap_from = -1,
                       double gap_to = -1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> jitter(0.0, 0.003), noise(0.0, sigma);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RawRecord r;
  for (int i = 0; i < 30 * 60; ++i) {
    const double t = i / 30.0 + jitter(rng);
    if (u(rng) < 0.1 || (t >= gap_from && t < gap_to)) continue;
    const Eigen::Vector4d q = envelope(t);
    const double c = std::cos(w * t), s = std::sin(w * t);
    r.t_s.push_back(t);
    r.f.push_back(q[1] * s + q[0] * c + noise(rng));
    r.g.push_back(q[3] * s + q[2] * c + noise(rng));
  }
  r.omega_rad_s = w;
  return r;
}

TEST(IrregularDemodulator, ErrorsMatchReportedStandardErrors) {
  const double w = 2.0 * M_PI * 1.0, sigma = 0.01;
  IrregularDemodulatorOptions o;
  o.omega_rad_s = w;
  o.output_rate_hz = 0.5;  // window 4 s: ~108 frames, 4 pendulum periods
  double sum_z2 = 0.0;
  int count = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const IrregularDemodResult res = demodulateIrregular(cameraRecord(w, sigma, seed), o);
    ASSERT_GE(res.record.size(), 25u);
    EXPECT_EQ(res.n_too_few + res.n_rank_deficient, 0);
    for (size_t k = 0; k < res.record.size(); ++k) {
      const Eigen::Vector4d err = res.record.q[k] - envelope(res.record.t_s[k]);
      for (int c = 0; c < 4; ++c) {
        // The standard error is what the noise implies: ~ sigma sqrt(2 / n) (x ~2.2 for the
        // envelope-slope and offset columns).
        EXPECT_GT(res.std_error[k][c], sigma * std::sqrt(2.0 / res.n_samples[k]) * 0.7);
        EXPECT_LT(res.std_error[k][c], sigma * std::sqrt(2.0 / res.n_samples[k]) * 1.6);
        const double z = err[c] / res.std_error[k][c];
        EXPECT_LT(std::abs(z), 5.0);
        sum_z2 += z * z;
        ++count;
      }
    }
  }
  // Calibration: RMS of the normalized errors ~ 1 (560 values: +-0.15 is > 4 sigma).
  EXPECT_NEAR(std::sqrt(sum_z2 / count), 1.0, 0.15);
}

TEST(IrregularDemodulator, ExactForNoiseFreeLinearEnvelope) {
  const double w = 2.0 * M_PI * 1.0;
  IrregularDemodulatorOptions o;
  o.omega_rad_s = w;
  o.output_rate_hz = 0.5;
  const IrregularDemodResult res = demodulateIrregular(cameraRecord(w, 0.0, 9), o);
  for (size_t k = 0; k < res.record.size(); ++k)
    EXPECT_LT((res.record.q[k] - envelope(res.record.t_s[k])).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(IrregularDemodulator, DropoutWindowsReportedAndBadSamplesCounted) {
  const double w = 2.0 * M_PI * 1.0;
  RawRecord r = cameraRecord(w, 0.01, 3, 20.0, 31.0);
  r.f[100] = std::nan("");
  r.t_s.insert(r.t_s.begin() + 200, r.t_s[199]);  // duplicate timestamp
  r.f.insert(r.f.begin() + 200, 0.0);
  r.g.insert(r.g.begin() + 200, 0.0);
  IrregularDemodulatorOptions o;
  o.omega_rad_s = w;
  o.output_rate_hz = 0.5;
  const IrregularDemodResult res = demodulateIrregular(r, o);
  EXPECT_EQ(res.counters.non_finite, 1u);
  EXPECT_EQ(res.counters.duplicate_timestamp, 1u);
  EXPECT_GE(res.n_too_few, 3);  // centres 24, 26, 28 s see no sample in +-2 s
  for (double tc : res.skipped_window_times) {
    EXPECT_GT(tc, 20.0);
    EXPECT_LT(tc, 31.0);
  }
  for (const auto& q : res.record.q) EXPECT_TRUE(q.allFinite());
}

TEST(IrregularDemodulator, BadOptionsAndDataAreInputErrors) {
  IrregularDemodulatorOptions o;
  o.output_rate_hz = 0.0;
  o.fit_offset = false;
  o.fit_offset_slope = true;
  EXPECT_EQ(o.validate().size(), 3u);  // omega, rate, offset slope
  o = IrregularDemodulatorOptions();
  o.omega_rad_s = 1.0;  // period 6.3 s > default window 0.2 s
  EXPECT_FALSE(o.validate().empty());
  o.omega_rad_s = 2 * M_PI;
  o.output_rate_hz = 0.5;
  RawRecord tiny;
  tiny.t_s = {0.0, 0.1, 0.2};
  tiny.f = {1.0, 0.0, -1.0};
  tiny.g = {0.0, 0.0, 0.0};
  EXPECT_THROW(demodulateIrregular(tiny, o), InputError);
}

}  // namespace
}  // namespace cvg_bench
