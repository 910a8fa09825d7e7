// The full-equation simulator: RK4 accuracy against the exact solution of a damped linear
// oscillator (fourth order, tiny phase error at 20 steps per period), agreement with the averaged
// model to first order in the small parameter (free decay and a forced stationary state, by exact
// whole-period demodulation inside the test), and the 2 omega0 parametric terms scaling as 1/eta.
#include "cvg_bench/core/simulate/full_equation_simulator.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/simulate/averaged_model_simulator.h"

namespace cvg_bench {
namespace {

/// Max |f - f_exact| over [0, T] for f'' + gamma f' + (omega^2 + omega c_m) f = 0, f(0) = 1, f'(0)
/// = 0.
double dampedOscillatorError(int steps_per_period) {
  const double omega = 100.0, gamma = 0.5, c_m = 0.3;
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = model.parameterVector({{"gamma", gamma}, {"c_m", c_m}});
  FullEquationSimulatorOptions o;
  o.steps_per_period = steps_per_period;
  FullEquationSimulator sim(model, z, omega, omega, 0.0, {}, o);
  sim.resetFast(FastState{1.0, 0.0, 0.0, 0.0}, 0.0);
  const double wd = std::sqrt(omega * omega + omega * c_m - gamma * gamma / 4);
  RawRecord rec;
  const double rate = omega / (2 * M_PI) * 5;  // 5 samples per period
  sim.sampleRaw(rate, static_cast<size_t>(10.0 * rate), rec);
  double err = 0.0;
  for (size_t k = 0; k < rec.size(); ++k) {
    const double t = rec.t_s[k];
    const double exact =
        std::exp(-gamma * t / 2) * (std::cos(wd * t) + gamma / (2 * wd) * std::sin(wd * t));
    err = std::max(err, std::abs(rec.f[k] - exact));
    EXPECT_EQ(rec.g[k], 0.0);
  }
  return err;
}

TEST(FullEquationSimulator, FourthOrderAccurateOnTheDampedLinearOscillator) {
  const double e20 = dampedOscillatorError(20);
  const double e40 = dampedOscillatorError(40);
  // 159 periods: the osculating variables carry only the small forces, so even 20 steps per
  // period give a tiny error (a phase error of 1e-6 rad after 159 periods).
  EXPECT_LT(e20, 1e-6);
  EXPECT_GT(e20 / e40, 12.0);  // RK4: halving the step divides the error by ~16
  EXPECT_LT(e20 / e40, 20.0);
}

TEST(FullEquationSimulator, FastStateRoundTripsThroughOsculatingVariables) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  FullEquationSimulator sim(model, Eigen::VectorXd::Zero(8), 50.0, 50.0);
  const FastState s{0.3, -4.0, -0.7, 12.0};
  sim.resetFast(s, 1.234);
  const FastState back = sim.fastState();
  EXPECT_NEAR(back.f, s.f, 1e-14);
  EXPECT_NEAR(back.f_dot, s.f_dot, 1e-12);
  EXPECT_NEAR(back.g, s.g, 1e-14);
  EXPECT_NEAR(back.g_dot, s.g_dot, 1e-12);
}

const ParameterValues kTruth = {{"gamma", 2.0}, {"nu", 0.5}, {"b_c", 0.2},  {"b_s", -0.1},
                                {"c_m", 1.5},   {"n", 0.3},  {"h_c", -0.8}, {"h_s", 0.6},
                                {"xi", 2.0},    {"u1", 2.0}, {"u2", 1.5},   {"u3", 0.2},
                                {"u4", -0.1}};

/// (2/P) * integral over one period of (f cos, f sin, g cos, g sin) at W, from samples of a whole
/// period on the step grid (the periodic trapezoid rule is exact for these harmonics).
Eigen::Vector4d demodulateOnePeriod(FullEquationSimulator& sim, int samples) {
  const double w = sim.reference(), period = 2 * M_PI / w;
  RawRecord rec;
  sim.sampleRaw(samples / period, samples, rec);
  Eigen::Vector4d acc = Eigen::Vector4d::Zero();
  for (int k = 0; k < samples; ++k) {
    const double c = std::cos(w * rec.t_s[k]), s = std::sin(w * rec.t_s[k]);
    acc +=
        (2.0 / samples) * Eigen::Vector4d(rec.f[k] * c, rec.f[k] * s, rec.g[k] * c, rec.g[k] * s);
  }
  return acc;
}

/// Max deviation of demodulated full equations from the averaged model over a free decay.
double freeDecayAveragingError(double omega) {
  const ResonatorModel model("xi", ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = model.parameterVector(kTruth);
  const Eigen::Vector4d q0(0.8, 0.3, -0.2, 0.4);
  FullEquationSimulator fast(model, z, omega, omega);
  fast.reset(q0, 0.0);
  AveragedModelSimulator slow(model, z);
  slow.reset(q0, 0.0);
  const double period = 2 * M_PI / omega;
  double err = 0.0;
  for (int i = 0; i < 40; ++i) {
    const double t_start = i * 0.05;
    fast.advanceTo(t_start);
    const Eigen::Vector4d demod = demodulateOnePeriod(fast, 40);
    slow.advanceTo(t_start + period / 2);  // the demodulated value belongs to mid-period
    err = std::max(err, (demod - slow.state()).cwiseAbs().maxCoeff());
  }
  return err;
}

TEST(FullEquationSimulator, TracksTheAveragedModelToFirstOrder) {
  const double coarse = freeDecayAveragingError(1000.0);
  const double fine = freeDecayAveragingError(4000.0);
  // Small parameter ~ |rates| / omega ~ 2e-3 at omega = 1000, amplitudes ~ 1.
  EXPECT_LT(coarse, 1e-2);
  EXPECT_GT(coarse / fine, 2.5);  // first order: 4x omega, about 4x smaller
  EXPECT_LT(coarse / fine, 6.0);
}

TEST(FullEquationSimulator, ForcedStationaryStateMatchesTheAveragedOne) {
  const double omega = 4000.0, lambda = 1.0;
  const ResonatorModel model("xi", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector(kTruth);
  AveragedModelSimulator slow(model, z, 0.0, detuningRate(omega, omega + lambda));
  slow.reset(Eigen::Vector4d::Zero(), 0.0);
  slow.advanceTo(30.0);  // 30 decay times 1 / gamma
  ASSERT_LT(slow.derivative().norm(), 1e-9);
  FullEquationSimulator fast(model, z, omega, omega + lambda);
  fast.reset(slow.state(), 0.0);
  fast.advanceTo(10.0);  // let the O(epsilon) transient of the full equations decay
  const Eigen::Vector4d demod = demodulateOnePeriod(fast, 40);
  EXPECT_LT((demod - slow.state()).norm(), 5e-3 * slow.state().norm());
}

/// Demodulated forced stationary state of the full equations with the parametric terms at eta.
Eigen::Vector4d forcedStateWithPumping(double eta) {
  const double omega = 2000.0;
  const ResonatorModel model("linear", ExperimentMode::kForced);
  const Eigen::VectorXd z = model.parameterVector(kTruth);
  const ParametricPumping pump{eta, Eigen::Vector4d(2.0, 1.5, 0.2, -0.1)};
  FullEquationSimulator fast(model, z, omega, omega, 0.0, pump);
  fast.reset(Eigen::Vector4d(0.5, 0.5, 0.0, 0.0), 0.0);
  fast.advanceTo(10.0);
  return demodulateOnePeriod(fast, 40);
}

TEST(FullEquationSimulator, ParametricTermsShiftTheStateAsOneOverEta) {
  const Eigen::Vector4d off = forcedStateWithPumping(0.0);
  const Eigen::Vector4d d1 = forcedStateWithPumping(8000.0) - off;
  const Eigen::Vector4d d2 = forcedStateWithPumping(16000.0) - off;
  // Coefficient omega^2 u~^2 / (2 eta): the averaged shift is first order in 1/eta.
  EXPECT_GT(d1.norm(), 0.1 * off.norm());
  EXPECT_NEAR(d1.norm() / d2.norm(), 2.0, 0.3);
  // Strong pumping (small eta) exceeds the damping: parametric resonance, the response grows.
  EXPECT_GT(forcedStateWithPumping(1000.0).norm(), 100.0 * off.norm());
}

TEST(FullEquationSimulator, RejectsBadInput) {
  const ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(8);
  EXPECT_THROW(FullEquationSimulator(model, z, -1.0, 1.0), InputError);
  EXPECT_THROW(FullEquationSimulator(model, Eigen::VectorXd::Zero(3), 1.0, 1.0), InputError);
  FullEquationSimulatorOptions o;
  o.steps_per_period = 2;
  EXPECT_THROW(FullEquationSimulator(model, z, 1.0, 1.0, 0.0, {}, o), InputError);
  FullEquationSimulator sim(model, z, 1.0, 1.0);
  sim.reset(Eigen::Vector4d::Zero(), 5.0);
  EXPECT_THROW(sim.advanceTo(4.0), InputError);
  EXPECT_THROW(sim.reset(Eigen::Vector4d::Constant(NAN)), InputError);
}

}  // namespace
}  // namespace cvg_bench
