// Unequal cubic stiffness of the two axes (beyond the paper): the f equation has (xi + xi_diff) N f
// and the g equation (xi - xi_diff) N g. xi_diff is tilde (÷ omega). Averaging as for xi:
//   2 a' = (i xi_diff / 4)(2 N a + S conj(a)),  2 b' = -(i xi_diff / 4)(2 N b + S conj(b)).
#include "cvg_bench/core/model/complex_product.h"
#include "cvg_bench/core/model/model_terms.h"
#include "cvg_bench/core/model/slow_complex.h"
#include "cvg_bench/core/model/slow_complex_jacobian.h"

namespace cvg_bench {
namespace {

class AxisCubicMismatchTerm : public ModelTerm {
 public:
  std::string name() const override { return "xi_diff"; }
  std::vector<std::string> parameterNames() const override { return {"xi_diff"}; }
  std::string description() const override {
    return "unequal cubic stiffness on the two axes (nonlinearity anisotropy)";
  }
  std::vector<CandidateExtension> candidates() const override {
    return {{"xi_diff", "xi_diff", "unequal cubic stiffness of the two axes", "1/(s amp^2)",
             "amplitude-dependent residual that depends on the pattern angle theta", false, true,
             true, 5}};
  }
  bool isAmplitudeLaw() const override { return true; }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext&,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    const SlowComplex z(q);
    const std::complex<double> k(0.0, 0.25);
    setComplexColumn(mul(k, 2.0 * z.n_sq * z.a + mul(z.s, std::conj(z.a))),
                     -mul(k, 2.0 * z.n_sq * z.b + mul(z.s, std::conj(z.b))), d, 0);
  }
  void averagedJacobian(const Eigen::Vector4d& q, const SlowContext&,
                        const Eigen::Ref<const Eigen::VectorXd>& z_term,
                        Eigen::Matrix4d& jacobian) const override {
    ComplexColumnDerivatives d = cubicColumnDerivatives(SlowComplex(q), 1.0);
    d.b_a = -d.b_a;  // the g equation carries -xi_diff
    d.b_ac = -d.b_ac;
    d.b_b = -d.b_b;
    d.b_bc = -d.b_bc;
    setComplexJacobian(d, std::complex<double>(0.0, 0.25 * z_term[0]), jacobian);
  }
  void fastColumns(const FastState& s, const FastContext& c,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    const double n = s.f * s.f + s.g * s.g;
    cols(0, 0) = c.omega_rad_s * n * s.f;
    cols(1, 0) = -c.omega_rad_s * n * s.g;
  }
};

}  // namespace

ModelTermPtr makeAxisCubicMismatchTerm() {
  return std::make_shared<AxisCubicMismatchTerm>();
}

}  // namespace cvg_bench
