// Section 4 of the paper: from the printed cubic-model estimate, the derived quantities reproduce
// the printed figures (which are truncated, not rounded: docs/paper.md item 13).
#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/derived_quantities.h"
#include "paper_section4_estimate.h"

namespace cvg_bench {
namespace {

const ParameterValues& kSection4 = testing_support::kSection4Estimate;

TEST(Section4, DerivedQuantitiesReproduceThePaper) {
  const DerivedQuantities d = deriveQuantities(kSection4, 85732.0, 0.4);
  EXPECT_NEAR(d.Q, 1992.4, 0.05);
  EXPECT_NEAR(d.zero_rate_rad_s, 1.268, 0.0005);
  EXPECT_NEAR(d.frequency_error_rad_s, 12.179, 0.0005);
  EXPECT_NEAR(d.frequency_error_hz, 1.94, 0.005);
  EXPECT_NEAR(d.frequency_split_rad_s, 17.264, 0.0005);
  EXPECT_NEAR(d.frequency_split_hz, 2.748, 0.0005);
  EXPECT_NEAR(d.damping_anisotropy_1_s, 3.8489, 0.00005);
  EXPECT_NEAR(d.alpha_rad, 0.6015, 0.0005);
  EXPECT_NEAR(d.alpha_rad * 180 / M_PI, 34.46, 0.005);
  EXPECT_NEAR(d.beta_rad, -0.2016, 0.00005);
  EXPECT_NEAR(d.beta_rad * 180 / M_PI, -11.55, 0.005);
}

TEST(Section4, BadInputIsAClearError) {
  EXPECT_THROW(deriveQuantities(kSection4, 0.0, 0.4), InputError);
  EXPECT_THROW(deriveQuantities(kSection4, 85732.0, 0.0), InputError);
  EXPECT_THROW(deriveQuantities(kSection4, 85732.0, -1.0), InputError);
  EXPECT_THROW(deriveQuantities({{"gamma", NAN}}, 85732.0, 0.4), InputError);
  EXPECT_THROW(deriveQuantities({{"gamma", 0.0}}, 85732.0, 0.4), InputError);
}

TEST(ModelDefinition, BadSpecsAreClearErrors) {
  EXPECT_THROW(ResonatorModel("linear+bogus", ExperimentMode::kFreeDecay), InputError);
  EXPECT_THROW(ResonatorModel("xi+xi", ExperimentMode::kFreeDecay), InputError);
  EXPECT_THROW(ResonatorModel("cm_rate", ExperimentMode::kForced), InputError);
  EXPECT_THROW(ResonatorModel("mu", ExperimentMode::kFreeDecay), InputError);
  EXPECT_THROW(ResonatorModel("", ExperimentMode::kFreeDecay), InputError);
  EXPECT_THROW(parseExperimentMode("sweep"), InputError);
  const ResonatorModel m("linear+xi", ExperimentMode::kForced);
  EXPECT_EQ(m.numParameters(), 13);
  EXPECT_EQ(m.spec(), "linear+xi");
  EXPECT_EQ(m.indexOf("u1"), 8);
  EXPECT_EQ(m.indexOf("xi"), 12);
  EXPECT_THROW(m.parameterVector({{"gamma", INFINITY}}), InputError);
  EXPECT_THROW(m.parameterVector({{"kappa", 1.0}}, true), InputError);
}

}  // namespace
}  // namespace cvg_bench
