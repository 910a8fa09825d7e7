// The paper's printed orbit-element rates (5.7)-(5.10), corrected (docs/paper.md items 4-5), for
// the paper's terms: the known answer the chain rule of the averaged model
// (core/model/orbit_rates_chain_rule.h) is tested against. Test support only: the product computes
// every model's rates by the chain rule, so a new term needs no edit of a drift formula.
#pragma once

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/orbit_elements.h"

namespace cvg_bench {
namespace paper_rates_detail {
inline double value(const ParameterValues& p, const char* name) {
  auto it = p.find(name);
  return it == p.end() ? 0.0 : it->second;
}
}  // namespace paper_rates_detail

/// The drift rate theta' of (5.9) [rad/s] (corrected; plus xi_k r k / 8), the gyro's zero-rate
/// error at (r, k, theta), with gamma, nu, b_c, b_s, c_m, n, h_c, h_s, xi, kappa, xi_k from p
/// (missing ones are 0). InputError at r^2 = k^2.
inline double driftRate(double r, double k, double theta, const ParameterValues& p) {
  using paper_rates_detail::value;

  requireFinite(r, "r");
  requireFinite(k, "k");
  requireFinite(theta, "theta");
  const double r2 = r * r, k2 = k * k;
  if (std::fabs(r2 - k2) <= 1e-14 * (r2 + k2) || r2 + k2 == 0.0)
    throw InputError("drift rate (5.9) is undefined for r^2 = k^2 (travelling wave or no wave)");
  const DefectAxes ax = defectAxes(p);
  const double nu = value(p, "nu"), xi = value(p, "xi"), kappa = value(p, "kappa");
  // xi_k (the second cubic invariant, docs/paper.md "The second cubic invariant") only turns the
  // pattern: it adds xi_k r k / 8 here and nothing to (5.7), (5.8), (5.10).
  const double xi_k = value(p, "xi_k");
  return -0.25 * nu + (xi + xi_k) / 8.0 * r * k + kappa / 8.0 * r * k * (r2 + k2) -
         r * k / (2 * (r2 - k2)) * ax.h_m * std::cos(4 * (theta - ax.alpha)) +
         (r2 + k2) / (4 * (r2 - k2)) * ax.b_m * std::sin(4 * (theta - ax.beta));
}

/// (5.7)-(5.10) (corrected) for free oscillation (u = 0); requires r^2 != k^2.
inline OrbitRates orbitRates(const OrbitElements& e, const ParameterValues& p) {
  using paper_rates_detail::value;
  const double r = e.r, k = e.k, r2 = r * r, k2 = k * k;
  if (std::fabs(r2 - k2) <= 1e-14 * (r2 + k2) || r2 + k2 == 0.0)
    throw InputError("orbit rates are undefined for a travelling wave (r^2 = k^2)");
  const DefectAxes ax = defectAxes(p);
  const double gamma = value(p, "gamma"), n = value(p, "n");
  const double cm = value(p, "c_m"), xi = value(p, "xi"), kappa = value(p, "kappa");
  const double sa = std::sin(4 * (e.theta - ax.alpha)), ca = std::cos(4 * (e.theta - ax.alpha));
  const double sb = std::sin(4 * (e.theta - ax.beta)), cb = std::cos(4 * (e.theta - ax.beta));
  OrbitRates o;
  // (5.7), (5.8)
  o.r_dot = 0.5 * (-gamma * r + n * k - ax.h_m * k * sa - ax.b_m * r * cb);
  o.k_dot = 0.5 * (-gamma * k + n * r + ax.h_m * r * sa + ax.b_m * k * cb);
  // (5.9)
  o.theta_dot = driftRate(r, k, e.theta, p);
  // (5.10)
  o.chi_dot = 0.5 * cm - 3.0 * xi / 8.0 * (k2 + r2) -
              kappa / 16.0 * (5 * k2 * k2 + 6 * k2 * r2 + 5 * r2 * r2) +
              (r2 + k2) / (2 * (r2 - k2)) * ax.h_m * ca - r * k / (r2 - k2) * ax.b_m * sb;
  return o;
}

}  // namespace cvg_bench
