// One physical effect of the resonator model: the single place where its equation lives.
//
// Every term is linear in its own parameters z_term (in the regression units of (2.6)/(3.3)) and
// supplies two views of the same force:
//  - fastColumns: its generalized force in the full equations (2.3)/(3.1),
//        f'' + omega^2 f = F_f,  g'' + omega^2 g = F_g,  (F_f, F_g)^T = fastColumns * z_term;
//  - averagedColumns: its first-order Krylov-Bogoliubov average in the van der Pol variables (2.4),
//        2 q' = averagedColumns * z_term,  q = (q1, p1, q2, p2).
// The averaged view must equal the first-harmonic projection of the fast view,
//   2 q1' = -(2/omega) <F_f sin(omega t)>,  2 p1' = (2/omega) <F_f cos(omega t)>  (likewise q2, p2
//   from F_g),
// which test/core/model_term_averaging_test.cpp checks term by term by quadrature.
// Tilde quantities (stiffness-type coefficients divided by omega) are stored under the plain name;
// fastColumns multiplies them back by omega.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace cvg_bench {

/// Experiment mode of the paper: free decay (section 2) or forced oscillation (section 3).
enum class ExperimentMode { kFreeDecay, kForced };

/// Slow-time context of the averaged model.
struct SlowContext {
  /// Time since the start of the record [s] (for time-varying terms such as cm_rate).
  double t_s = 0.0;
  /// Known control nonlinearity mu of (3.1)-(3.2) [1/amplitude^2]; 0 for magnetoelectric actuators.
  double mu = 0.0;
};

/// State of the full (fast) equations.
struct FastState {
  double f = 0.0, f_dot = 0.0, g = 0.0, g_dot = 0.0;
};

/// Context of the full equations.
struct FastContext {
  /// Natural frequency omega [rad/s] (multiplies the tilde parameters back).
  double omega_rad_s = 1.0;
  /// Phase of the drive omega0 * t [rad] (controls u1..u4 of (3.1)).
  double drive_phase_rad = 0.0;
  /// Time since the start of the record [s] (slowly varying terms).
  double t_s = 0.0;
  /// Known control nonlinearity mu.
  double mu = 0.0;
  /// Optional sin and cos of drive_phase_rad, precomputed by a caller that has them anyway (the
  /// simulator's reference at W = omega0); NaN (the default) means "compute from the phase".
  double drive_sin = std::numeric_limits<double>::quiet_NaN();
  double drive_cos = std::numeric_limits<double>::quiet_NaN();
};

/// An extension of the linear base that `explain` tries as a nested model (the linear model plus
/// one term, or mu of the controls term), with the physical cause in words and the residual
/// signature it removes. Declared by the term that owns it (ModelTerm::candidates); the list
/// explain uses is src/core/diagnose/candidate_extensions.cpp walking the registry.
struct CandidateExtension {
  std::string name;       ///< extension name in a model specification: "xi", "mu", ...
  std::string parameter;  ///< the parameter it adds (same as name for all current candidates)
  std::string cause;      ///< the physical cause, a short noun phrase ("cubic stiffness")
  std::string unit;       ///< unit of the parameter in regression units, e.g. "1/(s amp^2)"
  /// What its absence leaves in the residuals (the signature it removes), in words.
  std::string signature;
  /// Estimated by output error (Ceres): mu multiplies u~ bilinearly (3.2), LS cannot fit it.
  bool needs_output_error = false;
  /// Offered in free decay / forced data (validated there as a candidate).
  bool free_decay = true;
  bool forced = true;
  /// Position in explain's candidate list (the order of forward selection's ties and of the
  /// JSON's lists; kept as it was before the terms owned their candidacy).
  int rank = 0;
};

class ModelTerm {
 public:
  virtual ~ModelTerm() = default;
  /// Canonical name (`linear`, `controls`, `xi`, `kappa`, `gamma_nl`, `cm_rate`, `xi_diff`, ...).
  virtual std::string name() const = 0;
  /// Its parameters' canonical names, in column order.
  virtual std::vector<std::string> parameterNames() const = 0;
  /// One sentence: what the term is physically.
  virtual std::string description() const = 0;
  /// What one of its parameters is physically, a short noun phrase ("frequency split"); parameters
  /// of one term with the same meaning act together (a modulus and its axis: h_c, h_s). The
  /// default is the cause of the candidate that adds the parameter, else description().
  virtual std::string parameterMeaning(const std::string& parameter) const;
  /// Whether the term exists in the given experiment mode (e.g. controls only when forced).
  virtual bool appliesTo(ExperimentMode mode) const { return true; }
  /// The extensions of the linear base this term offers to `explain` (none by default).
  virtual std::vector<CandidateExtension> candidates() const { return {}; }
  /// An amplitude law: its force grows faster than linearly with the amplitude, so data at one
  /// amplitude cannot tell it from the linear terms (identifiability.cpp), and in one free decay
  /// it is tied to time through the decay (explain's caveat, explanation.cpp).
  virtual bool isAmplitudeLaw() const { return false; }
  /// Its averaged force depends on the time since the record's start (SlowContext::t_s), as
  /// cm_rate's does: the streaming recursive identifier, whose blocks forget the origin, refuses
  /// such terms (src/ros/streaming_free_decay_rls.cpp).
  virtual bool isTimeVarying() const { return false; }
  /// 4 x k columns of the averaged regressor D(q) (2.6)/(3.3).
  virtual void averagedColumns(const Eigen::Vector4d& q, const SlowContext& ctx,
                               Eigen::Ref<Eigen::MatrixXd> cols) const = 0;
  /// 2 x k columns of the generalized force in the full equations (2.3)/(3.1).
  virtual void fastColumns(const FastState& s, const FastContext& ctx,
                           Eigen::Ref<Eigen::MatrixXd> cols) const = 0;
  /// 4 x 4 Jacobian d(averagedColumns(q) z_term)/dq (columns: d/dq1, d/dp1, d/dq2, d/dp2) for the
  /// term's parameters z_term (k entries). The default is central differences of averagedColumns;
  /// the terms override it analytically (checked against central differences by
  /// test/core/model_term_jacobian_test.cpp).
  virtual void averagedJacobian(const Eigen::Vector4d& q, const SlowContext& ctx,
                                const Eigen::Ref<const Eigen::VectorXd>& z_term,
                                Eigen::Matrix4d& jacobian) const;
  /// The same by central differences of averagedColumns (the reference for the analytic forms).
  void averagedJacobianNumerical(const Eigen::Vector4d& q, const SlowContext& ctx,
                                 const Eigen::Ref<const Eigen::VectorXd>& z_term,
                                 Eigen::Matrix4d& jacobian) const;
  int numParameters() const { return static_cast<int>(parameterNames().size()); }
};

using ModelTermPtr = std::shared_ptr<const ModelTerm>;

/// The term with this canonical name; throws InputError naming the known terms otherwise.
ModelTermPtr makeModelTerm(const std::string& name);
/// Names of all terms makeModelTerm knows, base terms first.
std::vector<std::string> knownModelTermNames();
/// Whether the parameter belongs to a registered amplitude law (ModelTerm::isAmplitudeLaw).
bool isAmplitudeLawParameter(const std::string& parameter);
/// Whether the named extension (a term name) is a registered amplitude law; false for unknown
/// names and for extensions that are no term (mu).
bool isAmplitudeLawTerm(const std::string& name);

}  // namespace cvg_bench
