// The free-decay fitter's cheap (equation-error) fits come from the triangular factor of the
// widest system: the same LS solution and residual sum as the stacked system of (2.8) of each
// nested model, and per-equation residuals only where the subset search reads them.
#include "cvg_bench/core/diagnose/nested_model_fitters.h"

#include <gtest/gtest.h>

#include <Eigen/QR>

#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/experiment_runner.h"

namespace cvg_bench {
namespace {

SlowRecord cubicDecay() {
  ResonatorPreset p = loadShippedPreset("mems_ring");
  p.applyEffect("xi", 2.0e-3);
  SimulationOptions o;
  o.seed = 4321;
  return simulateExperiment(p, o).slow;
}

/// The stacked system's LS (column-equilibrated pivoted QR), computed directly.
struct Direct {
  Eigen::VectorXd z;
  double rss = 0.0;
};
Direct directLs(const SlowRecord& record, const std::vector<std::string>& ext) {
  IdentificationOptions o;
  o.model = ResonatorModel(ext, ExperimentMode::kFreeDecay).spec();
  const StackedSystem sys = buildFreeDecaySystem({record}, o);
  const Eigen::VectorXd norms = sys.d.colwise().norm().transpose();
  const Eigen::MatrixXd scaled = sys.d * norms.cwiseInverse().asDiagonal();
  Direct d;
  d.z = scaled.colPivHouseholderQr().solve(sys.y).cwiseQuotient(norms);
  d.rss = (sys.y - sys.d * d.z).squaredNorm();
  return d;
}

TEST(NestedModelFitters, CheapFitsFromTheWidestFactorEqualTheStackedLs) {
  const SlowRecord record = cubicDecay();
  NestedFitterOptions options;
  const auto fitter = makeFreeDecayFitter(record, options);
  const std::vector<std::vector<std::string>> order = {
      {}, {"xi", "kappa", "gamma_nl", "cm_rate"}, {"xi"}, {"kappa", "cm_rate"}, {"gamma_nl"}};
  for (const auto& ext : order) {
    const NestedFit f = fitter->fitEquationError(ext);
    const Direct d = directLs(record, ext);
    ASSERT_EQ(f.estimate.values.size(), d.z.size());
    EXPECT_NEAR(f.rss, d.rss, 1e-9 * d.rss) << f.model;
    EXPECT_LT((f.estimate.values - d.z).norm(), 1e-7 * d.z.norm()) << f.model;
    EXPECT_EQ(f.n_equations, 4 * static_cast<long>(record.size() - 2));
    // Residuals for the linear model and the widest fit; not for strict subsets of the widest.
    const bool expect_residuals = ext.empty() || ext.size() == 4;
    EXPECT_EQ(f.residuals.size() > 0, expect_residuals) << f.model;
    if (expect_residuals) {
      EXPECT_NEAR(f.residuals.squaredNorm(), d.rss, 1e-9 * d.rss);
    }
  }
  // A term outside the factor widens it and still matches.
  const NestedFit wider = fitter->fitEquationError({"xi", "xi_diff"});
  EXPECT_NEAR(wider.rss, directLs(record, {"xi", "xi_diff"}).rss, 1e-9 * wider.rss);
}

}  // namespace
}  // namespace cvg_bench

namespace cvg_bench {
namespace {

// The adequacy residuals' radial part is taken along the model's state: along the measured q it
// would have the mean 3 sigma^2 / |q| (e.q_meas = e.q_model + |e|^2), a smooth trend as the decay
// lowers |q| that the low-frequency test of a long record detects although the model is right.
TEST(NestedModelFitters, AdequacyRadialResidualsHaveNoNoiseBias) {
  ResonatorPreset p = loadShippedPreset("mems_ring");
  p.applyEffect("xi", 2.0e-3);
  SimulationOptions o;
  o.seed = 99;
  o.noise_std = 0.02;
  const SlowRecord record = simulateExperiment(p, o).slow;
  const auto fitter = makeFreeDecayFitter(record, NestedFitterOptions());
  const NestedFit fit = fitter->fit({"xi"});
  ASSERT_EQ(fit.estimate.method, "ceres");
  const std::vector<BlockResidual> blocks = fitter->adequacyResiduals(fit);
  double sum = 0.0, sum2 = 0.0, biased = 0.0;
  for (const auto& b : blocks) {
    sum += b.radial;
    sum2 += b.radial * b.radial;
    const Eigen::Vector4d measured = b.q + b.e;
    biased += b.e.dot(measured) / measured.norm();
  }
  const double n = static_cast<double>(blocks.size());
  const double se = std::sqrt(sum2 / n) / std::sqrt(n);
  EXPECT_LT(std::abs(sum / n), 3.0 * se);
  EXPECT_GT(biased / n, 5.0 * se);  // the statistic on the measured q: biased, seen here
}

}  // namespace
}  // namespace cvg_bench
