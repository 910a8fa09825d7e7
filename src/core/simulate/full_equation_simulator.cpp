#include "cvg_bench/core/simulate/full_equation_simulator.h"

#include <cmath>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

Eigen::Vector2d ParametricPumping::force(double f, double g, double drive_phase_rad,
                                         double omega_rad_s) const {
  if (!active()) return Eigen::Vector2d::Zero();
  // (eta/2) u_i u_j = (eta/2) (omega/eta)^2 u~_i u~_j = omega^2 / (2 eta) u~_i u~_j.
  const double k = omega_rad_s * omega_rad_s / (2.0 * eta);
  const double c2 = std::cos(2.0 * drive_phase_rad), s2 = std::sin(2.0 * drive_phase_rad);
  const Eigen::Vector4d& u = u_tilde;
  return Eigen::Vector2d(-k * ((u[0] * u[0] - u[1] * u[1]) * c2 + 2.0 * u[0] * u[1] * s2) * f,
                         -k * ((u[2] * u[2] - u[3] * u[3]) * c2 + 2.0 * u[2] * u[3] * s2) * g);
}

std::vector<std::string> FullEquationSimulatorOptions::validate() const {
  std::vector<std::string> problems;
  if (steps_per_period < 4)
    problems.push_back("steps_per_period must be >= 4, got " + std::to_string(steps_per_period));
  return problems;
}

FullEquationSimulator::FullEquationSimulator(const ResonatorModel& model, const Eigen::VectorXd& z,
                                             double omega_rad_s, double reference_rad_s, double mu,
                                             const ParametricPumping& pumping,
                                             const FullEquationSimulatorOptions& options)
    : model_(model), z_(z), omega_(omega_rad_s), w_(reference_rad_s), mu_(mu), pumping_(pumping) {
  requirePositive(omega_rad_s, "omega");
  requirePositive(reference_rad_s, "reference frequency W");
  requireFinite(mu, "mu");
  requireFinite(pumping.eta, "eta");
  if (pumping.eta < 0.0) throw InputError("eta must be >= 0 (0 = no parametric terms)");
  if (!pumping.u_tilde.allFinite()) throw InputError("u~ of the parametric terms must be finite");
  if (z.size() != model.numParameters())
    throw InputError("parameter vector has " + std::to_string(z.size()) + " entries, model " +
                     model.spec() + " needs " + std::to_string(model.numParameters()));
  if (!z.allFinite()) throw InputError("model parameters must be finite");
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("fast simulator: " + problems.front());
  max_step_ = 2.0 * M_PI / (w_ * options.steps_per_period);
  inv_w_ = 1.0 / w_;
  detune_over_w_ = (w_ * w_ - omega_ * omega_) * inv_w_;
  pumping_active_ = pumping_.active();
  for (const auto& term : model_.terms()) term_columns_.push_back(term->numParameters());
}

// Not vectorized on purpose: the terms have just written cols entry by entry, and a 16-byte load
// spanning two 8-byte stores cannot be store-forwarded (a stall per column pair).
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-vectorize")))
#endif
Eigen::Vector2d
FullEquationSimulator::modelForce(const FastState& s, const FastContext& ctx) const {
  Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, kMaxModelParameters> cols(2, z_.size());
  int offset = 0;
  const auto& terms = model_.terms();
  for (size_t i = 0; i < terms.size(); ++i) {
    terms[i]->fastColumns(s, ctx, cols.middleCols(offset, term_columns_[i]));
    offset += term_columns_[i];
  }
  // cols * z in registers, two independent chains per row (no store-reload per column).
  const double* a = cols.data();
  const double* z = z_.data();
  double f0 = 0.0, g0 = 0.0, f1 = 0.0, g1 = 0.0;
  int j = 0;
  for (; j + 1 < offset; j += 2) {
    f0 += a[2 * j] * z[j];
    g0 += a[2 * j + 1] * z[j];
    f1 += a[2 * j + 2] * z[j + 1];
    g1 += a[2 * j + 3] * z[j + 1];
  }
  if (j < offset) {
    f0 += a[2 * j] * z[j];
    g0 += a[2 * j + 1] * z[j];
  }
  return Eigen::Vector2d(f0 + f1, g0 + g1);
}

void FullEquationSimulator::reset(const Eigen::Vector4d& x, double t_s) {
  if (!x.allFinite()) throw InputError("initial state must be finite");
  requireFinite(t_s, "initial time");
  x_ = x;
  t_ = t_s;
}

void FullEquationSimulator::resetFast(const FastState& s, double t_s) {
  // Inverse of (2.4): q1 = f cos - (f'/W) sin, p1 = f sin + (f'/W) cos.
  const double c = std::cos(w_ * t_s), sn = std::sin(w_ * t_s);
  reset(Eigen::Vector4d(s.f * c - s.f_dot / w_ * sn, s.f * sn + s.f_dot / w_ * c,
                        s.g * c - s.g_dot / w_ * sn, s.g * sn + s.g_dot / w_ * c),
        t_s);
}

