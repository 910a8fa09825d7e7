// The model-free orbit reading (orbit_reading.h) on a record with a known course: the pattern turns
// at a constant rate, the amplitude decays exponentially (a known Q), the quadrature grows
// linearly; white noise on q. The reading's rates and Q must hold the truth within their intervals.
#include "cvg_bench/core/diagnose/orbit_reading.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/model/orbit_elements.h"

namespace cvg_bench {
namespace {

SlowRecord knownOrbit(double theta_rate, double lambda, double k_rate, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.002);
  SlowRecord rec;
  rec.omega_rad_s = 2.0;
  for (int i = 0; i < 2000; ++i) {
    const double t = 0.5 * i;
    const OrbitElements e{std::exp(-lambda * t), 0.01 + k_rate * t, -0.7 + theta_rate * t, 0.3 * t};
    Eigen::Vector4d q = slowFromOrbit(e);
    for (int c = 0; c < 4; ++c) q[c] += noise(rng);
    rec.t_s.push_back(t);
    rec.q.push_back(q);
  }
  return rec;
}

TEST(OrbitReading, KnownRatesAndQWithinTheirIntervals) {
  // theta turns through 1.5 rad (several wraps of pi/2) at 1.5e-3 rad/s; r falls by e^-0.5.
  const double theta_rate = 1.5e-3, lambda = 5e-4, k_rate = 1e-4;
  int covered = 0, total = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const OrbitReading m = readOrbit(knownOrbit(theta_rate, lambda, k_rate, seed), 0.0, nullptr);
    ASSERT_TRUE(m.valid) << m.why_not;
    EXPECT_EQ(m.windows.size(), 8u);
    EXPECT_NEAR(m.period_s, M_PI, 1e-12);
    EXPECT_NEAR(m.theta_rate.value, theta_rate, 1e-5);
    EXPECT_NEAR(m.k_rate.value, k_rate, 1e-5);
    for (const auto& w : m.windows) {
      ++total;
      covered += w.theta_rate.ci_low <= theta_rate && theta_rate <= w.theta_rate.ci_high;
      // Q = omega / (-2 r'/r) = 2 / (2 lambda) = 2000.
      EXPECT_NEAR(w.q.value, 2000.0, 0.1 * 2000.0);
    }
  }
  // 95 % intervals on 80 windows: at least 68 should hold the truth (binomial 0.1 % tail).
  EXPECT_GE(covered, 68) << covered << " of " << total;
}

TEST(OrbitReading, TheRkSlopeReadsACouplingOfThePatternRateToTheEllipse) {
  // theta' = c0 + C r k / 8 with k growing from 0.01 to 0.61 and r = 1: the windows' theta'
  // against r k / 8 has slope C (Airy's form of (5.9)); no model, so no model slope.
  const double c0 = 1e-4, C = 2e-3, k_rate = 3e-4;
  int covered = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.002);
    SlowRecord rec;
    rec.omega_rad_s = 2.0;
    for (int i = 0; i < 2000; ++i) {
      const double t = 0.5 * i, k = 0.01 + k_rate * t;
      // theta = integral of c0 + C k / 8 dt.
      const double theta = -0.7 + c0 * t + C / 8.0 * (0.01 * t + 0.5 * k_rate * t * t);
      Eigen::Vector4d q = slowFromOrbit(OrbitElements{1.0, k, theta, 0.3 * t});
      for (int c = 0; c < 4; ++c) q[c] += noise(rng);
      rec.t_s.push_back(t);
      rec.q.push_back(q);
    }
    const OrbitReading m = readOrbit(rec, 0.0, nullptr);
    ASSERT_TRUE(m.valid);
    EXPECT_NEAR(m.rk_slope_measured.value, C, 0.1 * C);
    covered += m.rk_slope_measured.ci_low <= C && C <= m.rk_slope_measured.ci_high;
    EXPECT_EQ(m.rk_slope_model.std_error, 0.0);
  }
  EXPECT_GE(covered, 7);
}

TEST(OrbitReading, TooShortOrTravellingWaveSaysWhy) {
  SlowRecord rec = knownOrbit(1e-3, 1e-4, 0.0, 3);
  rec.t_s.resize(20);
  rec.q.resize(20);
  EXPECT_FALSE(readOrbit(rec, 0.0, nullptr).valid);
  SlowRecord travelling;
  for (int i = 0; i < 500; ++i) {
    travelling.t_s.push_back(i);
    travelling.q.push_back(slowFromOrbit(OrbitElements{1.0, 1.0, 0.0, 0.1 * i}));
  }
  const OrbitReading m = readOrbit(travelling, 1.0, nullptr);
  EXPECT_FALSE(m.valid);
  EXPECT_NE(m.why_not.find("travelling wave"), std::string::npos);
}

}  // namespace
}  // namespace cvg_bench
