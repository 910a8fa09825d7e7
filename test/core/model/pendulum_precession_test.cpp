// The second cubic invariant xi_k against a physical system it describes: the spherical pendulum.
// An exact pendulum (a bob on a rigid rod in 3-D, integrated in Cartesian coordinates, nothing of
// the model used) swinging on a thin ellipse precesses at Airy's rate (3/8) omega a b / L^2 in the
// sense of its motion, and its frequency falls as omega (1 - a^2 / (16 L^2)). The model with the
// pendulum's averaged coefficients xi~ = omega / (6 L^2), xi_k~ = 8 xi~ (sphericalPendulumCubic)
// must reproduce both, through its full equations (FullEquationSimulator) and its drift rate (5.9);
// the paper's one-parameter cubic (xi alone, fitted to the frequency law) gives a ninth of the
// precession (docs/paper.md "The second cubic invariant").
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "cvg_bench/core/model/model_terms.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/resonator_model.h"
#include "cvg_bench/core/simulate/full_equation_simulator.h"
#include "model/paper_orbit_rates.h"

namespace cvg_bench {
namespace {

constexpr double kGravity = 9.81;  // [m/s^2]
constexpr double kLength = 2.0;    // [m]

/// Exact spherical pendulum: position x (pivot at the origin, z up), x'' = -g e_z - lambda x with
/// the rod tension lambda = (|x'|^2 - g z) / L^2 keeping |x| = L.
struct Pendulum {
  using V6 = Eigen::Matrix<double, 6, 1>;
  V6 s;  // x, y, z, x', y', z'
  V6 rhs(const V6& u) const {
    const Eigen::Vector3d x = u.head<3>(), v = u.tail<3>();
    const double lambda = (v.squaredNorm() - kGravity * x[2]) / x.squaredNorm();
    V6 d;
    d.head<3>() = v;
    d.tail<3>() = -lambda * x - Eigen::Vector3d(0, 0, kGravity);
    return d;
  }
  void step(double h) {
    const V6 k1 = rhs(s), k2 = rhs(s + h / 2 * k1), k3 = rhs(s + h / 2 * k2), k4 = rhs(s + h * k3);
    s += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
};

/// Starts the bob at horizontal (a, 0) with horizontal velocity (0, omega b): an ellipse of
/// semi-axes a, b traversed counterclockwise seen from above.
Pendulum startPendulum(double a, double b) {
  const double omega = std::sqrt(kGravity / kLength);
  Pendulum p;
  const double z = -std::sqrt(kLength * kLength - a * a);
  p.s << a, 0, z, 0, omega * b, 0;
  return p;
}

/// Orientation [rad] of the horizontal trajectory's principal axis from its second moments over a
/// window: 0.5 atan2(2 Sxy, Sxx - Syy).
struct Moments {
  double sxx = 0, syy = 0, sxy = 0;
  void add(double x, double y) {
    sxx += x * x;
    syy += y * y;
    sxy += x * y;
  }
  double angle() const { return 0.5 * std::atan2(2 * sxy, sxx - syy); }
};

struct PendulumMeasurement {
  double precession_rad_s = 0.0;  ///< swing-plane (principal axis) rate
  double omega_rad_s = 0.0;       ///< swing frequency (zero crossings of y)
};

/// Swing-plane rate between two windows of 10 periods, `periods` apart.
PendulumMeasurement measurePendulum(double a, double b, int periods) {
  const double omega = std::sqrt(kGravity / kLength);
  const double period = 2 * M_PI / omega;
  const int steps = 400;  // per period
  const double h = period / steps;
  Pendulum p = startPendulum(a, b);
  const int window = 10;
  Moments first, last;
  double t = 0.0, first_up = -1, last_up = -1;
  int ups = 0;
  for (int i = 0; i < (periods + window) * steps; ++i) {
    if (i < window * steps) first.add(p.s[0], p.s[1]);
    if (i >= periods * steps) last.add(p.s[0], p.s[1]);
    const double x_before = p.s[0];
    p.step(h);
    t += h;
    // upward crossings of the principal axis' normal direction are not needed: the phase of x
    // (x changes sign from - to +) gives the period while the precession is slow.
    if (x_before < 0 && p.s[0] >= 0) {
      const double tc = t - h * p.s[0] / (p.s[0] - x_before);
      if (first_up < 0) first_up = tc;
      last_up = tc;
      ++ups;
    }
  }
  PendulumMeasurement m;
  m.precession_rad_s = std::remainder(last.angle() - first.angle(), M_PI) / (periods * period);
  m.omega_rad_s = 2 * M_PI * (ups - 1) / (last_up - first_up);
  return m;
}

/// Swing-plane rate of the model's full equations (2.3) with the given cubic coefficients: the
/// angle of the vector (f, g) is phi = 2 theta of (5.2).
double measureModel(const ParameterValues& cubic, double a, double b, int periods) {
  const double omega = std::sqrt(kGravity / kLength);
  const ResonatorModel model("xi+xi_k", ExperimentMode::kFreeDecay);
  FullEquationSimulator sim(model, model.parameterVector(cubic), omega, omega);
  sim.reset(Eigen::Vector4d(a, 0, 0, b));  // f = a cos wt, g = b sin wt
  const double t_end = periods * 2 * M_PI / omega;
  const double theta0 = orbitFromSlow(sim.osculating()).theta;
  sim.advanceTo(t_end);
  const double theta1 = orbitFromSlow(sim.osculating()).theta;
  return 2.0 * std::remainder(theta1 - theta0, M_PI / 2) / t_end;
}

TEST(PendulumPrecession, CoefficientsOfTheSphericalPendulum) {
  const PendulumCubic c = sphericalPendulumCubic(3.0, 2.0);
  EXPECT_DOUBLE_EQ(c.xi, 3.0 / 24.0);
  EXPECT_DOUBLE_EQ(c.xi_k, 1.0);
  EXPECT_THROW(sphericalPendulumCubic(-1.0, 2.0), std::exception);
  EXPECT_THROW(sphericalPendulumCubic(1.0, 0.0), std::exception);
}

TEST(PendulumPrecession, AiryPrecessionWithinOnePercent) {
  const double omega = std::sqrt(kGravity / kLength);
  const double a = 0.08, b = 0.03;  // [m]: a / L = 0.04, an ellipse like a real pendulum's
  const double airy = 3.0 / 8.0 * omega * a * b / (kLength * kLength);
  const int periods = 300;
  const PendulumMeasurement exact = measurePendulum(a, b, periods);
  // The exact pendulum itself follows Airy (higher orders are O(a^2 / L^2) = 0.2 %).
  EXPECT_NEAR(exact.precession_rad_s / airy, 1.0, 0.01);
  const PendulumCubic c = sphericalPendulumCubic(omega, kLength);
  // The model's full equations with xi + xi_k.
  const double model = measureModel({{"xi", c.xi}, {"xi_k", c.xi_k}}, a, b, periods);
  EXPECT_NEAR(model / airy, 1.0, 0.01);
  EXPECT_NEAR(model / exact.precession_rad_s, 1.0, 0.01);
  // The averaged drift rate (5.9): phi' = 2 theta' = 2 (xi + xi_k) r k / 8 with r = a, k = b.
  const double drift = 2.0 * driftRate(a, b, 0.0, {{"xi", c.xi}, {"xi_k", c.xi_k}});
  EXPECT_NEAR(drift / airy, 1.0, 1e-12);
  // The paper's one-parameter cubic with the pendulum's frequency law: a ninth of the precession.
  const double xi_only = measureModel({{"xi", c.xi}}, a, b, periods);
  EXPECT_NEAR(xi_only / airy, 1.0 / 9.0, 0.01 / 9.0);
}

// The frequency law depends on xi alone: a planar swing (b = 0) of the exact pendulum slows by
// omega a^2 / (16 L^2), the model's chi' = -(3/8) xi r^2 (5.10) with the pendulum's xi.
TEST(PendulumPrecession, AmplitudeFrequencyLawFromXiAlone) {
  const double omega = std::sqrt(kGravity / kLength);
  const double a = 0.2;  // [m]
  const PendulumMeasurement exact = measurePendulum(a, 0.0, 60);
  const PendulumCubic c = sphericalPendulumCubic(omega, kLength);
  const OrbitRates with = orbitRates({a, 0.0, 0.0, 0.0}, {{"xi", c.xi}, {"xi_k", c.xi_k}});
  const double shift = exact.omega_rad_s - omega;
  EXPECT_NEAR(with.chi_dot / shift, 1.0, 0.02);
  EXPECT_NEAR(with.chi_dot, -omega * a * a / (16 * kLength * kLength), 1e-14);
}

}  // namespace
}  // namespace cvg_bench