FastState FullEquationSimulator::fastState() const {
  const double c = std::cos(w_ * t_), s = std::sin(w_ * t_);
  return FastState{x_[0] * c + x_[1] * s, w_ * (x_[1] * c - x_[0] * s), x_[2] * c + x_[3] * s,
                   w_ * (x_[3] * c - x_[2] * s)};
}

Eigen::Vector4d FullEquationSimulator::rhs(double t, const Eigen::Vector4d& x, double c,
                                           double s) const {
  const FastState st{x[0] * c + x[1] * s, w_ * (x[1] * c - x[0] * s), x[2] * c + x[3] * s,
                     w_ * (x[3] * c - x[2] * s)};
  // The reference runs at W = omega0, the drive frequency: (c, s) are the drive phase's cos, sin.
  const FastContext ctx{omega_, w_ * t, t, mu_, s, c};
  Eigen::Vector2d force = modelForce(st, ctx);
  if (pumping_active_) force += pumping_.force(st.f, st.g, w_ * t, omega_);
  const double gf = force[0] * inv_w_ + detune_over_w_ * st.f;
  const double gg = force[1] * inv_w_ + detune_over_w_ * st.g;
  return Eigen::Vector4d(-gf * s, gf * c, -gg * s, gg * c);
}

void FullEquationSimulator::step(double h) {
  const double t0 = t_, tm = t_ + 0.5 * h, t1 = t_ + h;
  // Phase W t at the start: carried over from the previous step's end by rotation when the step
  // continues it, recomputed from t every kPhaseResync steps (rounding drift stays ~1e-15 rad).
  double c0, s0;
  if (t0 == phase_t_ && phase_steps_ < kPhaseResync) {
    c0 = phase_cos_;
    s0 = phase_sin_;
    ++phase_steps_;
  } else {
    c0 = std::cos(w_ * t0);
    s0 = std::sin(w_ * t0);
    phase_steps_ = 0;
  }
  if (h != half_step_of_) {
    half_step_of_ = h;
    half_cos_ = std::cos(0.5 * w_ * h);
    half_sin_ = std::sin(0.5 * w_ * h);
  }
  const double cm = c0 * half_cos_ - s0 * half_sin_, sm = s0 * half_cos_ + c0 * half_sin_;
  const double c1 = cm * half_cos_ - sm * half_sin_, s1 = sm * half_cos_ + cm * half_sin_;
  const Eigen::Vector4d k1 = rhs(t0, x_, c0, s0);
  const Eigen::Vector4d k2 = rhs(tm, x_ + 0.5 * h * k1, cm, sm);
  const Eigen::Vector4d k3 = rhs(tm, x_ + 0.5 * h * k2, cm, sm);
  const Eigen::Vector4d k4 = rhs(t1, x_ + h * k3, c1, s1);
  x_ += (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  t_ = t1;
  phase_t_ = t1;
  phase_cos_ = c1;
  phase_sin_ = s1;
}

void FullEquationSimulator::advanceTo(double t_end_s) {
  requireFinite(t_end_s, "end time");
  const double span = t_end_s - t_;
  if (span < 0.0) throw InputError("fast simulator cannot run backwards in time");
  if (span == 0.0) return;
  const long n = std::max(1L, static_cast<long>(std::ceil(span / max_step_ - 1e-9)));
  const double h = span / n, t0 = t_;
  for (long k = 0; k < n; ++k) {
    step(h);
    t_ = t0 + (k + 1) * h;  // no accumulated rounding in t
    phase_t_ = t_;          // the carried phase belongs to this grid time (within an ulp)
  }
  t_ = t_end_s;
}

void FullEquationSimulator::sampleRaw(double rate_hz, size_t n, RawRecord& out) {
  requirePositive(rate_hz, "sample rate");
  const double dt = 1.0 / rate_hz;
  const long m = std::max(1L, static_cast<long>(std::ceil(dt / max_step_ - 1e-9)));
  const double h = dt / m, t0 = t_;
  out.t_s.reserve(out.t_s.size() + n);
  out.f.reserve(out.f.size() + n);
  out.g.reserve(out.g.size() + n);
  for (size_t k = 0; k < n; ++k) {
    t_ = t0 + k * dt;
    const FastState s = fastState();
    out.t_s.push_back(t_);
    out.f.push_back(s.f);
    out.g.push_back(s.g);
    for (long j = 0; j < m; ++j) {
      step(h);
      t_ = t0 + k * dt + (j + 1) * h;
      phase_t_ = t_;
    }
  }
  t_ = t0 + n * dt;
}

}  // namespace cvg_bench
