// Orbit elements (5.2) both ways, and (5.7)-(5.10) (with docs/paper.md items 4-5) against the
// averaged model (2.5) mapped through (5.2) by the chain rule at random states away from r^2 = k^2.
#include "cvg_bench/core/model/orbit_elements.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/common/errors.h"
#include "model/paper_orbit_rates.h"

namespace cvg_bench {
namespace {

TEST(OrbitElements, RoundTrip) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    OrbitElements e{1.0 + 0.3 * u(rng), 0.6 * u(rng), 0.7 * M_PI / 4 * u(rng), M_PI * u(rng)};
    const OrbitElements back = orbitFromSlow(slowFromOrbit(e));
    EXPECT_NEAR(back.r, e.r, 1e-12);
    EXPECT_NEAR(back.k, e.k, 1e-12);
    EXPECT_NEAR(back.theta, e.theta, 1e-12);
    EXPECT_NEAR(std::remainder(back.chi - e.chi, 2 * M_PI), 0.0, 1e-12);
  }
}

Eigen::Vector4d orbitVector(const Eigen::Vector4d& q) {
  const OrbitElements e = orbitFromSlow(q);
  return Eigen::Vector4d(e.r, e.k, e.theta, e.chi);
}

TEST(OrbitElements, OrbitRatesEqualAveragedModelThroughChainRule) {
  const ParameterValues p = {{"gamma", 0.9}, {"nu", 0.4},     {"b_c", 0.3},  {"b_s", -0.2},
                             {"c_m", 0.7},   {"n", 0.25},     {"h_c", -0.5}, {"h_s", 0.35},
                             {"xi", 1.3},    {"kappa", -0.6}, {"xi_k", -2.1}};
  const ResonatorModel model("xi+kappa+xi_k", ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = model.parameterVector(p);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 50; ++i) {
    OrbitElements e{1.0 + 0.3 * u(rng), 0.5 * u(rng), 0.7 * M_PI / 4 * u(rng), 0.8 * M_PI * u(rng)};
    const Eigen::Vector4d q = slowFromOrbit(e);
    const Eigen::Vector4d qdot = model.slowDerivative(q, {}, z);
    const double h = 1e-6;
    const Eigen::Vector4d chain = (orbitVector(q + h * qdot) - orbitVector(q - h * qdot)) / (2 * h);
    const OrbitRates o = orbitRates(e, p);
    EXPECT_NEAR(o.r_dot, chain[0], 1e-7) << "r' (5.7)";
    EXPECT_NEAR(o.k_dot, chain[1], 1e-7) << "k' (5.8)";
    EXPECT_NEAR(o.theta_dot, chain[2], 1e-7) << "theta' (5.9)";
    EXPECT_NEAR(o.chi_dot, chain[3], 1e-7) << "chi' (5.10)";
  }
}

TEST(OrbitElements, DriftRejectsTravellingWaveAndNonFiniteInput) {
  EXPECT_THROW(driftRate(1.0, 1.0, 0.0, {{"nu", 1.0}}), InputError);
  EXPECT_THROW(driftRate(NAN, 0.0, 0.0, {}), InputError);
}

// xi_k only turns the pattern: theta' gains xi_k r k / 8, and r', k', chi' do not change.
TEST(OrbitElements, SecondCubicInvariantOnlyTurnsThePattern) {
  const OrbitElements e{1.2, 0.3, 0.1, 0.4};
  const ParameterValues base = {{"gamma", 0.2}, {"xi", 1.5}, {"h_c", 0.1}};
  ParameterValues with = base;
  with["xi_k"] = 4.0;
  const OrbitRates a = orbitRates(e, base), b = orbitRates(e, with);
  EXPECT_NEAR(b.theta_dot - a.theta_dot, 4.0 * 1.2 * 0.3 / 8.0, 1e-14);
  EXPECT_DOUBLE_EQ(b.r_dot, a.r_dot);
  EXPECT_DOUBLE_EQ(b.k_dot, a.k_dot);
  EXPECT_DOUBLE_EQ(b.chi_dot, a.chi_dot);
}

// A pure standing wave (k = 0) drifts at -nu/4 plus the damping-anisotropy term only.
TEST(OrbitElements, StandingWaveDrift) {
  const ParameterValues p = {{"nu", 2.0}, {"b_c", 0.4}, {"b_s", 0.0}, {"xi", 5.0}};
  EXPECT_NEAR(driftRate(1.0, 0.0, M_PI / 8, p), -0.5 + 0.25 * 0.4, 1e-14);
}

}  // namespace
}  // namespace cvg_bench
