// The one identification pipeline (identify_pipeline.h): each method on known-truth data made here
// (averaged free decay by RK4 of (2.6), forced sweep by the stationary points of (3.3)), and the
// control nonlinearity mu estimated jointly by the Ceres stage from an LS start at mu = 0.
#include "cvg_bench/core/estimate/identify_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/stationary_solver.h"
#include "identification_test_support.h"
#include "paper_section4_estimate.h"

namespace cvg_bench {
namespace {

using testing_support::kFreeDecayTruth;
using testing_support::kSection4Estimate;
constexpr double kOmega = testing_support::kSection4OmegaRadS;

SlowRecord freeDecay() {
  const ResonatorModel model("xi", ExperimentMode::kFreeDecay);
  SlowRecord r =
      testing_support::simulateFreeDecay(model, model.parameterVector(kFreeDecayTruth),
                                         Eigen::Vector4d(0.8, 0.3, 0.2, -0.1), 0.01, 401, 8);
  r.omega_rad_s = 30000.0;
  return r;
}

/// The section-4 ring swept over +-150 rad/s (61 points) with control nonlinearity mu.
SweepRecord forcedSweep(double mu) {
  const ResonatorModel model("xi", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector(kSection4Estimate);
  SweepRecord r;
  r.omega_rad_s = kOmega;
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  for (int j = 0; j < 61; ++j) {
    const double omega0 = kOmega - 150.0 + 5.0 * j;
    const StationaryPoint p =
        solveStationaryPoint(model, z, SlowContext{0.0, mu}, detuningRate(kOmega, omega0), q);
    EXPECT_TRUE(p.converged) << p.failure;
    q = p.q;
    r.omega0_rad_s.push_back(omega0);
    r.q.push_back(q);
  }
  return r;
}

PipelineOptions optionsFor(const std::string& model, Method method) {
  PipelineOptions o;
  o.method = method;
  o.identification.model = model;
  return o;
}

void expectTruth(const Estimate& e, const ParameterValues& truth, double rel) {
  for (const auto& kv : truth)
    EXPECT_NEAR(e.parameters.at(kv.first).value, kv.second, rel * (1.0 + std::fabs(kv.second)))
        << kv.first << " (" << e.method << ")";
}

TEST(IdentifyPipeline, MethodNamesRoundTrip) {
  for (Method m : {Method::kLs, Method::kRls, Method::kCeres})
    EXPECT_EQ(parseMethod(methodName(m)), m);
  EXPECT_THROW(parseMethod("gauss"), InputError);
}

TEST(IdentifyPipeline, EveryMethodRecoversNoiselessFreeDecay) {
  const SlowRecord record = freeDecay();
  const Estimate ls = identify(record, optionsFor("xi", Method::kLs));
  const Estimate rls = identify(record, optionsFor("xi", Method::kRls));
  const Estimate ceres = identify(record, optionsFor("xi", Method::kCeres));
  EXPECT_EQ(ls.method, "ls");
  EXPECT_EQ(rls.method, "rls");
  EXPECT_EQ(ceres.method, "ceres");
  expectTruth(ls, kFreeDecayTruth, 1e-5);
  // (2.12) at forgetting 1 equals the batch solution (docs/paper.md item 9).
  for (const auto& kv : kFreeDecayTruth)
    EXPECT_NEAR(rls.parameters.at(kv.first).value, ls.parameters.at(kv.first).value, 1e-8)
        << kv.first;
  expectTruth(ceres, kFreeDecayTruth, 1e-6);
}

// The deferred form (explain's refined fits): the solved estimate already has identify()'s
// values, sigma and dof but no intervals; finish() returns identify()'s estimate.
TEST(IdentifyPipeline, DeferredCeresFinishesToTheSameEstimate) {
  SlowRecord record = freeDecay();
  for (size_t i = 0; i < record.size(); ++i)
    record.q[i] += 1e-3 * Eigen::Vector4d(std::sin(7.1 * i), std::cos(3.3 * i), std::sin(1.9 * i),
                                          std::cos(5.7 * i));
  const PipelineOptions o = optionsFor("xi", Method::kCeres);
  const Estimate full = identify(record, o);
  const DeferredEstimate d = identifyDeferred(record, o);
  ASSERT_TRUE(static_cast<bool>(d.finish));
  EXPECT_EQ(d.estimate.method, "ceres");
  EXPECT_TRUE(d.estimate.parameters.empty());
  EXPECT_EQ(d.estimate.dof, full.dof);
  EXPECT_DOUBLE_EQ(d.estimate.sigma, full.sigma);
  const Estimate finished = d.finish();
  EXPECT_EQ(finished.notes, full.notes);
  EXPECT_EQ(finished.interval_method_id, full.interval_method_id);
  for (const auto& kv : full.parameters) {
    EXPECT_DOUBLE_EQ(
        d.estimate.values[std::find(d.estimate.names.begin(), d.estimate.names.end(), kv.first) -
                          d.estimate.names.begin()],
        kv.second.value)
        << kv.first;
    EXPECT_DOUBLE_EQ(finished.parameters.at(kv.first).value, kv.second.value) << kv.first;
    EXPECT_DOUBLE_EQ(finished.parameters.at(kv.first).std_error, kv.second.std_error) << kv.first;
  }
  EXPECT_FALSE(identifyDeferred(record, optionsFor("xi", Method::kLs)).finish);
}

TEST(IdentifyPipeline, CeresEstimatesMuJointlyFromLsStart) {
  const double mu = 0.3;
  const SweepRecord record = forcedSweep(mu);
  const Estimate e = identify(record, optionsFor("xi+mu", Method::kCeres));
  EXPECT_EQ(e.method, "ceres");
  EXPECT_EQ(e.model, "linear+xi+mu");
  EXPECT_EQ(e.rank, 14);
  ParameterValues truth = kSection4Estimate;
  truth[ResonatorModel::muName()] = mu;
  expectTruth(e, truth, 1e-6);
}

TEST(IdentifyPipeline, MuNeedsTheCeresStage) {
  const SweepRecord record = forcedSweep(0.0);
  for (Method m : {Method::kLs, Method::kRls})
    EXPECT_THROW(identify(record, optionsFor("xi+mu", m)), InputError) << methodName(m);
  // A known mu enters the LS regression instead (3.4).
  PipelineOptions known = optionsFor("xi", Method::kLs);
  const Estimate e = identify(forcedSweep(0.2), [&] {
    known.identification.mu = 0.2;
    return known;
  }());
  expectTruth(e, kSection4Estimate, 1e-6);
}

TEST(IdentifyPipeline, ModelKnowsWhetherItEstimatesMu) {
  EXPECT_TRUE(ResonatorModel("xi+mu", ExperimentMode::kForced).estimatesMu());
  EXPECT_FALSE(ResonatorModel("xi", ExperimentMode::kForced).estimatesMu());
  const ResonatorModel m(std::vector<std::string>{"mu", "xi"}, ExperimentMode::kForced);
  EXPECT_EQ(m.spec(), "linear+mu+xi");
  EXPECT_EQ(m.linearPart().spec(), "linear+xi");
  EXPECT_FALSE(m.linearPart().estimatesMu());
  EXPECT_EQ(m.parameterNames(), m.linearPart().parameterNames());
}

}  // namespace
}  // namespace cvg_bench
