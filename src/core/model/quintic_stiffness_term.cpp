// Quintic stiffness kappa (f^2 + g^2)^2 f (likewise g) of (2.2)/(2.3); parameter kappa~ = kappa /
// omega. First-order averaging gives
//   2 a' = (i kappa~ / 8)((2 N^2 + |S|^2) a + 2 N S conj(a)),  likewise b;
// single mode 2 q1' = -(5/8) kappa~ p1^5. The paper prints k5..k8 with 1/16 (docs/paper.md item 1).
#include "cvg_bench/core/model/complex_product.h"
#include "cvg_bench/core/model/model_terms.h"
#include "cvg_bench/core/model/slow_complex.h"
#include "cvg_bench/core/model/slow_complex_jacobian.h"

namespace cvg_bench {
namespace {

class QuinticStiffnessTerm : public ModelTerm {
 public:
  std::string name() const override { return "kappa"; }
  std::vector<std::string> parameterNames() const override { return {"kappa"}; }
  std::string description() const override {
    return "quintic stiffness: frequency shift growing with the fourth power of amplitude";
  }
  std::vector<CandidateExtension> candidates() const override {
    return {{"kappa", "kappa", "quintic stiffness", "1/(s amp^4)",
             "phase-rate (tangential) residual growing with amplitude^4", false, true, true, 1}};
  }
  bool isAmplitudeLaw() const override { return true; }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext&,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    const SlowComplex z(q);
    const std::complex<double> k(0.0, 0.125);
    const double c0 = 2.0 * z.n_sq * z.n_sq + std::norm(z.s);
    const std::complex<double> c1 = 2.0 * z.n_sq * z.s;
    setComplexColumn(mul(k, c0 * z.a + mul(c1, std::conj(z.a))),
                     mul(k, c0 * z.b + mul(c1, std::conj(z.b))), d, 0);
  }
  void averagedJacobian(const Eigen::Vector4d& q, const SlowContext&,
                        const Eigen::Ref<const Eigen::VectorXd>& z_term,
                        Eigen::Matrix4d& jacobian) const override {
    setComplexJacobian(quinticColumnDerivatives(SlowComplex(q)),
                       std::complex<double>(0.0, 0.125 * z_term[0]), jacobian);
  }
  void fastColumns(const FastState& s, const FastContext& c,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    const double n = s.f * s.f + s.g * s.g;
    cols(0, 0) = c.omega_rad_s * n * n * s.f;
    cols(1, 0) = c.omega_rad_s * n * n * s.g;
  }
};

}  // namespace

ModelTermPtr makeQuinticStiffnessTerm() {
  return std::make_shared<QuinticStiffnessTerm>();
}

}  // namespace cvg_bench
