// The identifier node's recursive mode: block RLS fed one slow state at a time reaches the batch
// least-squares estimate at forgetting factor 1 (docs/paper.md item 9), on a seeded simulated
// decay.
#include "cvg_bench/ros/streaming_free_decay_rls.h"

#include <gtest/gtest.h>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/simulate/experiment_runner.h"

namespace cvg_bench {
namespace {

SlowRecord simulatedDecay() {
  SimulationOptions so;
  so.mode = ExperimentMode::kFreeDecay;
  so.seed = 3;
  return simulateExperiment(loadShippedPreset("mems_ring"), so).slow;
}

TEST(StreamingFreeDecayRls, ReachesTheBatchEstimate) {
  const SlowRecord rec = simulatedDecay();
  IdentificationOptions o;
  o.model = "xi";
  StreamingFreeDecayRls rls(o);
  EXPECT_THROW(rls.estimate(rec.omega_rad_s), AnalysisError);  // nothing yet
  for (size_t i = 0; i < rec.size(); ++i) rls.add(rec.t_s[i], rec.q[i]);
  ASSERT_TRUE(rls.initialized());
  const Estimate r = rls.estimate(rec.omega_rad_s);
  const Estimate b = identifyFreeDecay(rec, o);
  ASSERT_EQ(r.names, b.names);
  EXPECT_EQ(r.n_equations, b.n_equations);
  EXPECT_EQ(r.method, "rls");
  for (size_t i = 0; i < b.names.size(); ++i) {
    const double se = b.parameters.at(b.names[i]).std_error;
    EXPECT_NEAR(r.values[i], b.values[i], 1e-6 * se) << b.names[i];
    // The recursive intervals are the paper's (2.11): they contain the batch value.
    EXPECT_LT(r.parameters.at(b.names[i]).ci_low, b.values[i]);
    EXPECT_GT(r.parameters.at(b.names[i]).ci_high, b.values[i]);
  }
  EXPECT_NEAR(r.sigma, b.sigma, 1e-9 * b.sigma);
  EXPECT_GT(r.derived.count("Q"), 0u);
}

TEST(StreamingFreeDecayRls, RefusesWhatItCannotDo) {
  IdentificationOptions o;
  o.model = "cm_rate";
  EXPECT_THROW(StreamingFreeDecayRls{o}, InputError);
  o.model = "linear";
  StreamingFreeDecayRls rls(o);
  rls.add(1.0, Eigen::Vector4d(1, 0, 0, 0));
  EXPECT_THROW(rls.add(0.5, Eigen::Vector4d(1, 0, 0, 0)), InputError);
  EXPECT_THROW(rls.add(2.0, Eigen::Vector4d(std::nan(""), 0, 0, 0)), InputError);
}

}  // namespace
}  // namespace cvg_bench
