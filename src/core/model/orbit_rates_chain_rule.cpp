#include "cvg_bench/core/model/orbit_rates_chain_rule.h"

#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

namespace {

/// a - b wrapped into (-period/2, period/2].
double wrapped(double a, double b, double period) {
  double d = std::fmod(a - b, period);
  if (d > period / 2) d -= period;
  if (d <= -period / 2) d += period;
  return d;
}

}  // namespace

ResonatorModel freeOscillationModelOf(const ParameterValues& values) {
  std::vector<std::string> extensions;
  for (const std::string& name : knownModelTermNames()) {
    if (name == "linear" || name == "controls") continue;
    const ModelTermPtr term = makeModelTerm(name);
    if (!term->appliesTo(ExperimentMode::kFreeDecay)) continue;
    bool all = true;
    for (const auto& p : term->parameterNames()) all = all && values.count(p) > 0;
    if (all) extensions.push_back(name);
  }
  return ResonatorModel(extensions, ExperimentMode::kFreeDecay);
}

OrbitRates orbitRatesOfModel(const ResonatorModel& model, const ParameterValues& values,
                             const OrbitElements& e, double t_s) {
  if (!(e.r > 0.0) || !(std::abs(e.r * e.r - e.k * e.k) > 1e-12 * e.r * e.r))
    throw InputError("orbit rates need r > 0 and r^2 != k^2 (a standing-wave component)");
  const Eigen::VectorXd z = model.parameterVector(values);
  SlowContext ctx;
  ctx.t_s = t_s;
  constexpr int kPhases = 8;
  OrbitRates mean;
  for (int i = 0; i < kPhases; ++i) {
    OrbitElements at = e;
    at.chi = 2.0 * M_PI * i / kPhases;
    const Eigen::Vector4d q = slowFromOrbit(at);
    const Eigen::Vector4d qd = model.slowDerivative(q, ctx, z);
    // Step along q' small against the state: relative 1e-6 of |q|.
    const double h = qd.norm() > 0.0 ? 1e-6 * q.norm() / qd.norm() : 0.0;
    if (h == 0.0) continue;
    // r', k', theta' exactly from the invariants of (5.2) (orbit_elements.h): S = r^2 + k^2 =
    // |q|^2, P = r k = q1 p2 - p1 q2, (r^2 - k^2)(cos 4 theta, sin 4 theta) = (C, D) with
    // C = q1^2 + p1^2 - q2^2 - p2^2, D = 2 (q1 q2 + p1 p2); so r +- k = sqrt(S +- 2P) and
    // 4 theta = atan2(D, C). Their derivatives along q' give the rates.
    const double q1 = q[0], p1 = q[1], q2 = q[2], p2 = q[3];
    const double d1 = qd[0], e1 = qd[1], d2 = qd[2], e2 = qd[3];
    const double S = q.squaredNorm(), Sd = 2.0 * q.dot(qd);
    const double P = q1 * p2 - p1 * q2, Pd = d1 * p2 + q1 * e2 - e1 * q2 - p1 * d2;
    const double C = q1 * q1 + p1 * p1 - q2 * q2 - p2 * p2;
    const double Cd = 2.0 * (q1 * d1 + p1 * e1 - q2 * d2 - p2 * e2);
    const double D = 2.0 * (q1 * q2 + p1 * p2), Dd = 2.0 * (d1 * q2 + q1 * d2 + e1 * p2 + p1 * e2);
    const double plus = std::sqrt(S + 2.0 * P), minus = std::sqrt(std::max(0.0, S - 2.0 * P));
    const double plus_d = (Sd + 2.0 * Pd) / (2.0 * plus), minus_d = (Sd - 2.0 * Pd) / (2.0 * minus);
    mean.r_dot += 0.5 * (plus_d + minus_d);
    mean.k_dot += 0.5 * (plus_d - minus_d);
    mean.theta_dot += (C * Dd - D * Cd) / (4.0 * (C * C + D * D));
    const OrbitElements a = orbitFromSlow(q + h * qd), b = orbitFromSlow(q - h * qd);
    // chi modulo pi: a pattern angle wrapping by pi/2 shifts chi by pi ((5.2) is the same q).
    mean.chi_dot += wrapped(a.chi, b.chi, M_PI) / (2 * h);
  }
  mean.r_dot /= kPhases;
  mean.k_dot /= kPhases;
  mean.theta_dot /= kPhases;
  mean.chi_dot /= kPhases;
  return mean;
}

}  // namespace cvg_bench
