// The angular-momentum cubic term xi_k (include/cvg_bench/core/model/angular_momentum_cubic_term.h;
// docs/paper.md "The second cubic invariant"). Averaging (first harmonic, (2.4)): with
// f = q1 cos + p1 sin, f' = omega (p1 cos - q1 sin) (likewise g), the angular momentum
// l = f g' - g f' = omega L exactly, L = q1 p2 - p1 q2 = r k (5.2); projecting F_f = -(xi_k/2) L g'
// gives 2 q1' = -(xi_k / 2) L q2, 2 p1' = -(xi_k / 2) L p2, and F_g = +(xi_k/2) L f' gives
// 2 q2' = (xi_k / 2) L q1, 2 p2' = (xi_k / 2) L p1: the X-part of the paper's k1..k4 (2.5),
// X = L / 2, alone.
#include "cvg_bench/core/model/angular_momentum_cubic_term.h"

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/model_terms.h"

namespace cvg_bench {
namespace {

class AngularMomentumCubicTerm : public ModelTerm {
 public:
  std::string name() const override { return "xi_k"; }
  std::vector<std::string> parameterNames() const override { return {"xi_k"}; }
  std::string description() const override {
    return "second isotropic cubic invariant: precession proportional to the angular momentum "
           "(r k), no amplitude-frequency shift";
  }
  std::vector<CandidateExtension> candidates() const override {
    // Offered for free decay, where the orbit's quadrature k evolves; in forced sweeps it is a
    // term of `identify --model` but not yet validated as a candidate.
    return {{"xi_k", "xi_k",
             "second cubic invariant (angular-momentum coupling, e.g. Airy precession)",
             "1/(s amp^2)",
             "pattern-angle drift proportional to r k (the ellipse's area) that xi's frequency law "
             "cannot carry",
             false, true, false, 6}};
  }
  bool isAmplitudeLaw() const override { return true; }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext&,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    const double half_l = 0.5 * (q[0] * q[3] - q[1] * q[2]);
    d(0, 0) = -half_l * q[2];
    d(1, 0) = -half_l * q[3];
    d(2, 0) = half_l * q[0];
    d(3, 0) = half_l * q[1];
  }
  void averagedJacobian(const Eigen::Vector4d& q, const SlowContext&,
                        const Eigen::Ref<const Eigen::VectorXd>& z_term,
                        Eigen::Matrix4d& jacobian) const override {
    // column = (L/2) v with v = (-q2, -p2, q1, p1); d/dq = (1/2)(v dL^T + L dv/dq).
    const double l = q[0] * q[3] - q[1] * q[2];
    const Eigen::Vector4d v(-q[2], -q[3], q[0], q[1]);
    const Eigen::Vector4d dl(q[3], -q[2], -q[1], q[0]);
    Eigen::Matrix4d dv = Eigen::Matrix4d::Zero();
    dv(0, 2) = -1.0;
    dv(1, 3) = -1.0;
    dv(2, 0) = 1.0;
    dv(3, 1) = 1.0;
    jacobian = 0.5 * z_term[0] * (v * dl.transpose() + l * dv);
  }
  void fastColumns(const FastState& s, const FastContext& c,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    const double half_l_over_omega = 0.5 * (s.f * s.g_dot - s.g * s.f_dot) / c.omega_rad_s;
    cols(0, 0) = -half_l_over_omega * s.g_dot;
    cols(1, 0) = half_l_over_omega * s.f_dot;
  }
};

}  // namespace

ModelTermPtr makeAngularMomentumCubicTerm() {
  return std::make_shared<AngularMomentumCubicTerm>();
}

PendulumCubic sphericalPendulumCubic(double omega_rad_s, double length_m) {
  requireFinite(omega_rad_s, "omega_rad_s");
  requireFinite(length_m, "length_m");
  if (!(omega_rad_s > 0.0) || !(length_m > 0.0))
    throw InputError("spherical pendulum: omega_rad_s and length_m must be positive");
  PendulumCubic p;
  p.xi = omega_rad_s / (6.0 * length_m * length_m);
  p.xi_k = 8.0 * p.xi;
  return p;
}

}  // namespace cvg_bench
