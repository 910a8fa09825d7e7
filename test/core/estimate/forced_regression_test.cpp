// Forced-sweep identification (section 3) on stationary points of the paper's section-4 estimate.
#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/identification.h"
#include "identification_test_support.h"
#include "paper_section4_estimate.h"

namespace cvg_bench {
namespace {

constexpr double kOmega = testing_support::kSection4OmegaRadS;
const ParameterValues& kSection4 = testing_support::kSection4Estimate;

SweepRecord section4Sweep(int n = 61) {
  const ResonatorModel model("xi", ExperimentMode::kForced);
  std::vector<double> detunings;
  for (int j = 0; j < n; ++j) detunings.push_back(-80.0 + 160.0 * j / (n - 1));
  return testing_support::simulateSweep(model, model.parameterVector(kSection4), kOmega, detunings);
}

IdentificationOptions cubic() {
  IdentificationOptions o;
  o.model = "xi";
  return o;
}

TEST(ForcedIdentification, NoiselessSweepRecoversSection4) {
  const Estimate e = identifyForced(section4Sweep(), cubic());
  EXPECT_EQ(e.n_equations, 244);
  EXPECT_EQ(e.rank, 13);
  for (const auto& kv : kSection4)
    EXPECT_NEAR(e.parameters.at(kv.first).value, kv.second, 1e-8 * std::fabs(kv.second))
        << kv.first;
  EXPECT_NEAR(e.derived.at("Q").value, kOmega / 43.029, 1e-5);
  EXPECT_NEAR(e.derived.at("alpha_rad").value, 0.6015, 5e-4);
}

TEST(ForcedIdentification, NoisySweepIsCoveredByTheIntervals) {
  const SweepRecord clean = section4Sweep();
  int covered = 0, total = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Estimate e = identifyForced(testing_support::withNoise(clean, 3e-4, seed), cubic());
    testing_support::countCoverage(e, kSection4, &covered, &total);
  }
  const double coverage = static_cast<double>(covered) / total;
  EXPECT_GE(coverage, 0.85);
  EXPECT_LE(coverage, 0.995);
}

TEST(ForcedIdentification, BadInputIsAnInputError) {
  EXPECT_THROW(identifyForced(section4Sweep(3), cubic()), InputError);  // N < 4
  SweepRecord nan = section4Sweep(10);
  nan.q[3][1] = NAN;
  EXPECT_THROW(identifyForced(nan, cubic()), InputError);
  SweepRecord no_omega = section4Sweep(10);
  no_omega.omega_rad_s = 0.0;
  EXPECT_THROW(identifyForced(no_omega, cubic()), InputError);
  IdentificationOptions mu = cubic();
  mu.model = "xi+mu";
  try {
    identifyForced(section4Sweep(10), mu);
    FAIL() << "mu accepted by LS";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--method ceres"), std::string::npos);
  }
  IdentificationOptions drift = cubic();
  drift.model = "cm_rate";
  EXPECT_THROW(identifyForced(section4Sweep(10), drift), InputError);
}

TEST(ForcedIdentification, KnownMuEntersTheControlColumns) {
  const ResonatorModel model("xi", ExperimentMode::kForced);
  std::vector<double> det;
  for (int j = 0; j < 41; ++j) det.push_back(-60.0 + 3.0 * j);
  const SweepRecord rec =
      testing_support::simulateSweep(model, model.parameterVector(kSection4), kOmega, det, 0.05);
  IdentificationOptions o = cubic();
  o.mu = 0.05;
  const Estimate e = identifyForced(rec, o);
  for (const auto& kv : kSection4)
    EXPECT_NEAR(e.parameters.at(kv.first).value, kv.second, 1e-8 * std::fabs(kv.second))
        << kv.first;
}

}  // namespace
}  // namespace cvg_bench
