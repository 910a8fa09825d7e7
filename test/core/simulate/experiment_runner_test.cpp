// The simulated experiments: free decay starts from the stationary forced oscillation; sweep steps
// are stationary; a strongly nonlinear (Duffing) sweep jumps at the analytic folds, with hysteresis
// between up- and down-sweep; seeded noise is bit-identical per seed and has the requested std.
#include "cvg_bench/core/simulate/experiment_runner.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/orbit_elements.h"

namespace cvg_bench {
namespace {

ResonatorPreset memsRing() {
  return loadShippedPreset("mems_ring");
}

TEST(ExperimentRunner, FreeDecayStartsFromTheStationaryForcedOscillation) {
  const ResonatorPreset p = memsRing();
  const ExperimentRunner runner(p);
  const double lambda = p.decay_drive_detuning_rad_s;
  const Eigen::Vector4d qs = runner.stationaryForcedState(lambda);
  const ResonatorModel forced(p.truthModelSpec(ExperimentMode::kForced), ExperimentMode::kForced);
  const Eigen::Vector4d rate =
      forced.slowDerivative(qs, SlowContext{0.0, p.mu}, p.truthParameters(forced),
                            detuningRate(p.omega_rad_s, p.omega_rad_s + lambda));
  EXPECT_LT(rate.norm(), 1e-9 * p.parameters.at("gamma") * qs.norm());
  const SlowRecord rec = runner.freeDecaySlow(0.1);
  ASSERT_EQ(rec.size(), 201u);  // 0.1 s at 2 kHz, both ends
  EXPECT_LT((rec.q.front() - runner.freeDecayInitialState()).norm(), 1e-15);
  // Controls off: the amplitude decays at about gamma / 2 (anisotropy changes it by < 10 %).
  const double decay = std::log(rec.q.front().norm() / rec.q.back().norm()) / 0.1;
  EXPECT_NEAR(decay, p.parameters.at("gamma") / 2, 0.1 * p.parameters.at("gamma") / 2);
}

// A free decay started from chosen orbit elements: the first slow sample has them (the averaged
// model), the full equations start at the same osculating state (f(0) = q1, g(0) = q2 at t = 0),
// and the elements are written to the metadata; impossible elements are refused.
TEST(ExperimentRunner, FreeDecayCanStartFromChosenOrbitElements) {
  const ResonatorPreset p = memsRing();
  SimulationOptions o;
  o.mode = ExperimentMode::kFreeDecay;
  o.noise_std = 0.0;
  o.free_decay_start.r = 0.5;
  o.free_decay_start.k = 0.1;
  o.free_decay_start.theta = 0.3;
  const SlowRecord slow = simulateExperiment(p, o).slow;
  const OrbitElements e = orbitFromSlow(slow.q.front());
  EXPECT_NEAR(e.r, 0.5, 1e-12);
  EXPECT_NEAR(e.k, 0.1, 1e-12);
  EXPECT_NEAR(e.theta, 0.3, 1e-12);
  EXPECT_EQ(slow.metadata.count("free_decay_start"), 1u);
  EXPECT_EQ(slow.metadata.count("drive_detuning_rad_s"), 0u);
  o.raw = true;
  o.duration_s = 0.01;
  const RawRecord raw = simulateExperiment(p, o).raw;
  const Eigen::Vector4d q0 = slowFromOrbit(o.free_decay_start);
  EXPECT_NEAR(raw.f.front(), q0[0], 1e-12);
  EXPECT_NEAR(raw.g.front(), q0[2], 1e-12);
  o.free_decay_start.k = 0.6;  // |k| > r: no such orbit
  EXPECT_THROW(simulateExperiment(p, o), InputError);
  o.free_decay_start.k = 0.1;
  o.free_decay_start.theta = std::nan("");
  EXPECT_THROW(simulateExperiment(p, o), InputError);
}

TEST(ExperimentRunner, PaperRingSweepIsStationaryWithoutJumps) {
  const ResonatorPreset p = memsRing();
  const SweepResult sweep = ExperimentRunner(p).forcedSweep();
  ASSERT_EQ(sweep.steps.size(), 61u);
  EXPECT_EQ(sweep.n_jumps, 0);  // the paper's ring: backbone shift 3 xi / 8 < half-width gamma / 2
  EXPECT_EQ(sweep.n_unsettled, 0);
  const ResonatorModel forced(p.truthModelSpec(ExperimentMode::kForced), ExperimentMode::kForced);
  double peak = 0.0, edge = 0.0;
  for (const auto& s : sweep.steps) {
    const Eigen::Vector4d rate =
        forced.slowDerivative(s.q, SlowContext{0.0, p.mu}, p.truthParameters(forced),
                              detuningRate(p.omega_rad_s, s.omega0_rad_s));
    EXPECT_LT(rate.norm(), 1e-9 * s.q.norm());
    peak = std::max(peak, s.q.norm());
  }
  edge = std::max(sweep.steps.front().q.norm(), sweep.steps.back().q.norm());
  EXPECT_GT(peak, 0.8);         // normalized amplitudes, ~1 at resonance
  EXPECT_LT(edge, 0.3 * peak);  // the 61 points span the peak
}

/// Single-mode Duffing resonator: 2 a' = -gamma a + i (2 lambda - c_m + (3/4) xi |a|^2) a + u
/// (a = q1 + i p1; (2.5) with the cubic average of docs/paper.md item 1), stationary amplitude s =
/// |a|^2: k^2 s^3 + 2 d k s^2 + (gamma^2 + d^2) s - |u|^2 = 0, d = 2 lambda - c_m, k = 3 xi / 4.
/// Bistable where the cubic has three real roots (discriminant > 0).
bool duffingBistable(double lambda, double gamma, double c_m, double xi, double u) {
  const double d = 2 * lambda - c_m, k = 0.75 * xi;
  const double a = k * k, b = 2 * d * k, c = gamma * gamma + d * d, e = -u * u;
  const double disc = 18 * a * b * c * e - 4 * b * b * b * e + b * b * c * c - 4 * a * c * c * c -
                      27 * a * a * e * e;
  return disc > 0;
}

TEST(ExperimentRunner, DuffingSweepJumpsAtTheFoldsWithHysteresis) {
  ResonatorPreset p = memsRing();
  const double gamma = 43.0, c_m = 24.0, xi = 400.0, u1 = 32.0, u2 = 30.0;
  p.parameters = {{"gamma", gamma}, {"c_m", c_m}, {"xi", xi}};
  p.drive_u_tilde = Eigen::Vector4d(u1, u2, 0, 0);
  p.sweep_lambda_min_rad_s = -300;
  p.sweep_lambda_max_rad_s = 300;
  p.sweep_points = 61;  // 10 rad/s steps
  p.sweep_down = true;
  // Analytic bistable interval [fold_low, fold_high] (backbone bends to lambda < 0 for xi > 0).
  double fold_low = NAN, fold_high = NAN;
  for (double l = -300; l <= 300; l += 0.01) {
    if (!duffingBistable(l, gamma, c_m, xi, std::hypot(u1, u2))) continue;
    if (std::isnan(fold_low)) fold_low = l;
    fold_high = l;
  }
  ASSERT_FALSE(std::isnan(fold_low));
  ASSERT_GT(fold_high - fold_low, 30.0);  // several sweep steps wide
  const SweepResult sweep = ExperimentRunner(p).forcedSweep();
  ASSERT_EQ(sweep.steps.size(), 122u);
  ASSERT_EQ(sweep.n_jumps, 2);
  for (const auto& s : sweep.steps) {
    if (!s.jump) continue;
    if (s.direction > 0) {
      // Up-sweep: the low branch ends at the upper fold; the first step beyond it jumps up.
      EXPECT_GE(s.lambda_rad_s, fold_high);
      EXPECT_LT(s.lambda_rad_s, fold_high + 10.0);
    } else {
      // Down-sweep: the high branch ends at the lower fold.
      EXPECT_LE(s.lambda_rad_s, fold_low);
      EXPECT_GT(s.lambda_rad_s, fold_low - 10.0);
    }
  }
  ASSERT_TRUE(sweep.has_hysteresis);
  EXPECT_GE(sweep.hysteresis_lambda_min_rad_s, fold_low);
  EXPECT_LE(sweep.hysteresis_lambda_max_rad_s, fold_high);
  EXPECT_GT(sweep.hysteresis_lambda_max_rad_s - sweep.hysteresis_lambda_min_rad_s, 20.0);
}

TEST(ExperimentRunner, SeededNoiseIsBitIdenticalAndHasTheRequestedStd) {
  const ResonatorPreset p = memsRing();
  SimulationOptions o;
  o.seed = 7;
  const AnyRecord a = simulateExperiment(p, o), b = simulateExperiment(p, o);
  ASSERT_EQ(a.kind, RecordKind::kFreeDecay);
  ASSERT_EQ(a.slow.size(), b.slow.size());
  for (size_t k = 0; k < a.slow.size(); ++k) ASSERT_EQ(a.slow.q[k], b.slow.q[k]);
  o.seed = 8;
  const AnyRecord c = simulateExperiment(p, o);
  EXPECT_NE(a.slow.q[5], c.slow.q[5]);
  o.noise_std = 0.0;
  const AnyRecord clean = simulateExperiment(p, o);
  double sum_sq = 0.0;
  size_t n = 0;
  for (size_t k = 0; k < a.slow.size(); ++k, n += 4)
    sum_sq += (a.slow.q[k] - clean.slow.q[k]).squaredNorm();
  // n = 1604 draws: the sample std is within 6 % (3.4 standard errors of 1/sqrt(2n)).
  EXPECT_NEAR(std::sqrt(sum_sq / n), p.noise_q_std, 0.06 * p.noise_q_std);
  EXPECT_EQ(a.slow.metadata.at("seed"), "7");
}

// cm_rate (frequency drift during the record) starts at t = 0 of the free decay: the forced
// pre-drive ignores it, and by (5.10) it only advances the phase: chi gains cm_rate T^2 / 4 over
// [0, T].
TEST(ExperimentRunner, FrequencyDriftActsOnlyDuringTheFreeDecay) {
  ResonatorPreset drifting = memsRing();
  drifting.applyEffect("cm_rate=100");
  const ResonatorPreset steady = memsRing();
  const double duration = 0.1;
  const SlowRecord a = ExperimentRunner(drifting).freeDecaySlow(duration);
  const SlowRecord b = ExperimentRunner(steady).freeDecaySlow(duration);
  EXPECT_LT((a.q.front() - b.q.front()).norm(), 1e-15);
  const OrbitElements ea = orbitFromSlow(a.q.back()), eb = orbitFromSlow(b.q.back());
  EXPECT_NEAR(ea.r, eb.r, 1e-6 * eb.r);
  EXPECT_NEAR(std::remainder(ea.chi - eb.chi, 2 * M_PI), 100.0 * duration * duration / 4, 1e-5);
  SimulationOptions forced;
  forced.mode = ExperimentMode::kForced;
  EXPECT_THROW(simulateExperiment(drifting, forced), InputError);
}

TEST(ExperimentRunner, MetadataCarryTheTruth) {
  ResonatorPreset p = memsRing();
  p.applyEffect("kappa=0.5");
  SimulationOptions o;
  o.mode = ExperimentMode::kForced;
  const AnyRecord r = simulateExperiment(p, o);
  ASSERT_EQ(r.kind, RecordKind::kForcedSweep);
  const auto& md = r.sweep.metadata;
  EXPECT_EQ(md.at("truth_model"), "linear+xi+kappa");
  EXPECT_EQ(std::stod(md.at("truth_gamma")), 43.029);
  EXPECT_EQ(std::stod(md.at("truth_kappa")), 0.5);
  EXPECT_EQ(std::stod(md.at("truth_u1")), 32.159);
  EXPECT_EQ(std::stod(md.at("omega")), 85732.0);
  EXPECT_EQ(md.at("mode"), "forced");
  EXPECT_EQ(r.sweep.jump.size(), 61u);
}

TEST(ExperimentRunner, RawRecords) {
  ResonatorPreset p = memsRing();
  p.sweep_points = 3;
  SimulationOptions o;
  o.raw = true;
  o.duration_s = 0.002;
  const AnyRecord fd = simulateExperiment(p, o);
  ASSERT_EQ(fd.kind, RecordKind::kRaw);
  EXPECT_EQ(fd.raw.size(), 601u);  // 0.002 s at 300 kHz, both ends
  o.mode = ExperimentMode::kForced;
  const AnyRecord fr = simulateExperiment(p, o);
  ASSERT_EQ(fr.kind, RecordKind::kRaw);
  EXPECT_EQ(fr.raw.size(), 3u * 600u);
  EXPECT_EQ(fr.raw.extra.at("omega0").front(), p.omega_rad_s + p.sweep_lambda_min_rad_s);
  EXPECT_EQ(fr.raw.extra.at("omega0").back(), p.omega_rad_s + p.sweep_lambda_max_rad_s);
  for (size_t k = 1; k < fr.raw.size(); ++k) ASSERT_GT(fr.raw.t_s[k], fr.raw.t_s[k - 1]);
  // The parametric terms exist only in the full equations: a slow forced sweep refuses them.
  p.eta = 1e6;
  o.raw = false;
  EXPECT_THROW(simulateExperiment(p, o), InputError);
}

}  // namespace
}  // namespace cvg_bench
