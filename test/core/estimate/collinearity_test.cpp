// Near-collinear identifiability (collinearity.h): exact variance-inflation factors on a known
// design; a free decay with one standing wave along an axis (the second mode only noise) reports
// the individual damping / frequency parameters as not identified, names the combinations it
// determines, and takes Q from the envelope decay, whose interval holds the trajectory's true
// envelope Q; two pattern angles identify everything and Q comes from gamma.
#include "cvg_bench/core/estimate/collinearity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cvg_bench/core/estimate/ceres_refinement.h"
#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "identification_test_support.h"

namespace cvg_bench {
namespace {

// nu + b_s = 0 and n - h_s = 0 keep q2 = p2 = 0 exactly for a wave started at theta = 0, k = 0.
const ParameterValues kTruth = {{"gamma", 0.05}, {"nu", 0.01}, {"b_c", 0.01}, {"b_s", -0.01},
                                {"c_m", 0.3},    {"n", 0.04},  {"h_c", 0.1},  {"h_s", 0.04}};
constexpr double kOmega = 1000.0;

SlowRecord run(double theta, double sigma, unsigned seed) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  SlowRecord r = testing_support::simulateFreeDecay(
      model, model.parameterVector(kTruth), slowFromOrbit({1.0, 0.0, theta, 0.0}), 0.02, 2000);
  r.omega_rad_s = kOmega;
  return sigma > 0 ? testing_support::withNoise(r, sigma, seed) : r;
}

bool has(const std::vector<std::string>& v, const std::string& x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

/// The reported combination of gamma and b_c ("gamma+b_c", or with a coefficient near 1 when the
/// noise tilts the weak direction), or nullptr.
const ParameterEstimate* gammaPlusBc(const Estimate& e, std::string* name) {
  for (const auto& kv : e.combinations) {
    if (kv.first.rfind("gamma+", 0) == 0 && kv.first.find("b_c") != std::string::npos &&
        kv.first.find("nu") == std::string::npos) {
      *name = kv.first;
      return &kv.second;
    }
  }
  return nullptr;
}

TEST(Collinearity, VarianceInflationOfTwoCorrelatedColumnsIsOneOverOneMinusRSquared) {
  // Unit columns at correlation r: VIF = 1 / (1 - r^2) for both, whatever their scales.
  const double r = 0.999;
  Eigen::MatrixXd j(3, 2);
  j << 1.0, 1e5 * r, 0.0, 1e5 * std::sqrt(1 - r * r), 0.0, 0.0;
  const CollinearityReport rep = analyzeCollinearity({"a", "b"}, j, 2);
  EXPECT_NEAR(rep.vif[0], 1.0 / (1.0 - r * r), 1e-6 * rep.vif[0]);
  EXPECT_NEAR(rep.vif[1], 1.0 / (1.0 - r * r), 1e-6 * rep.vif[1]);
  EXPECT_NEAR(rep.condition_number, std::sqrt((1 + r) / (1 - r)), 1e-6 * rep.condition_number);
  EXPECT_TRUE(rep.not_identified.empty());  // VIF 500 < 1e4
  ASSERT_EQ(rep.weak.size(), 0u);           // s_min = sqrt(1 - r) = 0.032 > 0.01
}

TEST(Collinearity, StandingWaveAlongAnAxisReportsNotIdentifiedAndQFromTheEnvelope) {
  const SlowRecord clean = run(0.0, 0.0, 0);
  // The true envelope rate: -d ln|q|^2 / dt of the noiseless trajectory (2 q' = D(q) z).
  const double t_end = clean.t_s.back();
  const double rate_true =
      -std::log(clean.q.back().squaredNorm() / clean.q.front().squaredNorm()) / t_end;
  const double q_true = kOmega / rate_true;
  int q_covered = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const Estimate e = identifyFreeDecay(run(0.0, 1e-3, seed), IdentificationOptions());
    ASSERT_EQ(e.rank, 8);
    for (const char* p : {"gamma", "b_c", "nu", "b_s"}) EXPECT_TRUE(has(e.not_identified, p)) << p;
    EXPECT_GT(e.vif.at("gamma"), 1e4);
    EXPECT_FALSE(e.weak_directions.empty());
    std::string name;
    const ParameterEstimate* g = gammaPlusBc(e, &name);
    ASSERT_NE(g, nullptr) << e.identifiability_note;
    EXPECT_LT(std::fabs(g->value - 0.06), 5 * g->std_error + 1e-4) << name;
    EXPECT_NE(e.identifiability_note.find("not identified by this record"), std::string::npos);
    ASSERT_TRUE(e.derived.count("Q"));
    EXPECT_NE(e.derived_method.at("Q").find("envelope"), std::string::npos);
    const ParameterEstimate& q = e.derived.at("Q");
    EXPECT_DOUBLE_EQ(q.value, e.derived.at("Q_envelope").value);
    EXPECT_LT(q.ci_high - q.ci_low, 0.05 * q.value);  // the envelope is well identified
    q_covered += q.ci_low <= q_true && q_true <= q.ci_high;
  }
  EXPECT_GE(q_covered, 8);  // 95 % intervals, 10 seeds: P(< 8) = 0.012
}

TEST(Collinearity, TwoPatternAnglesIdentifyEverythingAndQComesFromGamma) {
  const Estimate e = identifyFreeDecay(
      std::vector<SlowRecord>{run(0.0, 1e-3, 3), run(M_PI / 8, 1e-3, 4)}, IdentificationOptions());
  EXPECT_TRUE(e.not_identified.empty());
  for (const auto& kv : e.vif) EXPECT_LT(kv.second, 100.0) << kv.first;
  EXPECT_EQ(e.derived_method.at("Q"), "omega/gamma");
  EXPECT_NEAR(e.derived.at("Q").value, kOmega / 0.05, 0.02 * kOmega / 0.05);
}

TEST(Collinearity, OutputErrorFitReportsTheSameWeakParameters) {
  const SlowRecord rec = run(0.0, 1e-3, 5);
  const Estimate start = identifyFreeDecay(rec, IdentificationOptions());
  const Estimate e = refineWithCeres(rec, start);
  for (const char* p : {"gamma", "b_c"}) EXPECT_TRUE(has(e.not_identified, p)) << p;
  std::string name;
  EXPECT_NE(gammaPlusBc(e, &name), nullptr) << e.identifiability_note;
  EXPECT_NE(e.derived_method.at("Q").find("envelope"), std::string::npos);
}

}  // namespace
}  // namespace cvg_bench
