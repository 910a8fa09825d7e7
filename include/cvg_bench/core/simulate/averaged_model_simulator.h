// Simulator of the averaged (slow) model, q' = ResonatorModel::slowDerivative:
//   2 q' = D(q) z - rate (p1, -q1, p2, -q2)   ((2.6) free decay with rate = 0; (3.3) forced with
//   rate = detuningRate(omega, omega0)),
// integrated by the adaptive Dormand-Prince 5(4) Runge-Kutta pair. It is the fast path for long
// high-Q runs (an HRG ring-down of minutes to hours costs milliseconds) and settles forced sweep
// steps. It has the first-order averaging error of the model against the full equations
// (FullEquationSimulator), relative size ~ |rates| / omega.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

struct AveragedModelSimulatorOptions {
  /// Relative error tolerance per step, in (0, 1).
  double relative_tolerance = 1e-10;
  /// Absolute error tolerance per step [amplitude units], > 0.
  double absolute_tolerance = 1e-14;
  /// Largest step [s], > 0 (also bounds the first step).
  double max_step_s = 10.0;
  /// Every problem, empty when valid.
  std::vector<std::string> validate() const;
};

class AveragedModelSimulator {
 public:
  /// model and z: the truth model (regression units); mu: known control nonlinearity (forced);
  /// detuning_rate: (omega0^2 - omega^2) / omega0 [rad/s] (0 in free decay). InputError on bad
  /// input.
  AveragedModelSimulator(const ResonatorModel& model, const Eigen::VectorXd& z, double mu = 0.0,
                         double detuning_rate = 0.0,
                         const AveragedModelSimulatorOptions& options = {});

  void reset(const Eigen::Vector4d& q, double t_s = 0.0);
  const Eigen::Vector4d& state() const { return q_; }
  double time() const { return t_; }
  /// Changes the detuning rate (forced sweep steps) keeping the state.
  void setDetuningRate(double detuning_rate);
  /// q' at the current state.
  Eigen::Vector4d derivative() const;
  /// Advances to t_end_s (>= time()) with adaptive steps; AnalysisError if the step size
  /// underflows or the state stops being finite.
  void advanceTo(double t_end_s);
  /// Appends n samples at times time() + k / rate_hz, k = 0..n-1, to out (t_s, q).
  void sample(double rate_hz, size_t n, SlowRecord& out);
  /// Accepted steps so far (for benchmarks).
  long stepsTaken() const { return steps_; }

 private:
  Eigen::Vector4d rhs(double t, const Eigen::Vector4d& q) const;

  ResonatorModel model_;
  Eigen::VectorXd z_;
  double mu_, rate_;
  AveragedModelSimulatorOptions options_;
  Eigen::Vector4d q_ = Eigen::Vector4d::Zero();
  double t_ = 0.0;
  double h_ = 0.0;  ///< step proposed for the next call (0: choose afresh)
  long steps_ = 0;
};

}  // namespace cvg_bench
