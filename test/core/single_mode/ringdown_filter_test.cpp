// Known-answer tests of the detector filter of a ring-down: its power correlation, its estimate
// from the noise floor of a record read through a known low-pass, and the filtered envelope.
#include "cvg_bench/core/single_mode/ringdown_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include "cvg_bench/core/single_mode/ringdown_fit.h"
#include "cvg_bench/core/single_mode/ringdown_segmentation.h"

namespace cvg_bench {
namespace {

TEST(RingdownFilter, PowerCorrelationOfEqualPoles) {
  // rho_1 = e^{-x}, rho_2 = (1 + x) e^{-x}, rho_3 = (1 + x + x^2 / 3) e^{-x}, squared.
  EXPECT_NEAR(ringdownFilterPowerCorrelation(1, 0.5), std::exp(-1.0), 1e-12);
  EXPECT_NEAR(ringdownFilterPowerCorrelation(2, 1.0), 4.0 * std::exp(-2.0), 1e-12);
  const double r3 = (1.0 + 2.0 + 4.0 / 3.0) * std::exp(-2.0);
  EXPECT_NEAR(ringdownFilterPowerCorrelation(3, 2.0), r3 * r3, 1e-12);
  const double r4 = (1.0 + 1.0 + 0.4 + 1.0 / 15.0) * std::exp(-1.0);
  EXPECT_NEAR(ringdownFilterPowerCorrelation(4, 1.0), r4 * r4, 1e-12);
  EXPECT_NEAR(ringdownFilterPowerCorrelation(2, 0.0), 1.0, 1e-12);
}

/// A ring-down (plateau, decay tau = 0.3 s at zero amplitude, extra rate extra_nl x that at the
/// drive-off from a law in A^2, floor -60 dB) read through `order` equal poles of time constant
/// tc_s at 1 kHz, with white complex noise at the detector input.
RingdownEnvelope filteredRecord(int order, double tc_s, unsigned seed, double extra_nl = 0.0) {
  const double dt = 1e-3, tau = 0.3, t_off = 0.2, floor = 1e-3;
  const int n = 4000, pre = 200;
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const double a = std::exp(-dt / tc_s);
  // Noise through the filter, scaled to rms `floor` afterwards; the signal through it separately.
  std::vector<std::complex<double>> nz(n + pre), sg(n + pre);
  for (int i = 0; i < n + pre; ++i) {
    nz[i] = {g(rng), g(rng)};
    const double t = (i - pre) * dt;
    // dA/dt = -(g0 + g2 A^2) A from A = 1, g2 = extra_nl g0: A^2 = e^{-2 g0 s} / (1 + extra_nl
    // (1 - e^{-2 g0 s})) (the closed form of ringdown_models.h).
    const double e2 = std::exp(-2.0 * (t - t_off) / tau);
    sg[i] = t < t_off ? 1.0 : std::sqrt(e2 / (1.0 + extra_nl * (1.0 - e2)));
  }
  for (int s = 0; s < order; ++s) {
    std::complex<double> yn = 0.0, ys = 1.0;
    for (int i = 0; i < n + pre; ++i) {
      yn = a * yn + (1.0 - a) * nz[i], nz[i] = yn;
      ys = a * ys + (1.0 - a) * sg[i], sg[i] = ys;
    }
  }
  double p = 0.0;
  for (int i = pre; i < n + pre; ++i) p += std::norm(nz[i]);
  const double scale = floor / std::sqrt(p / n);
  RingdownEnvelope env;
  env.frequency_hz = 1e4;
  for (int i = 0; i < n; ++i) {
    env.t_s.push_back(i * dt);
    env.log_amplitude.push_back(std::log(std::abs(sg[i + pre] + scale * nz[i + pre])));
  }
  return env;
}

TEST(RingdownFilter, TimeConstantAndOrderFromTheFloorNoise) {
  // Two poles of 6 ms and one of 10 ms (6 and 10 samples): the correlation time of the floor's
  // power, the integral of rho_n^2 (1.25 T for two poles, 0.5 T for one), within 20 %; the
  // order as far as it is identified.
  for (int order : {2, 1}) {
    const double tc = order == 2 ? 6e-3 : 10e-3;
    for (unsigned seed : {1u, 2u}) {
      const RingdownEnvelope env = filteredRecord(order, tc, seed);
      const RingdownSegment seg = segmentRingdown(env);
      ASSERT_TRUE(seg.has_floor);
      const RingdownDetectorFilter f = estimateDetectorFilter(env, seg, 1.0 / 0.3);
      ASSERT_TRUE(f.found) << f.why;
      EXPECT_EQ(f.source, "noise_floor");
      auto corrTime = [](int n, double t) {
        double s = 0.0;
        for (int k = 0; k < 4000; ++k) s += ringdownFilterPowerCorrelation(n, (k + 0.5) * 0.01);
        return s * 0.01 * t;
      };
      EXPECT_NEAR(corrTime(f.order, f.time_constant_s) / corrTime(order, tc), 1.0, 0.2)
          << "order " << f.order << " T " << f.time_constant_s;
      EXPECT_GT(f.n_samples, 1000);
      // The order is weakly identified (the shape of the first lags): one pole has the cusp at
      // lag 0, two poles a smooth start (taken as 2 to 4).
      if (order == 1) {
        EXPECT_EQ(f.order, 1) << "T " << f.time_constant_s;
      } else {
        EXPECT_GE(f.order, 2) << "T " << f.time_constant_s;
      }
    }
  }
}

TEST(RingdownFilter, LawInAmplitudeSquaredRecoveredThroughTheFilter) {
  // Two poles of 20 ms (0.067 of the decay time), extra rate 1.5 g0 at the drive-off: fitted
  // from the plateau through the estimated filter, the A^2 law leaves a smaller sum of squares
  // than the law in A and gives g0 and g2 within 10 % and 25 %.
  const double tau = 0.3, extra = 1.5;
  const RingdownEnvelope env = filteredRecord(2, 20e-3, 5, extra);
  const RingdownSegment seg = segmentRingdown(env);
  const RingdownFit lin = fitRingdown(env, seg, "linear");
  const RingdownDetectorFilter filt = estimateDetectorFilter(env, seg, lin.p(1) / lin.t_scale_s);
  ASSERT_TRUE(filt.found) << filt.why;
  const RingdownFit nl = fitRingdown(env, seg, "gamma_nl", {}, ringdownStarts("gamma_nl", lin));
  const RingdownFit ga = fitRingdown(env, seg, "gamma_a", {}, ringdownStarts("gamma_a", lin));
  const RingdownFilteredFit fn = fitRingdownThroughFilter(env, seg, nl, filt, {});
  const RingdownFilteredFit fa = fitRingdownThroughFilter(env, seg, ga, filt, {});
  ASSERT_TRUE(fn.ok && fa.ok);
  EXPECT_LT(fn.sse_whitened, fa.sse_whitened);
  EXPECT_LT(fn.t_start_s, 0.2);  // the plateau is fitted
  EXPECT_NEAR(fn.drive_off_s, 0.2, 0.01);
  // Normalized rates: g [1 / t_scale]; A' = A / A_ref, so g2' = g2 A_ref^2 t_scale.
  const double g0 = 1.0 / tau, g2 = extra * g0;
  EXPECT_NEAR(fn.p(1) / nl.t_scale_s, g0, 0.1 * g0);
  EXPECT_NEAR(fn.p(2) * std::exp(-2.0 * nl.log_a_ref) / nl.t_scale_s, g2, 0.25 * g2);
}

TEST(RingdownFilter, NoFloorNoFilter) {
  RingdownEnvelope env;
  env.frequency_hz = 1e4;
  for (int i = 0; i < 1000; ++i) {
    env.t_s.push_back(i * 1e-3);
    env.log_amplitude.push_back(i < 100 ? 0.0 : -(i - 100) * 1e-3 / 0.3);
  }
  const RingdownSegment seg = segmentRingdown(env);
  const RingdownDetectorFilter f = estimateDetectorFilter(env, seg, 1.0 / 0.3);
  EXPECT_FALSE(f.found);
  EXPECT_EQ(f.source, "none");
}

TEST(RingdownFilter, FilteredEnvelopeOfOnePoleIsTheClosedForm) {
  // y' = (x - y) / T, x = e^{-g s} after s = 0, y(0) = 1: y = (e^{-g s} - g T e^{-s/T}) / (1 - g
  // T).
  const double g = 2.0, T = 0.05, t_off = 0.1;
  Eigen::VectorXd p(2);
  p << 0.3, g;  // ln A = 0.3 - g t
  std::vector<double> t;
  for (int i = 0; i < 200; ++i) t.push_back(i * 0.005);
  const std::vector<double> f = ringdownFilteredLogAmplitude("linear", p, t_off, 1, T, t, 0.0);
  ASSERT_EQ(f.size(), t.size());
  const double a_off = 0.3 - g * t_off;
  for (size_t i = 0; i < t.size(); ++i) {
    const double s = t[i] - t_off;
    const double want =
        s <= 0.0 ? a_off
                 : a_off + std::log((std::exp(-g * s) - g * T * std::exp(-s / T)) / (1.0 - g * T));
    // Grid T / 8, linear between its points: under 3e-4 Np at the corner (the records' noise
    // is 3e-3 Np or more).
    EXPECT_NEAR(f[i], want, 3e-4) << "t " << t[i];
  }
  // Two poles, long after the corner: the exponential passes with the gain 1 / (1 - g T)^2.
  const std::vector<double> f2 = ringdownFilteredLogAmplitude("linear", p, t_off, 2, T, t, 0.0);
  EXPECT_NEAR(f2.back(), 0.3 - g * t.back() - 2.0 * std::log(1.0 - g * T), 1e-4);
}

}  // namespace
}  // namespace cvg_bench
