// Known answers of explain's best-subset selection and of its calibrated adequacy test
// (forward_selection.h, residual_noise_model.h): two effects acting together are found as a pair,
// a clean record selects nothing, and clean records with AR(1) rho = 0.9 noise or through the
// demodulator are called adequate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/core/diagnose/explanation.h"
#include "cvg_bench/core/diagnose/residual_noise_model.h"
#include "cvg_bench/core/estimate/uncertainty/long_run_variance.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/experiment_runner.h"

namespace cvg_bench {
namespace {

struct Effect {
  std::string name;
  double value;
};

// mems_ring with its own cubic stiffness off, so "clean" means the linear model.
ResonatorPreset preset(const std::vector<Effect>& effects) {
  ResonatorPreset p = loadShippedPreset("mems_ring");
  p.applyEffect("xi", 0.0);
  for (const auto& e : effects) p.applyEffect(e.name, e.value);
  return p;
}

SlowRecord freeDecay(const std::vector<Effect>& effects, uint64_t seed, double noise_std = -1.0) {
  SimulationOptions o;
  o.seed = seed;
  o.noise_std = noise_std;
  return simulateExperiment(preset(effects), o).slow;
}

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Cubic and quintic stiffness together (magnitudes of hidden_effect_test.cpp's library): nearly
// collinear in a decay (amplitude^2 and amplitude^4 both fall), found as a pair.
TEST(SubsetSelection, FreeDecayFindsCubicAndQuinticStiffnessTogether) {
  const SlowRecord rec = freeDecay({{"xi", 30.0}, {"kappa", 30.0}}, 101);
  const Explanation x = explainFreeDecay(rec, ExplainOptions());
  EXPECT_EQ(sorted(x.selection.selected), (std::vector<std::string>{"kappa", "xi"})) << x.cause;
  EXPECT_FALSE(x.unexplained) << x.cause;
  const auto& p = x.finalEstimate().parameters;
  EXPECT_NEAR(p.at("xi").value, 30.0, 4 * p.at("xi").std_error) << x.cause;
  EXPECT_NEAR(p.at("kappa").value, 30.0, 4 * p.at("kappa").std_error) << x.cause;
  // The runner-up is another subset, worse by a positive criterion difference.
  EXPECT_FALSE(x.selection.runner_up.model.empty());
  EXPECT_NE(x.selection.runner_up.model, x.selection.chosen.model);
  EXPECT_GT(x.selection.runner_up_delta, 0.0);
  EXPECT_NE(x.cause.find("Runner-up"), std::string::npos);
}

TEST(SubsetSelection, FreeDecayFindsCubicStiffnessWithNonlinearDamping) {
  const SlowRecord rec = freeDecay({{"xi", 30.0}, {"gamma_nl", 12.0}}, 102);
  const Explanation x = explainFreeDecay(rec, ExplainOptions());
  EXPECT_EQ(sorted(x.selection.selected), (std::vector<std::string>{"gamma_nl", "xi"})) << x.cause;
  EXPECT_FALSE(x.unexplained) << x.cause;
}

TEST(SubsetSelection, CleanFreeDecaySelectsNothing) {
  const Explanation x = explainFreeDecay(freeDecay({}, 103), ExplainOptions());
  EXPECT_TRUE(x.selection.selected.empty()) << x.cause;
  EXPECT_FALSE(x.unexplained) << x.cause;
  EXPECT_EQ(x.selection.chosen.model, "linear");
  EXPECT_GT(x.selection.runner_up_delta, 0.0);
}

// Clean record, noise AR(1) rho = 0.9 on each slow variable at the preset's std (1e-3).
TEST(SubsetSelection, CleanFreeDecayWithAr1NoiseIsAdequate) {
  SlowRecord rec = freeDecay({}, 104, 0.0);
  std::mt19937_64 rng(104);
  std::normal_distribution<double> normal(0.0, 1e-3);
  const double rho = 0.9;
  Eigen::Vector4d n;
  for (int c = 0; c < 4; ++c) n[c] = normal(rng);
  for (auto& q : rec.q) {
    q += n;
    for (int c = 0; c < 4; ++c) n[c] = rho * n[c] + std::sqrt(1 - rho * rho) * normal(rng);
  }
  const Explanation x = explainFreeDecay(rec, ExplainOptions());
  EXPECT_TRUE(x.selection.selected.empty()) << x.cause;
  EXPECT_FALSE(x.unexplained) << x.cause;
  // The variogram-ratio noise model recovers rho.
  EXPECT_NEAR(x.noise_model.rho1, 0.9, 0.05) << x.noise_model.description;
  // Without whitening the runs test would call it structured.
  EXPECT_LT(x.lack_of_fit.p_value_unwhitened, 0.01);
}

// Clean raw f, g of the full equations through the tool's own demodulator (2 kHz slow rate): the
// record's noise_correlation whitens the residuals.
TEST(SubsetSelection, CleanDemodulatedRawFreeDecayIsAdequate) {
  SimulationOptions o;
  o.raw = true;
  o.seed = 105;
  const AnyRecord raw = simulateExperiment(preset({}), o);
  DemodulatorOptions d;
  d.output_rate_hz = 2000.0;
  const SlowRecord rec = demodulateUniform(raw.raw, d);
  ASSERT_TRUE(rec.metadata.count("noise_correlation"));
  const Explanation x = explainFreeDecay(rec, ExplainOptions());
  EXPECT_TRUE(x.selection.selected.empty()) << x.cause;
  EXPECT_FALSE(x.unexplained) << x.cause;
  EXPECT_NE(x.noise_model.description.find("known noise correlation"), std::string::npos);
}

TEST(SubsetSelection, OptionsValidateTheReplacementCap) {
  SelectionOptions o;
  EXPECT_TRUE(o.validate().empty());
  EXPECT_EQ(o.max_tried_per_finalist, 2);
  o.max_tried_per_finalist = 0;
  EXPECT_EQ(o.validate().size(), 1u);
}

TEST(ResidualCorrelation, LongRunFactorOfAr1) {
  std::mt19937_64 rng(106);
  std::normal_distribution<double> normal;
  const double rho = 0.8;  // c = (1 + rho) / (1 - rho) = 9
  Eigen::VectorXd r(4 * 20000);
  Eigen::Vector4d n = Eigen::Vector4d::Zero();
  for (int i = 0; i < 20000; ++i) {
    for (int c = 0; c < 4; ++c) n[c] = rho * n[c] + normal(rng);
    r.segment<4>(4 * i) = n;
  }
  EXPECT_NEAR(longRunVarianceFactor(r, 4), 9.0, 1.0);
  EXPECT_NEAR(lagOneCorrelation(r, 4), 0.8, 0.02);
  EXPECT_DOUBLE_EQ(longRunVarianceFactor(std::vector<double>{0.5, 0.25}), 2.5);
  // The variogram ratio ignores a slow drift added to the noise; the lag-1 correlation does not.
  for (int i = 0; i < 20000; ++i) r.segment<4>(4 * i).array() += 20.0 * std::sin(i * 1e-3);
  EXPECT_GT(lagOneCorrelation(r, 4), 0.95);
  EXPECT_NEAR(noiseModelFromResiduals(r, 4).rho1, 0.8, 0.03);
}

TEST(ResidualNoiseModel, LevinsonRecoversAr2AndWhitens) {
  // AR(2): x_t = 0.5 x_{t-1} + 0.3 x_{t-2} + e: rho_1 = 0.5 / 0.7, rho_2 = 0.5 rho_1 + 0.3.
  const double r1 = 0.5 / 0.7, r2 = 0.5 * r1 + 0.3, r3 = 0.5 * r2 + 0.3 * r1;
  const ResidualNoiseModel m = noiseModelFromCorrelation({r1, r2, r3});
  ASSERT_EQ(m.ar.size(), 3u);
  EXPECT_NEAR(m.ar[0], 0.5, 1e-12);
  EXPECT_NEAR(m.ar[1], 0.3, 1e-12);
  EXPECT_NEAR(m.ar[2], 0.0, 1e-12);
  Eigen::VectorXd x(5);
  x << 1.0, 2.0, 0.0, -1.0, 3.0;
  const Eigen::VectorXd w = whiten(x, 1, m);
  EXPECT_DOUBLE_EQ(w[0], 1.0);
  EXPECT_NEAR(w[2], 0.0 - 0.5 * 2.0 - 0.3 * 1.0, 1e-12);
  EXPECT_NEAR(w[4], 3.0 - 0.5 * -1.0 - 0.3 * 0.0, 1e-12);
}

// Noise coloured beyond the known part: (1 - 0.4 L)(1 - 0.6 L) x = e, known rho_1 = 0.4 only. The
// AR(1) of what the known filter leaves is 0.6, and the composed filter is the AR(2) 1.0, -0.24.
TEST(ResidualNoiseModel, KnownThenFittedAr1ComposesTheFilters) {
  std::mt19937_64 rng(8201);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 20000;
  Eigen::VectorXd x(4 * n);
  for (int c = 0; c < 4; ++c) {
    double x1 = 0.0, x2 = 0.0;
    for (int t = 0; t < n; ++t) {
      const double v = 1.0 * x1 - 0.24 * x2 + g(rng);
      x[4 * t + c] = v;
      x2 = x1;
      x1 = v;
    }
  }
  const ResidualNoiseModel known = noiseModelFromCorrelation({0.4}, 1);
  ASSERT_EQ(known.ar.size(), 1u);
  const ResidualNoiseModel m = withDetrendedAr1(known, x, 4);
  ASSERT_EQ(m.ar.size(), 2u) << m.description;
  const double b = m.ar[0] - 0.4;
  EXPECT_NEAR(b, 0.6, 0.02) << m.description;
  EXPECT_NEAR(m.ar[1], -0.4 * b, 1e-12);
  EXPECT_NE(m.description.find("of what it leaves"), std::string::npos);
  // White beyond the known part: the known model unchanged.
  Eigen::VectorXd y(4 * n);
  for (int c = 0; c < 4; ++c) {
    double y1 = 0.0;
    for (int t = 0; t < n; ++t) y[4 * t + c] = y1 = 0.4 * y1 + g(rng);
  }
  EXPECT_EQ(withDetrendedAr1(known, y, 4).ar.size(), 1u);
}

}  // namespace
}  // namespace cvg_bench
