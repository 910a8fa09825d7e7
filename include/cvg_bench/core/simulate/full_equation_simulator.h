// Simulator of the full (fast) equations (2.3)/(3.1):
//   f'' + omega^2 f = F_f,   g'' + omega^2 g = F_g,   (F_f, F_g) = ResonatorModel::fastForce (+ the
//   optional 2 omega0 parametric terms of (2.1), ParametricPumping).
// Integrated exactly (no averaging) in osculating van der Pol variables x = (q1, p1, q2, p2) at a
// reference frequency W (W = omega for free decay, W = omega0 for forced oscillations), the change
// of variables (2.4):
//   f = q1 cos Wt + p1 sin Wt,   f' = W (p1 cos Wt - q1 sin Wt)   (g likewise with q2, p2),
// which turns the equations into
//   q1' = -(G_f / W) sin Wt,   p1' = (G_f / W) cos Wt,   G_f = F_f + (W^2 - omega^2) f
// (likewise q2', p2' with G_g). Classical RK4 on these integrates the omega^2 f part analytically,
// so the truncation error scales with the small forces: 20 steps per period already give phase
// errors far below the averaging error. Allocation-free per step.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

/// The 2 omega0 parametric terms of (2.1) that (3.1) drops (docs/paper.md item 6), simulator only:
///   F_f += -(eta/2) ((u1^2 - u2^2) cos 2 omega0 t + 2 u1 u2 sin 2 omega0 t) f,  g likewise (u3,
///   u4),
/// with the physical voltages u_i = u~_i omega / eta, i.e. the coefficient is omega^2 / (2 eta)
/// times the u~ combination. eta [1/s^2 in normalized amplitude units] is the electrostatic
/// coefficient of (2.1) (its cubic stiffness is 3 eta, i.e. xi~ = 3 eta / omega); eta = 0 is off.
struct ParametricPumping {
  double eta = 0.0;                                   ///< >= 0; 0 switches the terms off
  Eigen::Vector4d u_tilde = Eigen::Vector4d::Zero();  ///< u~1..u~4 [1/s x amplitude]
  bool active() const { return eta > 0.0 && u_tilde.squaredNorm() > 0.0; }
  /// Its generalized force at drive phase omega0 t = drive_phase_rad.
  Eigen::Vector2d force(double f, double g, double drive_phase_rad, double omega_rad_s) const;
};

struct FullEquationSimulatorOptions {
  /// RK4 steps per period 2 pi / W of the reference frequency; >= 4 (20 is accurate, see header).
  int steps_per_period = 20;
  /// Every problem, empty when valid.
  std::vector<std::string> validate() const;
};

class FullEquationSimulator {
 public:
  /// model and z: the truth model and its parameter vector (regression units); omega_rad_s: the
  /// natural frequency omega; reference_rad_s: W (= omega for free decay, = omega0 forced; the
  /// drive phase of the controls is W t); mu: known control nonlinearity. InputError on bad input.
  FullEquationSimulator(const ResonatorModel& model, const Eigen::VectorXd& z, double omega_rad_s,
                        double reference_rad_s, double mu = 0.0,
                        const ParametricPumping& pumping = {},
                        const FullEquationSimulatorOptions& options = {});

  /// Sets the osculating state x = (q1, p1, q2, p2) at time t_s (t enters the phase W t and the
  /// slowly varying terms, e.g. cm_rate).
  void reset(const Eigen::Vector4d& x, double t_s = 0.0);
  /// Sets the state from f, f', g, g' at time t_s.
  void resetFast(const FastState& s, double t_s = 0.0);
  const Eigen::Vector4d& osculating() const { return x_; }
  double time() const { return t_; }
  double omega() const { return omega_; }
  double reference() const { return w_; }
  /// f, f', g, g' now.
  FastState fastState() const;
  /// Largest step: 2 pi / (W steps_per_period) [s].
  double maxStep() const { return max_step_; }

  /// One RK4 step of length h_s > 0.
  void step(double h_s);
  /// Advances to t_end_s (>= time()) in equal steps no longer than maxStep().
  void advanceTo(double t_end_s);
  /// Appends n samples f, g at times time() + k / rate_hz, k = 0..n-1, to out (t_s, f, g), leaving
  /// the state at the time after the last sample. Steps are sample intervals split evenly into
  /// pieces no longer than maxStep(), so every sample lies on the step grid.
  void sampleRaw(double rate_hz, size_t n, RawRecord& out);

 private:
  Eigen::Vector4d rhs(double t, const Eigen::Vector4d& x, double c, double s) const;

  /// (F_f, F_g) of the model's terms (the same sum as ResonatorModel::fastForce, with the terms'
  /// column counts cached so that a step allocates nothing).
  Eigen::Vector2d modelForce(const FastState& s, const FastContext& ctx) const;

  ResonatorModel model_;
  Eigen::VectorXd z_;
  std::vector<int> term_columns_;  ///< parameters per term, in model_.terms() order
  double omega_, w_, mu_;
  ParametricPumping pumping_;
  double max_step_;
  double inv_w_ = 1.0;           ///< 1 / W [s]
  double detune_over_w_ = 0.0;   ///< (W^2 - omega^2) / W [rad/s]
  bool pumping_active_ = false;  ///< pumping_.active(), cached
  Eigen::Vector4d x_ = Eigen::Vector4d::Zero();
  double t_ = 0.0;
  /// cos, sin of W h / 2 for the last step length h (cached: steps mostly have one length).
  double half_step_of_ = -1.0, half_cos_ = 1.0, half_sin_ = 0.0;
  /// cos, sin of W t at t = phase_t_ (the end of the last step), and the steps since they were
  /// last computed from t (carried by rotation in between; NaN time = none).
  static constexpr int kPhaseResync = 32;
  double phase_t_ = std::numeric_limits<double>::quiet_NaN(), phase_cos_ = 1.0, phase_sin_ = 0.0;
  int phase_steps_ = 0;
};

}  // namespace cvg_bench
