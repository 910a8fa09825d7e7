// Cubic stiffness xi (f^2 + g^2) f (likewise g) of (2.2)/(2.3); parameter xi~ = xi / omega.
// First-order averaging (first harmonic of N f with f = Re(a e^{-i w t})):
//   2 a' = (i xi~ / 4)(2 N a + S conj(a)),  2 b' = (i xi~ / 4)(2 N b + S conj(b)),
// which is the paper's k1..k4 (E = 3N/4, X = (p2 q1 - p1 q2)/2);
// single mode 2 q1' = -(3/4) xi~ p1^3.
#include "cvg_bench/core/model/complex_product.h"
#include "cvg_bench/core/model/model_terms.h"
#include "cvg_bench/core/model/slow_complex.h"
#include "cvg_bench/core/model/slow_complex_jacobian.h"

namespace cvg_bench {
namespace {

class CubicStiffnessTerm : public ModelTerm {
 public:
  std::string name() const override { return "xi"; }
  std::vector<std::string> parameterNames() const override { return {"xi"}; }
  std::string description() const override {
    return "cubic stiffness: the natural frequency depends on amplitude squared (Duffing)";
  }
  std::vector<CandidateExtension> candidates() const override {
    return {{"xi", "xi", "cubic stiffness", "1/(s amp^2)",
             "phase-rate (tangential) residual growing with amplitude^2", false, true, true, 0}};
  }
  bool isAmplitudeLaw() const override { return true; }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext&,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    const SlowComplex z(q);
    const std::complex<double> k(0.0, 0.25);
    setComplexColumn(mul(k, 2.0 * z.n_sq * z.a + mul(z.s, std::conj(z.a))),
                     mul(k, 2.0 * z.n_sq * z.b + mul(z.s, std::conj(z.b))), d, 0);
  }
  void averagedJacobian(const Eigen::Vector4d& q, const SlowContext&,
                        const Eigen::Ref<const Eigen::VectorXd>& z_term,
                        Eigen::Matrix4d& jacobian) const override {
    setComplexJacobian(cubicColumnDerivatives(SlowComplex(q), 1.0),
                       std::complex<double>(0.0, 0.25 * z_term[0]), jacobian);
  }
  void fastColumns(const FastState& s, const FastContext& c,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    const double n = s.f * s.f + s.g * s.g;
    cols(0, 0) = c.omega_rad_s * n * s.f;
    cols(1, 0) = c.omega_rad_s * n * s.g;
  }
};

}  // namespace

ModelTermPtr makeCubicStiffnessTerm() {
  return std::make_shared<CubicStiffnessTerm>();
}

}  // namespace cvg_bench
