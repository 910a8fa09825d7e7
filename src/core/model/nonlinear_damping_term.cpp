// Amplitude-dependent damping (beyond the paper): -gamma_nl (f^2 + g^2) f' in the f equation,
// likewise g. gamma_nl is a velocity coefficient (not tilde) [1/(s amplitude^2)].
// First harmonic of N f' with f' = Re(-i w a e^{-i w t}) gives
//   2 a' = -(gamma_nl / 4)(2 N a - S conj(a)),  likewise b;
// single mode: 2 a' = -(gamma_nl |a|^2 / 4) a, i.e. an effective damping gamma + gamma_nl A^2 / 4.
#include "cvg_bench/core/model/complex_product.h"
#include "cvg_bench/core/model/model_terms.h"
#include "cvg_bench/core/model/slow_complex.h"
#include "cvg_bench/core/model/slow_complex_jacobian.h"

namespace cvg_bench {
namespace {

class NonlinearDampingTerm : public ModelTerm {
 public:
  std::string name() const override { return "gamma_nl"; }
  std::vector<std::string> parameterNames() const override { return {"gamma_nl"}; }
  std::string description() const override {
    return "amplitude-dependent damping: decay rate grows with amplitude squared "
           "(air/thermoelastic "
           "or anchor loss nonlinearity)";
  }
  std::vector<CandidateExtension> candidates() const override {
    return {{"gamma_nl", "gamma_nl", "amplitude-dependent damping", "1/(s amp^2)",
             "amplitude-rate (radial) residual growing with amplitude^2", false, true, true, 3}};
  }
  bool isAmplitudeLaw() const override { return true; }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext&,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    const SlowComplex z(q);
    setComplexColumn(-0.25 * (2.0 * z.n_sq * z.a - mul(z.s, std::conj(z.a))),
                     -0.25 * (2.0 * z.n_sq * z.b - mul(z.s, std::conj(z.b))), d, 0);
  }
  void averagedJacobian(const Eigen::Vector4d& q, const SlowContext&,
                        const Eigen::Ref<const Eigen::VectorXd>& z_term,
                        Eigen::Matrix4d& jacobian) const override {
    setComplexJacobian(cubicColumnDerivatives(SlowComplex(q), -1.0), -0.25 * z_term[0], jacobian);
  }
  void fastColumns(const FastState& s, const FastContext&,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    const double n = s.f * s.f + s.g * s.g;
    cols(0, 0) = -n * s.f_dot;
    cols(1, 0) = -n * s.g_dot;
  }
};

}  // namespace

ModelTermPtr makeNonlinearDampingTerm() {
  return std::make_shared<NonlinearDampingTerm>();
}

}  // namespace cvg_bench
