// Free decays stacked for one fit (record_stacking.h): the joins are gaps the regression leaves
// out, and two decays started at different pattern angles bound the anisotropies better than one.
#include "cvg_bench/core/io/record_stacking.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../identification_test_support.h"
#include "../paper_section4_estimate.h"
#include "cvg_bench/core/estimate/free_decay_regression.h"
#include "cvg_bench/core/estimate/identify_pipeline.h"
#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace {

/// A noisy linear free decay (the section-4 truth) started at pattern angle theta [rad].
SlowRecord decayAt(double theta, unsigned seed) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  ParameterValues truth = testing_support::kFreeDecayTruth;
  truth.erase("xi");
  // Amplitude 1 along the pattern angle theta, no quadrature: (q1, p1, q2, p2).
  const Eigen::Vector4d q0(std::cos(theta), 0.0, std::sin(theta), 0.0);
  SlowRecord r =
      testing_support::simulateFreeDecay(model, model.parameterVector(truth), q0, 0.01, 401, 4);
  std::mt19937 rng(seed);
  std::normal_distribution<double> e(0.0, 0.01);
  for (auto& q : r.q)
    for (int k = 0; k < 4; ++k) q(k) += e(rng);
  r.omega_rad_s = 30000.0;
  r.source = "theta" + std::to_string(theta);
  return r;
}

TEST(RecordStacking, JoinsAreGapsTheRegressionLeavesOut) {
  std::vector<std::string> notes;
  const SlowRecord a = decayAt(0.0, 1), b = decayAt(0.6, 2);
  const SlowRecord s = stackFreeDecays({a, b}, notes);
  ASSERT_EQ(s.size(), a.size() + b.size());
  EXPECT_NEAR(s.t_s[a.size()] - s.t_s[a.size() - 1], 20.0 * 0.01, 1e-12);
  const std::vector<size_t> gaps = timeGapsOf(s);
  ASSERT_EQ(gaps.size(), 1u);
  EXPECT_EQ(gaps.front(), a.size() - 1);
  EXPECT_EQ(s.metadata.at("stacked_records"), "2");
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes.front().find("2 free decays stacked"), std::string::npos) << notes.front();
}

TEST(RecordStacking, RecordsOfAnotherFrequencyOrGivenTwiceAreRefused) {
  std::vector<std::string> notes;
  SlowRecord b = decayAt(0.6, 2);
  b.omega_rad_s = 30001.0;
  EXPECT_THROW(stackFreeDecays({decayAt(0.0, 1), b}, notes), InputError);
  EXPECT_THROW(stackFreeDecays({}, notes), InputError);
  const SlowRecord a = decayAt(0.0, 1);
  EXPECT_THROW(stackFreeDecays({a, a}, notes), InputError);  // one source counted twice
}

// One decay along theta = 0 leaves the damping anisotropy's b_s (the axis at 45 deg of the pattern
// in (2.6)'s 2-theta terms) loosely bound; a second decay started 22.5 deg away narrows it, and
// the stacked fit covers the truth.
TEST(RecordStacking, ASecondPatternAngleNarrowsTheAnisotropies) {
  PipelineOptions o;
  o.identification.model = "linear";
  const Estimate one = identify(decayAt(0.0, 1), o);
  std::vector<std::string> notes;
  const Estimate two = identify(stackFreeDecays({decayAt(0.0, 1), decayAt(M_PI / 8, 2)}, notes), o);
  for (const char* k : {"b_c", "b_s", "nu", "gamma"}) {
    const ParameterEstimate& p = two.parameters.at(k);
    EXPECT_NEAR(p.value, testing_support::kFreeDecayTruth.at(k), 4.0 * p.std_error) << k;
  }
  EXPECT_LT(two.parameters.at("b_s").std_error, one.parameters.at("b_s").std_error / 1.3);
}

}  // namespace
}  // namespace cvg_bench
