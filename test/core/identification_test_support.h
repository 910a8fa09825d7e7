// Test helpers for the identification tests: known-truth data from the averaged model itself
// (RK4 on ResonatorModel::slowDerivative for free decay, Newton on slowDerivative = 0 for forced
// sweeps), so the tests do not depend on the simulator.
#pragma once

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {
namespace testing_support {

/// Counts the parameters of `truth` whose reported interval contains the true value (covered) and
/// all of them (total).
inline void countCoverage(const Estimate& e, const ParameterValues& truth, int* covered,
                          int* total) {
  for (const auto& kv : truth) {
    const ParameterEstimate& p = e.parameters.at(kv.first);
    *covered += p.ci_low <= kv.second && kv.second <= p.ci_high;
    ++*total;
  }
}

/// n_samples samples of the averaged free decay at dt spacing, RK4 with `substeps` steps each.
inline SlowRecord simulateFreeDecay(const ResonatorModel& model, const Eigen::VectorXd& z,
                                    const Eigen::Vector4d& q0, double dt, int n_samples,
                                    int substeps = 4) {
  SlowRecord rec;
  Eigen::Vector4d q = q0;
  const double h = dt / substeps;
  SlowContext c;
  auto f = [&](double t, const Eigen::Vector4d& x) {
    c.t_s = t;
    return model.slowDerivative(x, c, z);
  };
  double t = 0.0;
  for (int i = 0; i < n_samples; ++i) {
    rec.t_s.push_back(i * dt);
    rec.q.push_back(q);
    for (int s = 0; s < substeps; ++s) {
      const Eigen::Vector4d k1 = f(t, q), k2 = f(t + h / 2, q + h / 2 * k1),
                            k3 = f(t + h / 2, q + h / 2 * k2), k4 = f(t + h, q + h * k3);
      q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += h;
    }
    t = (i + 1) * dt;
  }
  return rec;
}

/// Stationary point of (3.3) at drive frequency omega0 by Newton from the linear solution.
inline Eigen::Vector4d stationaryPoint(const ResonatorModel& model, const Eigen::VectorXd& z,
                                       double omega, double omega0, double mu = 0.0) {
  SlowContext c;
  c.mu = mu;
  const double rate = detuningRate(omega, omega0);
  auto f = [&](const Eigen::Vector4d& q) { return model.slowDerivative(q, c, z, rate); };
  auto jac = [&](const Eigen::Vector4d& q) {
    Eigen::Matrix4d j;
    for (int i = 0; i < 4; ++i) {
      Eigen::Vector4d dq = Eigen::Vector4d::Zero();
      dq[i] = 1e-7;
      j.col(i) = (f(q + dq) - f(q - dq)) / 2e-7;
    }
    return j;
  };
  Eigen::Vector4d q = -jac(Eigen::Vector4d::Zero()).lu().solve(f(Eigen::Vector4d::Zero()));
  for (int it = 0; it < 100; ++it) {
    const Eigen::Vector4d step = jac(q).lu().solve(f(q));
    q -= step;
    if (step.norm() < 1e-15 * (1 + q.norm())) break;
  }
  return q;
}

inline SweepRecord simulateSweep(const ResonatorModel& model, const Eigen::VectorXd& z,
                                 double omega, const std::vector<double>& detunings,
                                 double mu = 0.0) {
  SweepRecord rec;
  rec.omega_rad_s = omega;
  for (double l : detunings) {
    rec.omega0_rad_s.push_back(omega + l);
    rec.q.push_back(stationaryPoint(model, z, omega, omega + l, mu));
  }
  return rec;
}

/// Adds independent N(0, sigma^2) noise to every q component.
template <class Record>
Record withNoise(Record rec, double sigma, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> n(0.0, sigma);
  for (auto& q : rec.q)
    for (int i = 0; i < 4; ++i) q[i] += n(gen);
  return rec;
}

}  // namespace testing_support
}  // namespace cvg_bench
