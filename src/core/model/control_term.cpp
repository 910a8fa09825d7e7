// Drive of (3.1): eta (1 + 3 mu f^2)(-u1 sin w0 t + u2 cos w0 t) in the f equation, likewise g with
// u3, u4. Parameters u~i = eta u_i / omega (tilde); mu is known (SlowContext/FastContext).
// Averaged (3.2): 2 q' gets D_u z_u with D_u = E + mu D_n,
//   D_n = [[k11, k9, 0, 0], [k9, k12, 0, 0], [0, 0, k13, k10], [0, 0, k10, k14]],
//   k9 = -3 q1 p1 / 2, k10 = -3 q2 p2 / 2, k11 = 3 (3 p1^2 + q1^2) / 4, k12 = 3 (p1^2 + 3 q1^2) /
//   4, k13, k14 likewise with q2, p2 (derived: <f^2 sin^2> = (3 p^2 + q^2)/8, <f^2 sin cos> = q p /
//   4).
// (The paper writes "E + alpha D_n"; alpha means mu, docs/paper.md item 3.)
#include <cmath>

#include "cvg_bench/core/model/model_terms.h"

namespace cvg_bench {
namespace {

class ControlTerm : public ModelTerm {
 public:
  std::string name() const override { return "controls"; }
  std::vector<std::string> parameterNames() const override { return {"u1", "u2", "u3", "u4"}; }
  std::string description() const override {
    return "drive voltages u1..u4 at omega0 with control nonlinearity mu (3.1)";
  }
  std::vector<CandidateExtension> candidates() const override {
    // mu of (3.1)-(3.2), the known nonlinearity of the controls, identified as an extension.
    return {{"mu", "mu", "control (actuator) nonlinearity", "1/amp^2",
             "residual concentrated near resonance where the drive acts on large amplitudes", true,
             false, true, 2}};
  }
  bool appliesTo(ExperimentMode mode) const override { return mode == ExperimentMode::kForced; }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext& c,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    const double q1 = q[0], p1 = q[1], q2 = q[2], p2 = q[3], mu = c.mu;
    const double k9 = -1.5 * q1 * p1, k10 = -1.5 * q2 * p2;
    const double k11 = 0.75 * (3 * p1 * p1 + q1 * q1), k12 = 0.75 * (p1 * p1 + 3 * q1 * q1);
    const double k13 = 0.75 * (3 * p2 * p2 + q2 * q2), k14 = 0.75 * (p2 * p2 + 3 * q2 * q2);
    d.setZero();
    d(0, 0) = 1 + mu * k11;
    d(0, 1) = mu * k9;
    d(1, 0) = mu * k9;
    d(1, 1) = 1 + mu * k12;
    d(2, 2) = 1 + mu * k13;
    d(2, 3) = mu * k10;
    d(3, 2) = mu * k10;
    d(3, 3) = 1 + mu * k14;
  }
  // Only the mu D_n part depends on q: derivatives of k9..k14 above.
  void averagedJacobian(const Eigen::Vector4d& q, const SlowContext& c,
                        const Eigen::Ref<const Eigen::VectorXd>& u,
                        Eigen::Matrix4d& jacobian) const override {
    const double mu = c.mu;
    jacobian.setZero();
    for (int m = 0; m < 2; ++m) {
      const double qm = q[2 * m], pm = q[2 * m + 1], ua = u[2 * m], ub = u[2 * m + 1];
      // row 2m: ua (1 + mu k11) + ub mu k9; row 2m+1: ua mu k9 + ub (1 + mu k12).
      jacobian(2 * m, 2 * m) = mu * (1.5 * qm * ua - 1.5 * pm * ub);
      jacobian(2 * m, 2 * m + 1) = mu * (4.5 * pm * ua - 1.5 * qm * ub);
      jacobian(2 * m + 1, 2 * m) = mu * (-1.5 * pm * ua + 4.5 * qm * ub);
      jacobian(2 * m + 1, 2 * m + 1) = mu * (-1.5 * qm * ua + 1.5 * pm * ub);
    }
  }
  void fastColumns(const FastState& s, const FastContext& c,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    const double w = c.omega_rad_s;
    const bool given = !std::isnan(c.drive_sin) && !std::isnan(c.drive_cos);
    const double sn = given ? c.drive_sin : std::sin(c.drive_phase_rad);
    const double cs = given ? c.drive_cos : std::cos(c.drive_phase_rad);
    const double af = w * (1 + 3 * c.mu * s.f * s.f), ag = w * (1 + 3 * c.mu * s.g * s.g);
    // u1, u2 drive f; u3, u4 drive g (entries set one by one: cheaper than zeroing the block).
    cols(0, 0) = -af * sn;
    cols(0, 1) = af * cs;
    cols(0, 2) = 0.0;
    cols(0, 3) = 0.0;
    cols(1, 0) = 0.0;
    cols(1, 1) = 0.0;
    cols(1, 2) = -ag * sn;
    cols(1, 3) = ag * cs;
  }
};

}  // namespace

ModelTermPtr makeControlTerm() {
  return std::make_shared<ControlTerm>();
}

}  // namespace cvg_bench
