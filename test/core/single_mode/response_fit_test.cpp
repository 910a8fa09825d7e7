// The one-mode response fit and its selection against the time-integrated generator
// (response_simulator.h, which shares no code with the fit): f0, Q, backbone and width growth
// inside their intervals and near the truth, the lock-in's sign convention found, jumps
// reproduced, the right term selected and a saturating drive called unexplained.
#include <gtest/gtest.h>

#include "cvg_bench/core/simulate/response_simulator.h"
#include "cvg_bench/core/single_mode/response_explain.h"
#include "cvg_bench/core/single_mode/response_laws.h"

namespace cvg_bench {
namespace {

ResponseSimulatorOptions base(unsigned seed) {
  ResponseSimulatorOptions o;
  o.f0_hz = 100.0;
  o.q = 100.0;  // width 1 Hz
  o.levels = 3;
  o.points_per_sweep = 40;
  o.max_amplitude = 2e-6;  // any unit: the fit normalises
  o.noise = 0.004 * o.max_amplitude;
  o.background = {0.1 * o.max_amplitude, -0.05 * o.max_amplitude};
  o.seed = seed;
  return o;
}

void expectCovers(const ResponseFit& f, const std::string& key, double truth, double rel_tol) {
  const ResponseValue& v = f.derived.at(key);
  EXPECT_LE(v.ci_low, truth) << key;
  EXPECT_GE(v.ci_high, truth) << key;
  EXPECT_NEAR(v.value / truth, 1.0, rel_tol) << key;
}

TEST(ResponseFit, LinearRecordGivesF0AndQWithHonestIntervals) {
  for (bool conj : {false, true}) {
    ResponseSimulatorOptions o = base(11);
    o.conjugate = conj;
    const ResponseRecord r = simulateResponse(o);
    ResponseFitOptions fo;
    const ResponseFit f = fitResponse(responseDataOf(r, fo.kind), ResponseTerms{}, fo);
    EXPECT_EQ(f.conjugated, conj);
    EXPECT_EQ(f.n_sweeps, 6);
    EXPECT_EQ(f.n_drive_levels, 3);
    expectCovers(f, "f0_hz", 100.0, 1e-3);
    expectCovers(f, "Q", 100.0, 0.02);
    EXPECT_NE(f.interval_method.find("jackknife"), std::string::npos);
    EXPECT_EQ(f.jumps, 0);
  }
}

// The start grid's sizes are options: a coarser grid (two passes, 11 x 11 after the first) still
// starts the fit in the right basin on a clean linear record.
TEST(ResponseFit, CoarserStartGridStillFindsTheResonance) {
  const ResponseRecord r = simulateResponse(base(11));
  ResponseFitOptions fo;
  fo.grid_passes = 2;
  fo.grid_later_frequencies = 11;
  fo.grid_later_widths = 11;
  const ResponseFit f = fitResponse(responseDataOf(r, fo.kind), ResponseTerms{}, fo);
  expectCovers(f, "f0_hz", 100.0, 1e-3);
  expectCovers(f, "Q", 100.0, 0.02);
}

TEST(ResponseFit, VelocityResponseOfALowQMode) {
  ResponseSimulatorOptions o = base(12);
  o.q = 30.0;
  o.kind = ResponseKind::kVelocity;
  const ResponseRecord r = simulateResponse(o);
  ResponseFitOptions fo;
  fo.kind = ResponseKind::kVelocity;
  const ResponseFit f = fitResponse(responseDataOf(r, fo.kind), ResponseTerms{}, fo);
  expectCovers(f, "Q", 30.0, 0.02);
  expectCovers(f, "f0_hz", 100.0, 1e-3);
}

TEST(ResponseFit, SofteningBackboneWithJumpsAndHysteresis) {
  ResponseSimulatorOptions o = base(13);
  const double u_max = o.max_amplitude * o.max_amplitude;
  o.backbone_hz_per_amp2 = -2.5 / u_max;  // 2.5 widths at the top level: bistable
  const ResponseRecord r = simulateResponse(o);
  ResponseFitOptions fo;
  ResponseTerms t;
  t.backbone = true;
  const ResponseFit f = fitResponse(responseDataOf(r, fo.kind), t, fo);
  expectCovers(f, "backbone_hz_per_amp2", o.backbone_hz_per_amp2, 0.05);
  expectCovers(f, "Q", 100.0, 0.05);
  EXPECT_GE(f.jumps, 2);  // the top level's up and down sweeps
  EXPECT_TRUE(f.not_determined.empty()) << f.not_determined.front();
}

TEST(ResponseExplain, SelectsTheTermTheRecordHas) {
  ResponseExplainOptions xo;
  {
    const ResponseRecord r = simulateResponse(base(21));
    const ResponseExplanation x = explainResponse(responseDataOf(r, xo.fit.kind), xo);
    EXPECT_EQ(x.selected, "linear");
    EXPECT_FALSE(x.unexplained) << x.adequacy_ratio;
    // Every combination of the registry's terms is a candidate, with its terms' keys and p values.
    const std::vector<ResponseTerms> all = responseTermCombinations();
    ASSERT_EQ(x.candidates.size(), all.size());
    for (size_t i = 0; i < all.size(); ++i) {
      const ResponseCandidate& c = x.candidates[i];
      EXPECT_EQ(c.fit.terms.name(), all[i].name());
      for (const ResponseLaw& law : responseLaws()) {
        const bool has = all[i].*law.flag;
        EXPECT_EQ(c.fit.derived.count(law.derived_key), has ? 1u : 0u) << c.fit.terms.name();
        EXPECT_EQ(c.p_values.count(law.name), has ? 1u : 0u) << c.fit.terms.name();
        EXPECT_EQ(c.effect_over_width.count(law.name), has ? 1u : 0u) << c.fit.terms.name();
        if (law.model_term_key) {
          EXPECT_EQ(c.fit.derived.count(law.model_term_key), has ? 1u : 0u) << law.model_term_key;
        }
      }
    }
  }
  {
    ResponseSimulatorOptions o = base(22);
    o.width_growth_hz_per_amp2 = 1.0 / (o.max_amplitude * o.max_amplitude);  // width doubles
    const ResponseRecord r = simulateResponse(o);
    const ResponseExplanation x = explainResponse(responseDataOf(r, xo.fit.kind), xo);
    EXPECT_EQ(x.selected, "gamma_nl") << x.verdict;
    EXPECT_FALSE(x.unexplained);
    EXPECT_NE(x.verdict.find("width grows"), std::string::npos);
  }
  {
    ResponseSimulatorOptions o = base(23);
    o.saturation_amplitude = 0.3 * o.max_amplitude;  // the drive stops acting: no amplitude law
    const ResponseRecord r = simulateResponse(o);
    const ResponseExplanation x = explainResponse(responseDataOf(r, xo.fit.kind), xo);
    EXPECT_TRUE(x.unexplained) << x.verdict;
    EXPECT_GT(x.adequacy_ratio, xo.adequacy_threshold);
  }
}

}  // namespace
}  // namespace cvg_bench
