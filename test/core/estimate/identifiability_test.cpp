// Identifiability (docs/paper.md item 11): a pure standing wave determines only 4 combinations of
// the 8 linear parameters; two runs at pattern angles 0 and pi/8 determine all.
#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "identification_test_support.h"

namespace cvg_bench {
namespace {

// nu + b_s = 0 and n - h_s = 0 keep q2 = p2 = 0 exactly for a wave started at theta = 0, k = 0.
const ParameterValues kTruth = {{"gamma", 0.05}, {"nu", 0.01}, {"b_c", 0.01}, {"b_s", -0.01},
                                {"c_m", 0.3},    {"n", 0.04},  {"h_c", 0.1},  {"h_s", 0.04}};

SlowRecord run(double theta) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  return testing_support::simulateFreeDecay(model, model.parameterVector(kTruth),
                                            slowFromOrbit({1.0, 0.0, theta, 0.0}), 0.02, 2000);
}

TEST(Identifiability, StandingWaveLeavesFourCombinations) {
  const SlowRecord standing = run(0.0);
  for (const auto& q : standing.q) ASSERT_EQ(q[2], 0.0);
  ASSERT_EQ(standing.q.back()[3], 0.0);
  const Estimate e = identifyFreeDecay(standing, IdentificationOptions());
  EXPECT_EQ(e.rank, 4);
  EXPECT_EQ(e.unidentifiable.size(), 8u);
  EXPECT_TRUE(e.parameters.empty());  // no individual parameter is reported
  EXPECT_NE(e.identifiability_note.find("second mode"), std::string::npos)
      << e.identifiability_note;
  ASSERT_EQ(e.combinations.size(), 4u);
  EXPECT_NEAR(e.combinations.at("gamma+b_c").value, 0.06, 1e-8);
  EXPECT_NEAR(e.combinations.at("nu+b_s").value, 0.0, 1e-8);
  EXPECT_NEAR(e.combinations.at("c_m+h_c").value, 0.4, 1e-8);
  EXPECT_NEAR(e.combinations.at("n-h_s").value, 0.0, 1e-8);
  for (const auto& kv : e.combinations) EXPECT_TRUE(std::isfinite(kv.second.std_error));
}

TEST(Identifiability, TwoPatternAnglesIdentifyEverything) {
  const Estimate e =
      identifyFreeDecay(std::vector<SlowRecord>{run(0.0), run(M_PI / 8)}, IdentificationOptions());
  EXPECT_EQ(e.rank, 8);
  EXPECT_TRUE(e.unidentifiable.empty());
  EXPECT_TRUE(e.identifiability_note.empty());
  for (const auto& kv : kTruth)
    EXPECT_NEAR(e.parameters.at(kv.first).value, kv.second, 1e-6 * std::fabs(kv.second))
        << kv.first;
}

}  // namespace
}  // namespace cvg_bench
