#include "cvg_bench/core/model/orbit_elements.h"

#include <cmath>

#include "cvg_bench/core/common/errors.h"

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
