#include "cvg_bench/core/simulate/averaged_model_simulator.h"

#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

std::vector<std::string> AveragedModelSimulatorOptions::validate() const {
  std::vector<std::string> p;
  if (!(relative_tolerance > 0.0 && relative_tolerance < 1.0))
    p.push_back("relative_tolerance must be in (0, 1)");
  if (!(absolute_tolerance > 0.0) || !std::isfinite(absolute_tolerance))
    p.push_back("absolute_tolerance must be > 0");
  if (!(max_step_s > 0.0) || !std::isfinite(max_step_s)) p.push_back("max_step_s must be > 0");
  return p;
}

AveragedModelSimulator::AveragedModelSimulator(const ResonatorModel& model,
                                               const Eigen::VectorXd& z, double mu,
                                               double detuning_rate,
                                               const AveragedModelSimulatorOptions& options)
    : model_(model), z_(z), mu_(mu), rate_(detuning_rate), options_(options) {
  requireFinite(mu, "mu");
  requireFinite(detuning_rate, "detuning rate");
  if (z.size() != model.numParameters())
    throw InputError("parameter vector has " + std::to_string(z.size()) + " entries, model " +
                     model.spec() + " needs " + std::to_string(model.numParameters()));
  if (!z.allFinite()) throw InputError("model parameters must be finite");
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("slow simulator: " + problems.front());
}

void AveragedModelSimulator::reset(const Eigen::Vector4d& q, double t_s) {
  if (!q.allFinite()) throw InputError("initial state must be finite");
  requireFinite(t_s, "initial time");
  q_ = q;
  t_ = t_s;
  h_ = 0.0;
}

void AveragedModelSimulator::setDetuningRate(double detuning_rate) {
  requireFinite(detuning_rate, "detuning rate");
  rate_ = detuning_rate;
  h_ = 0.0;
}

Eigen::Vector4d AveragedModelSimulator::rhs(double t, const Eigen::Vector4d& q) const {
  return model_.slowDerivative(q, SlowContext{t, mu_}, z_, rate_);
}

Eigen::Vector4d AveragedModelSimulator::derivative() const {
  return rhs(t_, q_);
}

void AveragedModelSimulator::advanceTo(double t_end) {
  requireFinite(t_end, "end time");
  if (t_end < t_) throw InputError("slow simulator cannot run backwards in time");
  // Dormand-Prince 5(4) tableau (FSAL: the 7th stage is the next step's first).
  static constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
  static constexpr double a21 = 1.0 / 5, a31 = 3.0 / 40, a32 = 9.0 / 40, a41 = 44.0 / 45,
                          a42 = -56.0 / 15, a43 = 32.0 / 9, a51 = 19372.0 / 6561,
                          a52 = -25360.0 / 2187, a53 = 64448.0 / 6561, a54 = -212.0 / 729,
                          a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247,
                          a64 = 49.0 / 176, a65 = -5103.0 / 18656;
  static constexpr double b1 = 35.0 / 384, b3 = 500.0 / 1113, b4 = 125.0 / 192, b5 = -2187.0 / 6784,
                          b6 = 11.0 / 84;
  static constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920,
                          e5 = -17253.0 / 339200, e6 = 22.0 / 525, e7 = -1.0 / 40;
  const double rtol = options_.relative_tolerance, atol = options_.absolute_tolerance;
  Eigen::Vector4d k1 = rhs(t_, q_);
  if (h_ <= 0.0) {
    // A first step over which the state changes by ~1e-3 of its size; the control adapts it.
    const double size = std::max(q_.cwiseAbs().maxCoeff(), atol / rtol);
    const double rate = k1.cwiseAbs().maxCoeff();
    h_ = rate > 0.0 ? 1e-3 * size / rate : options_.max_step_s;
    h_ = std::min(std::max(h_, 1e-12), options_.max_step_s);
  }
  while (t_ < t_end) {
    const double remaining = t_end - t_;
    double h = std::min(h_, options_.max_step_s);
    const bool last = h >= remaining;
    if (last) h = remaining;
    const Eigen::Vector4d k2 = rhs(t_ + c2 * h, q_ + h * a21 * k1);
    const Eigen::Vector4d k3 = rhs(t_ + c3 * h, q_ + h * (a31 * k1 + a32 * k2));
    const Eigen::Vector4d k4 = rhs(t_ + c4 * h, q_ + h * (a41 * k1 + a42 * k2 + a43 * k3));
    const Eigen::Vector4d k5 =
        rhs(t_ + c5 * h, q_ + h * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4));
    const Eigen::Vector4d k6 =
        rhs(t_ + h, q_ + h * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5));
    const Eigen::Vector4d q_new = q_ + h * (b1 * k1 + b3 * k3 + b4 * k4 + b5 * k5 + b6 * k6);
    const Eigen::Vector4d k7 = rhs(t_ + h, q_new);
    const Eigen::Vector4d err = h * (e1 * k1 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7);
    const Eigen::Vector4d tol =
        (atol + rtol * q_.cwiseAbs().cwiseMax(q_new.cwiseAbs()).array()).matrix();
    const double ratio = (err.cwiseAbs().array() / tol.array()).maxCoeff();
    if (!std::isfinite(ratio) || !q_new.allFinite())
      throw AnalysisError("slow simulator: state is no longer finite at t = " + std::to_string(t_) +
                          " s");
    const double factor = ratio > 0.0 ? std::clamp(0.9 * std::pow(ratio, -0.2), 0.2, 5.0) : 5.0;
    if (ratio <= 1.0) {
      t_ = last ? t_end : t_ + h;
      q_ = q_new;
      k1 = k7;
      ++steps_;
      // Keep the free step size when the step was only shortened to land on t_end.
      if (!last || h == h_) h_ = h * factor;
    } else {
      h_ = h * factor;
      if (h_ < 1e-14 * std::max(1.0, std::abs(t_)))
        throw AnalysisError("slow simulator: step size underflow at t = " + std::to_string(t_) +
                            " s (stiff or singular dynamics)");
    }
  }
}

void AveragedModelSimulator::sample(double rate_hz, size_t n, SlowRecord& out) {
  requirePositive(rate_hz, "sample rate");
  const double t0 = t_;
  out.t_s.reserve(out.t_s.size() + n);
  out.q.reserve(out.q.size() + n);
  for (size_t k = 0; k < n; ++k) {
    advanceTo(t0 + k / rate_hz);
    out.t_s.push_back(t_);
    out.q.push_back(q_);
  }
}

}  // namespace cvg_bench
