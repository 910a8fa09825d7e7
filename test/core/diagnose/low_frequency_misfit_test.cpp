// Known answers of explain's structured adequacy test (low_frequency_misfit.h) and of the noise
// model fitted after the smooth part is removed (residual_noise_model.h): it holds its level on
// AR(1) rho = 0.9 noise and on a clean raw record with coloured (narrow-band) noise through the
// demodulator, and it is not fooled into whitening a smooth misfit away.
#include "cvg_bench/core/diagnose/low_frequency_misfit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/core/diagnose/explanation.h"
#include "cvg_bench/core/diagnose/residual_noise_model.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/experiment_runner.h"

namespace cvg_bench {
namespace {

/// n values of stationary AR(1) noise with marginal std sigma.
std::vector<double> ar1(std::mt19937_64* rng, int n, double rho, double sigma) {
  std::normal_distribution<double> normal(0.0, sigma);
  std::vector<double> x(n);
  double v = normal(*rng);
  for (int i = 0; i < n; ++i) {
    x[i] = v;
    v = rho * v + std::sqrt(1.0 - rho * rho) * normal(*rng);
  }
  return x;
}

std::vector<double> times(int n) {
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = 0.05 * i;
  return t;
}

// Level: 300 AR(1) rho = 0.9 records of 1,000 samples; the 1 % test rejects 1 % +- its binomial
// spread (Wilson 99 % interval of 3 / 300 is 0.3-4 %): at most 12 rejections.
TEST(LowFrequencyMisfit, HoldsItsLevelOnAr1Noise) {
  std::mt19937_64 rng(201);
  const std::vector<double> t = times(1000);
  int rejected = 0;
  for (int r = 0; r < 300; ++r)
    rejected += lowFrequencyPValue(ar1(&rng, 1000, 0.9, 1.0), t, {}, {}) < 0.01;
  EXPECT_LE(rejected, 12);
}

// Power: the same noise plus a smooth misfit of 4 noise std at its start (a decaying, curved
// residual, as a missing amplitude-dependent term leaves) is found in every record, and the fitted
// rho stays at the noise's 0.9 instead of being driven to the cap.
TEST(LowFrequencyMisfit, FindsASmoothMisfitInAr1Noise) {
  std::mt19937_64 rng(202);
  const std::vector<double> t = times(1000);
  for (int r = 0; r < 20; ++r) {
    std::vector<double> x = ar1(&rng, 1000, 0.9, 1.0);
    for (size_t i = 0; i < x.size(); ++i) x[i] += 4.0 * std::exp(-t[i] / 15.0) * std::cos(t[i] / 8);
    double rho = 0.0;
    bool capped = true;
    EXPECT_LT(lowFrequencyPValue(x, t, {}, {}, &rho, &capped), 0.01);
    EXPECT_NEAR(rho, 0.9, 0.07);
    EXPECT_FALSE(capped);
  }
}

// The noise model of 4 channels of AR(1) 0.9 plus a large curved misfit: rho ~ 0.9 after the
// smooth part is removed, where the lag-1 correlation of the raw residuals is ~1.
TEST(LowFrequencyMisfit, NoiseModelIgnoresTheSmoothPart) {
  std::mt19937_64 rng(203);
  const int n = 2000;
  Eigen::VectorXd r(4 * n);
  for (int c = 0; c < 4; ++c) {
    const std::vector<double> x = ar1(&rng, n, 0.9, 1.0);
    for (int i = 0; i < n; ++i) r[4 * i + c] = x[i] + 30.0 * std::pow(2.0 * i / n - 1.0, 2);
  }
  const ResidualNoiseModel m = noiseModelFromDetrendedResiduals(r, 4);
  EXPECT_NEAR(m.rho1, 0.9, 0.03) << m.description;
  // Noise more correlated than the ceiling is capped (and treated as misfit).
  for (int c = 0; c < 4; ++c) {
    const std::vector<double> x = ar1(&rng, n, 0.995, 1.0);
    for (int i = 0; i < n; ++i) r[4 * i + c] = x[i];
  }
  EXPECT_DOUBLE_EQ(noiseModelFromDetrendedResiduals(r, 4).rho1, 0.95);
}

// A clean raw record of the full equations with narrow-band noise around the carrier
// (a cos(omega t) + b sin(omega t), a and b AR(1) rho = 0.9 per raw sample: coloured after
// demodulation, beyond the demodulator's stated correlation) is explained by the linear model
// and called adequate.
TEST(LowFrequencyMisfit, CleanRawRecordWithColouredNoiseIsAdequate) {
  ResonatorPreset p = loadShippedPreset("mems_ring");
  p.applyEffect("xi", 0.0);
  SimulationOptions o;
  o.raw = true;
  o.seed = 204;
  o.noise_std = 0.0;
  AnyRecord raw = simulateExperiment(p, o);
  double amp = 0.0;
  for (size_t i = 0; i < raw.raw.size(); ++i)
    amp = std::max(amp, std::hypot(raw.raw.f[i], raw.raw.g[i]));
  std::mt19937_64 rng(204);
  const int n = static_cast<int>(raw.raw.size());
  const double sigma = 2e-3 * amp, w = raw.raw.omega_rad_s;
  const std::vector<double> a = ar1(&rng, n, 0.9, sigma), b = ar1(&rng, n, 0.9, sigma),
                            c = ar1(&rng, n, 0.9, sigma), d = ar1(&rng, n, 0.9, sigma);
  for (int i = 0; i < n; ++i) {
    const double ct = std::cos(w * raw.raw.t_s[i]), st = std::sin(w * raw.raw.t_s[i]);
    raw.raw.f[i] += a[i] * ct + b[i] * st;
    raw.raw.g[i] += c[i] * ct + d[i] * st;
  }
  DemodulatorOptions dm;
  dm.output_rate_hz = 2000.0;
  const SlowRecord rec = demodulateUniform(raw.raw, dm);
  const Explanation x = explainFreeDecay(rec, ExplainOptions());
  EXPECT_TRUE(x.selection.selected.empty()) << x.cause;
  EXPECT_FALSE(x.unexplained) << x.cause;
  EXPECT_GT(x.lack_of_fit.low_frequency_p_value, 0.01) << x.lack_of_fit.low_frequency;
}

}  // namespace
}  // namespace cvg_bench
