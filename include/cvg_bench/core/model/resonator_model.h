// The resonator model assembled from terms: the one definition from which the averaged equations
// (2.5)/(3.2), the regressor D(q) of (2.6)/(3.3), the full equations (2.3)/(3.1) for the simulator
// and the Ceres residuals all come.
//
// Parameter vector z (regression units, in parameterNames() order):
//   linear base  gamma, nu, b_c, b_s [1/s]; c_m, n, h_c, h_s [1/s, tilde = coefficient / omega];
//   forced mode  u1..u4 [1/s x amplitude, tilde = eta u_i / omega];
//   extensions   xi, kappa, xi_diff, xi_k [tilde, 1/(s amplitude^2), 1/(s amplitude^4)], gamma_nl
//                [1/(s amplitude^2)], cm_rate [1/s^2, tilde].
// Amplitudes are in the record's units (normalized by the maximum amplitude in the paper's section
// 4).
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

/// Named parameter values in regression units (see the header comment).
using ParameterValues = std::map<std::string, double>;

/// Detuning rate of the forced averaged equations: exactly (omega0^2 - omega^2) / omega0
/// = 2 lambda - lambda^2 / (omega + lambda) with lambda = omega0 - omega (docs/paper.md item 7)
/// [rad/s].
double detuningRate(double omega_rad_s, double omega0_rad_s);

/// The vector multiplying the detuning rate in (3.2)-(3.3): y / (2 lambda) = (p1, -q1, p2, -q2).
Eigen::Vector4d detuningDirection(const Eigen::Vector4d& q);

/// "free_decay" / "forced" <-> ExperimentMode; throws InputError for other names.
ExperimentMode parseExperimentMode(const std::string& name);
std::string experimentModeName(ExperimentMode mode);

/// Upper bound on the number of parameters of one model (fixed-capacity, allocation-free matrices).
constexpr int kMaxModelParameters = 32;

class ResonatorModel {
 public:
  /// spec: `linear` or `+`-joined extension names (`xi`, `xi+kappa`, `linear+xi`; the linear base
  /// is always included, `controls` is added in forced mode). Throws InputError for an unknown
  /// term, a duplicate, or a term that does not apply to the mode (e.g. cm_rate in forced mode).
  ResonatorModel(const std::string& spec, ExperimentMode mode);
  /// The same from the extension names (empty = `linear`), e.g. a nested model of the selection.
  ResonatorModel(const std::vector<std::string>& extensions, ExperimentMode mode);

  /// Name of the control nonlinearity of (3.1)-(3.2) in specs and estimates.
  static const std::string& muName();

  ExperimentMode mode() const { return mode_; }
  /// Canonical spec: `linear`, `linear+xi`, `linear+xi+kappa`, ...
  std::string spec() const;
  /// Names of the extension terms in the order given (empty for `linear`).
  const std::vector<std::string>& extensionNames() const { return extensions_; }
  /// True when the spec holds `mu` (forced mode only): mu multiplies u~ bilinearly in (3.2), so it
  /// is an unknown of the output-error fit, not a column of D(q) (parameterNames() lacks it).
  bool estimatesMu() const { return estimates_mu_; }
  /// The model without `mu`: the part linear in z that least squares can fit.
  ResonatorModel linearPart() const;
  const std::vector<ModelTermPtr>& terms() const { return terms_; }
  const std::vector<std::string>& parameterNames() const { return names_; }
  int numParameters() const { return static_cast<int>(names_.size()); }
  /// Index of a parameter in z, or -1.
  int indexOf(const std::string& name) const;

  /// D(q) of (2.6)/(3.3), 4 x numParameters().
  void regressor(const Eigen::Vector4d& q, const SlowContext& ctx,
                 Eigen::Ref<Eigen::MatrixXd> d) const;
  Eigen::MatrixXd regressor(const Eigen::Vector4d& q, const SlowContext& ctx) const;

  /// q' of the averaged equations: 2 q' = D(q) z - detuning_rate (p1, -q1, p2, -q2)
  /// ((2.6) in free decay with detuning_rate = 0, (3.3) when forced).
  Eigen::Vector4d slowDerivative(const Eigen::Vector4d& q, const SlowContext& ctx,
                                 const Eigen::VectorXd& z, double detuning_rate = 0.0) const;

  /// G = d(D(q) z)/dq, 4 x 4 (columns d/dq1, d/dp1, d/dq2, d/dp2): the sum of the terms'
  /// averagedJacobian (analytic); the linearization of (2.6)/(3.3) in the state, e.g. for the
  /// errors-in-variables covariance of the identification.
  void regressorJacobian(const Eigen::Vector4d& q, const SlowContext& ctx,
                         const Eigen::Ref<const Eigen::VectorXd>& z,
                         Eigen::Matrix4d& jacobian) const;
  /// d q' / dq of slowDerivative (with the same detuning_rate), 4 x 4.
  Eigen::Matrix4d slowJacobian(const Eigen::Vector4d& q, const SlowContext& ctx,
                               const Eigen::VectorXd& z, double detuning_rate = 0.0) const;

  /// Generalized forces (F_f, F_g) of the full equations (2.3)/(3.1):
  /// f'' + omega^2 f = F_f, g'' + omega^2 g = F_g.
  Eigen::Vector2d fastForce(const FastState& s, const FastContext& ctx,
                            const Eigen::VectorXd& z) const;

  /// z from named values; names the model lacks are an InputError when strict, else ignored;
  /// parameters missing from values are 0. Non-finite values are an InputError.
  Eigen::VectorXd parameterVector(const ParameterValues& values, bool strict = false) const;
  /// Named values from z.
  ParameterValues parameterValues(const Eigen::VectorXd& z) const;

 private:
  void addTerms(const std::vector<std::string>& parts, const std::string& spec);

  ExperimentMode mode_;
  bool estimates_mu_ = false;
  std::vector<std::string> extensions_;
  std::vector<ModelTermPtr> terms_;
  std::vector<int> offsets_;
  std::vector<int> sizes_;  ///< number of parameters of each term (cached: no per-call lookups)
  std::vector<std::string> names_;
};

}  // namespace cvg_bench
