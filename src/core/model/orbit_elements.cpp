#include "cvg_bench/core/model/orbit_elements.h"

#include <cmath>

#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace {

double value(const ParameterValues& p, const char* name) {
  auto it = p.find(name);
  return it == p.end() ? 0.0 : it->second;
}

}  // namespace

Eigen::Vector4d slowFromOrbit(const OrbitElements& e) {
  const double c2 = std::cos(2 * e.theta), s2 = std::sin(2 * e.theta);
  const double cx = std::cos(e.chi), sx = std::sin(e.chi);
  return Eigen::Vector4d(e.r * c2 * cx - e.k * s2 * sx, -e.r * c2 * sx - e.k * s2 * cx,
                         e.r * s2 * cx + e.k * c2 * sx, -e.r * s2 * sx + e.k * c2 * cx);
}

OrbitElements orbitFromSlow(const Eigen::Vector4d& q) {
  const double q1 = q[0], p1 = q[1], q2 = q[2], p2 = q[3];
  const double n = q.squaredNorm();
  const double c4 = q1 * q1 + p1 * p1 - q2 * q2 - p2 * p2;
  const double s4 = 2 * (q1 * q2 + p1 * p2);
  const double diff = std::hypot(c4, s4);  // r^2 - k^2 >= 0
  OrbitElements e;
  e.theta = (diff > 0.0) ? 0.25 * std::atan2(s4, c4) : 0.0;
  e.r = std::sqrt(std::max(0.0, 0.5 * (n + diff)));
  e.k = (e.r > 0.0) ? (q1 * p2 - p1 * q2) / e.r : 0.0;
  // r e^{i chi} = (q1 - i p1) cos 2 theta + (q2 - i p2) sin 2 theta.
  const double c2 = std::cos(2 * e.theta), s2 = std::sin(2 * e.theta);
  e.chi = std::atan2(-(p1 * c2 + p2 * s2), q1 * c2 + q2 * s2);
  return e;
}

DefectAxes defectAxes(const ParameterValues& p) {
  DefectAxes a;
  const double hc = value(p, "h_c"), hs = value(p, "h_s");
  const double bc = value(p, "b_c"), bs = value(p, "b_s");
  a.h_m = std::hypot(hc, hs);
  a.alpha = 0.25 * std::atan2(hs, hc);
  a.b_m = std::hypot(bc, bs);
  a.beta = 0.25 * std::atan2(bs, bc);
  return a;
}

OrbitRates orbitRates(const OrbitElements& e, const ParameterValues& p) {
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

double driftRate(double r, double k, double theta, const ParameterValues& p) {
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

std::vector<double> thetaGrid(long n) {
  if (n < 1 || n > kMaxThetaGridPoints)
    throw InputError("a theta grid needs 1.." + std::to_string(kMaxThetaGridPoints) +
                     " points, got " + std::to_string(n));
  std::vector<double> thetas;
  thetas.reserve(n);
  for (long i = 0; i < n; ++i) thetas.push_back(M_PI / 2 * i / n);
  return thetas;
}

}  // namespace cvg_bench
