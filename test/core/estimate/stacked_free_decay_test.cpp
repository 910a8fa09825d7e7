// Free decays of one resonator stacked in one regression (identification.h,
// identify_pipeline.h): each record keeps its own equations, two decays started at different
// pattern angles bound the anisotropies better than one, and what would fake precision is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../identification_test_support.h"
#include "../paper_section4_estimate.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/identify_pipeline.h"

namespace cvg_bench {
namespace {

/// A noisy linear free decay (the section-4 truth) started at pattern angle theta [rad], sampled
/// every dt seconds.
SlowRecord decayAt(double theta, unsigned seed, double dt = 0.01, int n = 401) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  ParameterValues truth = testing_support::kFreeDecayTruth;
  truth.erase("xi");
  // Amplitude 1 along the pattern angle theta, no quadrature: (q1, p1, q2, p2).
  const Eigen::Vector4d q0(std::cos(theta), 0.0, std::sin(theta), 0.0);
  SlowRecord r =
      testing_support::simulateFreeDecay(model, model.parameterVector(truth), q0, dt, n, 4);
  std::mt19937 rng(seed);
  std::normal_distribution<double> e(0.0, 0.01);
  for (auto& q : r.q)
    for (int k = 0; k < 4; ++k) q(k) += e(rng);
  r.omega_rad_s = 30000.0;
  r.source = "theta" + std::to_string(theta) + "_dt" + std::to_string(dt);
  return r;
}

PipelineOptions linearLs() {
  PipelineOptions o;
  o.identification.model = "linear";
  return o;
}

// Stacking adds each record's own equations: the equation count is the sum of the records'
// (no equation joins two records, none is lost), also when their sample steps differ by 10x.
TEST(StackedFreeDecay, EachRecordKeepsItsOwnEquations) {
  const PipelineOptions o = linearLs();
  const SlowRecord a = decayAt(0.0, 1), b = decayAt(0.6, 2, 0.1, 41);
  const Estimate ea = identify(a, o), eb = identify(b, o), both = identify({a, b}, o);
  EXPECT_EQ(both.n_equations, ea.n_equations + eb.n_equations);
  EXPECT_EQ(identify(std::vector<SlowRecord>{a}, o).n_equations, ea.n_equations);
}

TEST(StackedFreeDecay, AnotherFrequencyATwiceGivenRecordAndCeresAreRefused) {
  const PipelineOptions o = linearLs();
  SlowRecord b = decayAt(0.6, 2);
  b.omega_rad_s = 30010.0;  // 333 ppm: another resonator
  EXPECT_THROW(identify({decayAt(0.0, 1), b}, o), InputError);
  try {
    identify({decayAt(0.0, 1), b}, o);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--omega"), std::string::npos) << e.what();
  }
  PipelineOptions common = o;  // a given omega is the common one: then they stack
  common.identification.omega_rad_s = 30000.0;
  EXPECT_NO_THROW(identify({decayAt(0.0, 1), b}, common));
  SlowRecord near = decayAt(0.6, 2);
  near.omega_rad_s = 30000.0 * (1.0 + 2e-5);  // 20 ppm: a temperature drift, still one resonator
  EXPECT_NO_THROW(identify({decayAt(0.0, 1), near}, o));
  const SlowRecord a = decayAt(0.0, 1);
  EXPECT_THROW(identify({a, a}, o), InputError);  // one source counted twice
  PipelineOptions ceres = o;
  ceres.method = Method::kCeres;
  EXPECT_THROW(identify({a, decayAt(0.6, 2)}, ceres), InputError);
}

// One decay along theta = 0 leaves the damping anisotropy's b_s (the axis at 45 deg of the pattern
// in (2.6)'s 2-theta terms) loosely bound; a second decay started 22.5 deg away narrows it, and
// the stacked fit covers the truth.
TEST(StackedFreeDecay, ASecondPatternAngleNarrowsTheAnisotropies) {
  const PipelineOptions o = linearLs();
  const Estimate one = identify(decayAt(0.0, 1), o);
  const Estimate two = identify({decayAt(0.0, 1), decayAt(M_PI / 8, 2)}, o);
  for (const char* k : {"b_c", "b_s", "nu", "gamma"}) {
    const ParameterEstimate& p = two.parameters.at(k);
    EXPECT_NEAR(p.value, testing_support::kFreeDecayTruth.at(k), 4.0 * p.std_error) << k;
  }
  EXPECT_LT(two.parameters.at("b_s").std_error, one.parameters.at("b_s").std_error / 1.3);
}

}  // namespace
}  // namespace cvg_bench
