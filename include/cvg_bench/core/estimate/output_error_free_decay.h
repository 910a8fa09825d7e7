// Output-error residuals of a free-decay record (section 2) for Ceres.
//
// The model trajectory integrates the averaged equations (2.6), 2 q' = D(q) z, by classical RK4 on
// the record's own time grid t_0..t_N (optionally with substeps) from the fitted initial slow
// variables q(t_0):
//   r_i = q_model(t_i; z, q(t_0)) - q_measured(t_i),  i = 0..N  (4 (N + 1) residuals, units of q).
// Unlike the equation error of (2.7)-(2.8), the noisy measurement never enters the model, so the
// residuals are the measurement noise itself, which makes Ceres' covariance honest (docs/paper.md
// items 10, 15); noise filtered by the demodulator is correlated between samples, and a record that
// says how (demodulator_noise.h) gets the covariance with that correlation (docs/validation.md).
// Derivatives: forward sensitivities S = dq/d(z, q(t_0)) integrated by the same RK4 steps as the
// trajectory (S' = A(q) S + [B(q), 0], A = d q'/dq = G/2, B = d q'/dz = D(q)/2 of (2.6)): the exact
// derivative of the discrete RK4 map, one augmented integration instead of 2 per unknown.
// Numeric differences (central, Ridders) remain available as the reference the tests compare with.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <vector>

#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

/// q_model at every time of t_s (t_s[0] is the start, SlowContext::t_s counts from it) by RK4 with
/// `substeps` steps per interval. Returns false (trajectory left unfinished) when it overflows.
bool integrateSlowTrajectory(const ResonatorModel& model, const Eigen::VectorXd& z,
                             const Eigen::Vector4d& q0, const std::vector<double>& t_s,
                             int substeps, std::vector<Eigen::Vector4d>* trajectory);

/// The trajectory and its sensitivities at every time of t_s: (*sensitivity)[i] = d q(t_i) /
/// d(z, q(t_0)), 4 x (numParameters() + 4), by RK4 differentiated stage by stage (exact for the
/// discrete scheme). Returns false when the trajectory or a sensitivity overflows.
bool integrateSlowSensitivities(const ResonatorModel& model, const Eigen::VectorXd& z,
                                const Eigen::Vector4d& q0, const std::vector<double>& t_s,
                                int substeps, std::vector<Eigen::Vector4d>* trajectory,
                                std::vector<Eigen::Matrix<double, 4, Eigen::Dynamic>>* sensitivity);

/// The trajectory and d q(t_i) / d q(t_0) (4 x 4) alone, sample by sample: visit(i, q_i, S_i).
/// For fits of the initial state at fixed z (a quarter of the work of all sensitivities).
bool integrateSlowInitialSensitivity(
    const ResonatorModel& model, const Eigen::VectorXd& z, const Eigen::Vector4d& q0,
    const std::vector<double>& t_s, int substeps,
    const std::function<void(size_t, const Eigen::Vector4d&, const Eigen::Matrix4d&)>& visit);

/// The residual functor: parameter blocks (z [numParameters()], q(t_0) [4]), each in units of its
/// scale: z = z_scale .* x_z, q(t_0) = q0_scale * x_q. Scaling makes the unknowns O(1), so the
/// numeric-difference steps (which have absolute floors in Ceres) suit any amplitude unit (pixels,
/// volts) and parameter size.
class FreeDecayOutputError {
 public:
  /// Keeps references to model and record: both must outlive the functor. z_scale: numParameters()
  /// positive entries (empty = all 1); q0_scale > 0.
  FreeDecayOutputError(const ResonatorModel& model, const SlowRecord& record, int substeps,
                       const Eigen::VectorXd& z_scale = Eigen::VectorXd(), double q0_scale = 1.0);
  bool operator()(double const* const* parameters, double* residuals) const;
  int numResiduals() const { return 4 * static_cast<int>(record_.size()); }

 private:
  const ResonatorModel& model_;
  const SlowRecord& record_;
  int substeps_;
  Eigen::VectorXd z_scale_;
  double q0_scale_;
};

/// How the Jacobian of the trajectory residuals is obtained.
enum class TrajectoryDerivative {
  kSensitivity,  ///< forward sensitivities (exact for the RK4 map, one augmented integration)
  kCentral,      ///< central differences (2 trajectories per unknown, ~1e-10 relative accuracy)
  kRidders,  ///< Ridders' extrapolation (several times dearer, ~1e-13): the final Jacobian of the
             ///< covariance and the rank decision
};

/// The Ceres cost function over the scaled blocks (x_z, x_q) of FreeDecayOutputError.
std::unique_ptr<ceres::CostFunction> makeFreeDecayOutputErrorCost(
    const ResonatorModel& model, const SlowRecord& record, int substeps,
    TrajectoryDerivative derivative = TrajectoryDerivative::kSensitivity,
    const Eigen::VectorXd& z_scale = Eigen::VectorXd(), double q0_scale = 1.0);

/// The same problem in square-root form for the solver (k + 5 residuals, nothing per sample kept):
/// the factor [R c; 0 rho] of [J | r] folded sample by sample; LM sees the same cost, gradient and
/// Gauss-Newton matrix as with makeFreeDecayOutputErrorCost(kSensitivity). Not for the covariance
/// or the residual tests (they need the per-sample rows: evaluateFreeDecayOutputError).
/// last_pass (optional) receives what each evaluation with Jacobians saw (SquareRootPass).
struct SquareRootPass;
std::unique_ptr<ceres::CostFunction> makeFreeDecaySquareRootCost(
    const ResonatorModel& model, const SlowRecord& record, int substeps,
    const Eigen::VectorXd& z_scale = Eigen::VectorXd(), double q0_scale = 1.0,
    SquareRootPass* last_pass = nullptr);

/// The square-root cost's pass over the record with Jacobians: the unknowns it was made at (the
/// scaled blocks x_z, x_q stacked), the factor [R c; 0 rho] of [J | r] (J of the scaled blocks),
/// the residual sum of squares and the lag-one sum r_1.r_0 + r_2.r_1 + ... of the per-sample
/// residual 4-vectors: what the rank, the white-noise covariance and the residuals' lag-1 test
/// need, without the per-sample rows.
struct SquareRootPass {
  Eigen::VectorXd x;
  Eigen::MatrixXd r_aug;
  double ss = 0.0;
  double lag_one = 0.0;
};

/// Residuals r_i = q_model(t_i) - q_measured(t_i) (4 (N + 1)) and their Jacobian with respect to
/// the unscaled unknowns (z, q(t_0)), 4 (N + 1) x (numParameters() + 4), by forward sensitivities,
/// written straight into dense storage. False when the trajectory overflows.
bool evaluateFreeDecayOutputError(const ResonatorModel& model, const SlowRecord& record,
                                  int substeps, const Eigen::VectorXd& z, const Eigen::Vector4d& q0,
                                  Eigen::MatrixXd* jacobian, Eigen::VectorXd* residuals);

}  // namespace cvg_bench
