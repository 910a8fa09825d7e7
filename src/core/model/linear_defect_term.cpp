// Linear defect model of (2.3): damping gamma, angular-rate term nu, damping anisotropy (b_c, b_s),
// position forces c_m, n and frequency split (h_c, h_s); c_m, n, h_c, h_s are tilde (÷ omega).
//   F_f = -(gamma + b_c) f' - (-nu + b_s) g' - (c_m + h_c) f - (n + h_s) g
//   F_g = -(gamma - b_c) g' - (nu + b_s) f' - (c_m - h_c) g - (-n + h_s) f
// Averaged (2.5): the block D_gamma of (2.6) (section 2's print; section 3's print has a sign
// misprint in row 2, columns h_c, h_s, see docs/paper.md item 2).
#include "cvg_bench/core/model/model_terms.h"

namespace cvg_bench {
namespace {

class LinearDefectTerm : public ModelTerm {
 public:
  std::string name() const override { return "linear"; }
  std::vector<std::string> parameterNames() const override {
    return {"gamma", "nu", "b_c", "b_s", "c_m", "n", "h_c", "h_s"};
  }
  std::string description() const override {
    return "linear defects: damping, rotation term, damping anisotropy, position forces, "
           "frequency split (2.3)";
  }
  std::string parameterMeaning(const std::string& parameter) const override {
    if (parameter == "gamma") return "damping";
    if (parameter == "nu") return "rotation term";
    if (parameter == "b_c" || parameter == "b_s") return "damping anisotropy";
    if (parameter == "c_m") return "mean frequency offset";
    if (parameter == "n") return "position (circulatory) forces";
    if (parameter == "h_c" || parameter == "h_s") return "frequency split";
    return description();
  }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext&,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    const double q1 = q[0], p1 = q[1], q2 = q[2], p2 = q[3];
    d.row(0) << -q1, q2, -q1, -q2, p1, p2, p1, p2;
    d.row(1) << -p1, p2, -p1, -p2, -q1, -q2, -q1, -q2;
    d.row(2) << -q2, -q1, q2, -q1, p2, -p1, -p2, p1;
    d.row(3) << -p2, -p1, p2, -p1, -q2, q1, q2, -q1;
  }
  // D(q) z is linear in q: the Jacobian is the constant matrix of the rows above times z.
  void averagedJacobian(const Eigen::Vector4d&, const SlowContext&,
                        const Eigen::Ref<const Eigen::VectorXd>& z,
                        Eigen::Matrix4d& jacobian) const override {
    const double gamma = z[0], nu = z[1], b_c = z[2], b_s = z[3];
    const double c_m = z[4], n = z[5], h_c = z[6], h_s = z[7];
    jacobian << -gamma - b_c, c_m + h_c, nu - b_s, n + h_s,  //
        -c_m - h_c, -gamma - b_c, -n - h_s, nu - b_s,        //
        -nu - b_s, -n + h_s, -gamma + b_c, c_m - h_c,        //
        n - h_s, -nu - b_s, -c_m + h_c, -gamma + b_c;
  }
  void fastColumns(const FastState& s, const FastContext& c,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    const double w = c.omega_rad_s;
    cols.row(0) << -s.f_dot, s.g_dot, -s.f_dot, -s.g_dot, -w * s.f, -w * s.g, -w * s.f, -w * s.g;
    cols.row(1) << -s.g_dot, -s.f_dot, s.g_dot, -s.f_dot, -w * s.g, w * s.f, w * s.g, -w * s.f;
  }
};

}  // namespace

ModelTermPtr makeLinearDefectTerm() {
  return std::make_shared<LinearDefectTerm>();
}

}  // namespace cvg_bench
