// The averaged model (2.5) tracks the full equations (2.3) to first order in the small parameter:
// integrate (2.3) in f, g with RK4, demodulate over whole periods by (2.4), and compare with the
// averaged model integrated from the same start. Raising omega with the same tilde parameters
// shrinks the small parameter (rates / omega), so the error must shrink proportionally.
#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {
namespace {

const ParameterValues kTruth = {{"gamma", 0.5}, {"nu", 0.3},    {"b_c", 0.1}, {"b_s", -0.05},
                                {"c_m", 0.4},   {"n", 0.1},     {"h_c", 0.3}, {"h_s", -0.2},
                                {"xi", 0.6},    {"kappa", -0.2}};

struct Deviation {
  double max_abs = 0.0;
};

Deviation compareFullWithAveraged(double omega, double duration_s) {
  const ResonatorModel model("xi+kappa", ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = model.parameterVector(kTruth);
  const Eigen::Vector4d q0(0.8, 0.3, -0.2, 0.4);
  const double period = 2 * M_PI / omega;
  const int steps_per_period = 200;
  const double h = period / steps_per_period;
  using V4 = Eigen::Vector4d;  // (f, f', g, g')
  auto fast_rhs = [&](double t, const V4& x) {
    FastContext c{omega, omega * t, t, 0.0};
    const Eigen::Vector2d force = model.fastForce(FastState{x[0], x[1], x[2], x[3]}, c, z);
    return V4(x[1], -omega * omega * x[0] + force[0], x[3], -omega * omega * x[2] + force[1]);
  };
  auto slow_rhs = [&](double t, const V4& q) { return model.slowDerivative(q, SlowContext{t}, z); };
  V4 x(q0[0], omega * q0[1], q0[2], omega * q0[3]);
  V4 q = q0;
  double t = 0.0;
  Deviation dev;
  const int periods = static_cast<int>(duration_s / period);
  for (int p = 0; p < periods; ++p) {
    V4 acc = V4::Zero();  // (2/P) integral of (f cos, f sin, g cos, g sin) by the trapezoid rule
    for (int j = 0; j < steps_per_period; ++j) {
      const double ph = omega * t;
      const double w = 2.0 / steps_per_period;
      acc += w *
             V4(x[0] * std::cos(ph), x[0] * std::sin(ph), x[2] * std::cos(ph), x[2] * std::sin(ph));
      const V4 k1 = fast_rhs(t, x), k2 = fast_rhs(t + h / 2, x + h / 2 * k1);
      const V4 k3 = fast_rhs(t + h / 2, x + h / 2 * k2), k4 = fast_rhs(t + h, x + h * k3);
      x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += h;
    }
    // averaged model over the same period, reported at its middle
    const double t_mid = t - period / 2;
    V4 qm = q;
    double ts = t - period;
    const double hs = period / 2;
    for (int j = 0; j < 2; ++j) {
      const V4 k1 = slow_rhs(ts, qm), k2 = slow_rhs(ts + hs / 2, qm + hs / 2 * k1);
      const V4 k3 = slow_rhs(ts + hs / 2, qm + hs / 2 * k2), k4 = slow_rhs(ts + hs, qm + hs * k3);
      qm += hs / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      ts += hs;
      if (j == 0) {
        const V4 demod(acc[0], acc[1], acc[2], acc[3]);
        dev.max_abs = std::max(dev.max_abs, (demod - qm).cwiseAbs().maxCoeff());
      }
    }
    q = qm;
    (void)t_mid;
  }
  return dev;
}

TEST(FullEquationAveraging, AveragedModelTracksFullEquationsToFirstOrder) {
  const double duration = 8.0;  // the slow variables change by O(1) over this time
  const Deviation coarse = compareFullWithAveraged(100.0, duration);
  const Deviation fine = compareFullWithAveraged(400.0, duration);
  // Small parameter ~ |rates| / omega ~ 1e-2 at omega = 100.
  EXPECT_LT(coarse.max_abs, 0.05);
  EXPECT_LT(fine.max_abs, 0.0125);
  // First order: four times omega gives about a quarter of the error (allow 2.5x..6x).
  EXPECT_GT(coarse.max_abs / fine.max_abs, 2.5);
  EXPECT_LT(coarse.max_abs / fine.max_abs, 6.0);
}

}  // namespace
}  // namespace cvg_bench
