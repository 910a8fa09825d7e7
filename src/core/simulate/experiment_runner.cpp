#include "cvg_bench/core/simulate/experiment_runner.h"

#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/model/stationary_solver.h"
#include "cvg_bench/core/simulate/averaged_model_simulator.h"
#include "cvg_bench/core/simulate/full_equation_simulator.h"
#include "cvg_bench/core/simulate/measurement_noise.h"

namespace cvg_bench {
namespace {

/// The forced truth model with its parameters and the amplitude scale |u~| / gamma.
struct ForcedSystem {
  ResonatorModel model;
  Eigen::VectorXd z;
  double mu, omega, gamma, amplitude_scale;

  /// pre_drive: the drive before a free decay, which ignores free-decay-only effects (cm_rate).
  explicit ForcedSystem(const ResonatorPreset& p, bool pre_drive = false)
      : model(p.truthModelSpec(ExperimentMode::kForced, pre_drive), ExperimentMode::kForced),
        z(p.truthParameters(model)),
        mu(p.mu),
        omega(p.omega_rad_s),
        gamma(p.parameters.at("gamma")),
        amplitude_scale(std::max(p.drive_u_tilde.norm() / gamma, 1e-12)) {}

  double rate(double lambda) const { return detuningRate(omega, omega + lambda); }
};

struct NewtonResult {
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  bool converged = false;
};

/// Damped Newton on F(q) = 0 (the shared stationary solver), scaled to the drive's amplitude.
NewtonResult solveStationary(const ForcedSystem& sys, double rate, const Eigen::Vector4d& start) {
  StationarySolverOptions o;
  o.max_iterations = 40;
  o.step_tolerance = 1e-12;
  o.q_scale = sys.amplitude_scale;
  o.difference_step = 1e-7;
  o.min_reciprocal_condition = 1e-13;
  const StationaryPoint p =
      solveStationaryPoint(sys.model, sys.z, SlowContext{0.0, sys.mu}, rate, start, o);
  NewtonResult r;
  r.q = p.q;
  r.converged = p.converged && p.q.allFinite();
  return r;
}

struct Settled {
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  bool settled = false;
  double time_s = 0.0;
};

/// Integrates the averaged forced model from q_start until |q'| < tol gamma max(|q|, 1e-6 scale)
/// or max_time_s, then polishes by Newton when Newton stays close.
Settled settle(const ForcedSystem& sys, double lambda, const Eigen::Vector4d& q_start,
               double tolerance, double max_time_s) {
  AveragedModelSimulatorOptions so;
  so.max_step_s = 0.5 / sys.gamma;
  AveragedModelSimulator sim(sys.model, sys.z, sys.mu, sys.rate(lambda), so);
  sim.reset(q_start, 0.0);
  const double chunk = std::min(max_time_s, 0.5 / sys.gamma);
  Settled s;
  while (sim.time() < max_time_s) {
    sim.advanceTo(std::min(max_time_s, sim.time() + chunk));
    const double size = std::max(sim.state().norm(), 1e-6 * sys.amplitude_scale);
    if (sim.derivative().norm() < tolerance * sys.gamma * size) {
      s.settled = true;
      break;
    }
  }
  s.q = sim.state();
  s.time_s = sim.time();
  const NewtonResult polished = solveStationary(sys, sys.rate(lambda), s.q);
  if (polished.converged &&
      (polished.q - s.q).norm() <= 1e-3 * std::max(s.q.norm(), 1e-6 * sys.amplitude_scale))
    s.q = polished.q;
  return s;
}

/// Natural-parameter continuation of the branch through q_prev at lambda_prev to lambda, with
/// adaptive sub-steps: a Newton sub-step that moves the state by more than 10 % of its size is
/// halved. False when the branch ends before lambda (a fold: the sub-step shrinks below 1/4096 of
/// the step, the Jacobian is singular, or Newton fails).
bool continueBranch(const ForcedSystem& sys, double lambda_prev, double lambda,
                    const Eigen::Vector4d& q_prev, Eigen::Vector4d& q_out) {
  const double full = lambda - lambda_prev, min_step = std::abs(full) / 4096;
  double l = lambda_prev, dl = full / 8;
  Eigen::Vector4d q = q_prev;
  while ((full > 0 && l < lambda) || (full < 0 && l > lambda)) {
    if (std::abs(dl) < min_step) return false;
    const double l_next = (full > 0) ? std::min(l + dl, lambda) : std::max(l + dl, lambda);
    const NewtonResult r = solveStationary(sys, sys.rate(l_next), q);
    if (!r.converged || (r.q - q).norm() > 0.1 * std::max(q.norm(), 1e-3 * sys.amplitude_scale)) {
      dl *= 0.5;
      continue;
    }
    q = r.q;
    l = l_next;
    dl *= 1.5;
  }
  q_out = q;
  return true;
}

void addTruthMetadata(const ResonatorPreset& preset, const ResonatorModel& model,
                      const Eigen::VectorXd& z, RecordMetadata& md) {
  md["preset"] = preset.name;
  md["truth_model"] = model.spec();
  const auto values = model.parameterValues(z);
  for (const auto& kv : values) md["truth_" + kv.first] = printfGText(kv.second, 17);
  if (model.mode() == ExperimentMode::kForced) md["truth_mu"] = printfGText(preset.mu, 17);
  md["truth_eta"] = printfGText(preset.eta, 17);
}

}  // namespace

ExperimentRunner::ExperimentRunner(const ResonatorPreset& preset) : preset_(preset) {
  const auto problems = preset.validate();
  if (!problems.empty()) {
    std::string msg = "invalid preset '" + preset.name + "':";
    for (const auto& p : problems) msg += "\n  " + p;
    throw InputError(msg);
  }
}

Eigen::Vector4d ExperimentRunner::stationaryForcedState(double lambda,
                                                        const Eigen::Vector4d& start) const {
  const ForcedSystem sys(preset_, true);
  const Settled s = settle(sys, lambda, start, preset_.sweep_settle_tolerance,
                           50.0 * preset_.sweep_settle_time_s);
  if (!s.settled)
    throw AnalysisError("the forced oscillation at detuning " + printfGText(lambda, 17) +
                        " rad/s did not become stationary");
  return s.q;
}

Eigen::Vector4d ExperimentRunner::freeDecayInitialState() const {
  const double lambda = preset_.decay_drive_detuning_rad_s;
  const Eigen::Vector4d q = stationaryForcedState(lambda);
  // At t = 0 (drive phase 0), f = q1, f' = omega0 p1 by (2.4) at omega0; re-expressed at W = omega.
  const double ratio = (preset_.omega_rad_s + lambda) / preset_.omega_rad_s;
  return Eigen::Vector4d(q[0], q[1] * ratio, q[2], q[3] * ratio);
}

SlowRecord ExperimentRunner::freeDecaySlow(double duration_s) const {
  return freeDecaySlow(duration_s, freeDecayInitialState());
}

SlowRecord ExperimentRunner::freeDecaySlow(double duration_s, const Eigen::Vector4d& q0) const {
  requirePositive(duration_s, "free decay duration");
  const ResonatorModel model(preset_.truthModelSpec(ExperimentMode::kFreeDecay),
                             ExperimentMode::kFreeDecay);
  AveragedModelSimulator sim(model, preset_.truthParameters(model));
  sim.reset(q0, 0.0);
  SlowRecord rec;
  rec.omega_rad_s = preset_.omega_rad_s;
  const size_t n = static_cast<size_t>(std::floor(duration_s * preset_.decay_sample_rate_hz)) + 1;
  sim.sample(preset_.decay_sample_rate_hz, n, rec);
  return rec;
}

RawRecord ExperimentRunner::freeDecayRaw(double duration_s) const {
  return freeDecayRaw(duration_s, freeDecayInitialState());
}

RawRecord ExperimentRunner::freeDecayRaw(double duration_s, const Eigen::Vector4d& q0) const {
  requirePositive(duration_s, "free decay duration");
  const ResonatorModel model(preset_.truthModelSpec(ExperimentMode::kFreeDecay),
                             ExperimentMode::kFreeDecay);
  FullEquationSimulatorOptions fo;
  fo.steps_per_period = preset_.steps_per_period;
  FullEquationSimulator sim(model, preset_.truthParameters(model), preset_.omega_rad_s,
                            preset_.omega_rad_s, 0.0, {}, fo);
  sim.reset(q0, 0.0);
  RawRecord rec;
  rec.omega_rad_s = preset_.omega_rad_s;
  rec.metadata["mode"] = "free_decay";
  const size_t n = static_cast<size_t>(std::floor(duration_s * preset_.raw_sample_rate_hz)) + 1;
  sim.sampleRaw(preset_.raw_sample_rate_hz, n, rec);
  return rec;
}

SweepResult ExperimentRunner::forcedSweep() const {
  const ForcedSystem sys(preset_);
  const int n = preset_.sweep_points;
  std::vector<double> lambdas(n);
  for (int i = 0; i < n; ++i)
    lambdas[i] = preset_.sweep_lambda_min_rad_s +
                 (preset_.sweep_lambda_max_rad_s - preset_.sweep_lambda_min_rad_s) * i / (n - 1);
  std::vector<std::pair<double, int>> order;
  for (int i = 0; i < n; ++i) order.emplace_back(lambdas[i], 1);
  if (preset_.sweep_down)
    for (int i = n - 1; i >= 0; --i) order.emplace_back(lambdas[i], -1);

  SweepResult result;
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  for (size_t k = 0; k < order.size(); ++k) {
    SweepStep step;
    step.lambda_rad_s = order[k].first;
    step.omega0_rad_s = preset_.omega_rad_s + step.lambda_rad_s;
    step.direction = order[k].second;
    const Settled s = settle(sys, step.lambda_rad_s, q, preset_.sweep_settle_tolerance,
                             preset_.sweep_settle_time_s);
    step.q = s.q;
    step.settled = s.settled;
    step.settle_time_s = s.time_s;
    // Jumps are defined between stationary states only: an unsettled step (e.g. a limit cycle of
    // the averaged equations after a Hopf instability) is reported as such instead.
    const bool previous_settled = k > 0 && result.steps.back().settled;
    if (previous_settled && s.settled) {
      Eigen::Vector4d q_cont;
      const bool on_branch =
          continueBranch(sys, order[k - 1].first, step.lambda_rad_s, q, q_cont) &&
          (q_cont - s.q).norm() <=
              1e-3 * std::max({s.q.norm(), q_cont.norm(), 1e-6 * sys.amplitude_scale});
      step.jump = !on_branch;
    }
    result.n_jumps += step.jump;
    result.n_unsettled += !step.settled;
    q = s.q;
    result.steps.push_back(step);
  }
  if (preset_.sweep_down) {
    double largest = 0.0;
    for (const auto& s : result.steps) largest = std::max(largest, s.q.norm());
    for (int i = 0; i < n; ++i) {
      const SweepStep& up = result.steps[i];
      const SweepStep& down = result.steps[2 * n - 1 - i];
      if ((up.q - down.q).norm() <= 1e-3 * largest) continue;
      if (!result.has_hysteresis) {
        result.hysteresis_lambda_min_rad_s = up.lambda_rad_s;
        result.has_hysteresis = true;
      }
      result.hysteresis_lambda_max_rad_s = up.lambda_rad_s;
    }
  }
  return result;
}

RawRecord ExperimentRunner::forcedSweepRaw(const SweepResult& sweep, double segment_s) const {
  requirePositive(segment_s, "raw segment length");
  const ResonatorModel model(preset_.truthModelSpec(ExperimentMode::kForced),
                             ExperimentMode::kForced);
  const Eigen::VectorXd z = preset_.truthParameters(model);
  FullEquationSimulatorOptions fo;
  fo.steps_per_period = preset_.steps_per_period;
  ParametricPumping pumping{preset_.eta, preset_.drive_u_tilde};
  const double rate = preset_.raw_sample_rate_hz;
  const size_t n = static_cast<size_t>(std::floor(segment_s * rate));
  RawRecord rec;
  rec.omega_rad_s = preset_.omega_rad_s;
  rec.metadata["mode"] = "forced";
  auto& omega0_col = rec.extra["omega0"];
  auto& phase_col = rec.extra["drive_phase_rad"];
  double t_offset = 0.0;
  for (const SweepStep& step : sweep.steps) {
    FullEquationSimulator sim(model, z, preset_.omega_rad_s, step.omega0_rad_s, preset_.mu, pumping,
                              fo);
    sim.reset(step.q, 0.0);
    sim.advanceTo(preset_.sweep_raw_settle_s);
    RawRecord seg;
    sim.sampleRaw(rate, n, seg);
    for (size_t k = 0; k < seg.size(); ++k) {
      rec.t_s.push_back(t_offset + (seg.t_s[k] - preset_.sweep_raw_settle_s));
      rec.f.push_back(seg.f[k]);
      rec.g.push_back(seg.g[k]);
      omega0_col.push_back(step.omega0_rad_s);
      phase_col.push_back(std::fmod(step.omega0_rad_s * seg.t_s[k], 2.0 * M_PI));
    }
    t_offset += n / rate;
  }
  return rec;
}

SweepRecord sweepRecordOf(const SweepResult& sweep, double omega_rad_s) {
  SweepRecord rec;
  rec.omega_rad_s = omega_rad_s;
  for (const auto& s : sweep.steps) {
    rec.omega0_rad_s.push_back(s.omega0_rad_s);
    rec.q.push_back(s.q);
    rec.direction.push_back(s.direction);
    rec.jump.push_back(s.jump ? 1 : 0);
    rec.extra["stationary"].push_back(s.settled ? 1.0 : 0.0);
  }
  return rec;
}

AnyRecord simulateExperiment(const ResonatorPreset& preset, const SimulationOptions& options) {
  const ExperimentRunner runner(preset);
  if (options.noise_std >= 0.0 && !std::isfinite(options.noise_std))
    throw InputError("noise std must be finite");
  MeasurementNoise noise(options.seed);
  AnyRecord out;
  const ExperimentMode mode = options.mode;
  const ResonatorModel model(preset.truthModelSpec(mode), mode);
  const Eigen::VectorXd z = preset.truthParameters(model);
  const double q_std = options.noise_std >= 0.0 ? options.noise_std : preset.noise_q_std;
  const double fg_std = options.noise_std >= 0.0 ? options.noise_std : preset.noise_fg_std;
  RecordMetadata md;
  md["omega"] = printfGText(preset.omega_rad_s, 17);
  md["mode"] = experimentModeName(mode);
  addTruthMetadata(preset, model, z, md);
  md["seed"] = std::to_string(options.seed);

  if (mode == ExperimentMode::kFreeDecay) {
    const OrbitElements& start = options.free_decay_start;
    Eigen::Vector4d q0;
    if (start.r == 0.0) {
      md["drive_detuning_rad_s"] = printfGText(preset.decay_drive_detuning_rad_s, 17);
      q0 = runner.freeDecayInitialState();
    } else {
      if (!(std::isfinite(start.r) && start.r > 0.0 && std::isfinite(start.k) &&
            std::abs(start.k) <= start.r && std::isfinite(start.theta) && std::isfinite(start.chi)))
        throw InputError("free-decay start: need r > 0, |k| <= r, finite theta and chi, got r = " +
                         printfGText(start.r, 17) + ", k = " + printfGText(start.k, 17) +
                         ", theta = " + printfGText(start.theta, 17) +
                         ", chi = " + printfGText(start.chi, 17));
      md["free_decay_start"] = "r " + printfGText(start.r, 17) + ", k " + printfGText(start.k, 17) +
                               ", theta_rad " + printfGText(start.theta, 17) + ", chi_rad " +
                               printfGText(start.chi, 17);
      q0 = slowFromOrbit(start);
    }
    if (options.raw) {
      const double d = options.duration_s > 0 ? options.duration_s : preset.decay_raw_duration_s;
      out.kind = RecordKind::kRaw;
      out.raw = runner.freeDecayRaw(d, q0);
      noise.addTo(out.raw, fg_std);
      md["noise_std"] = printfGText(fg_std, 17);
      md["integrator"] = "full equations (2.3), RK4 in osculating variables, " +
                         std::to_string(preset.steps_per_period) + " steps per period";
      out.raw.metadata = md;
    } else {
      const double d = options.duration_s > 0 ? options.duration_s : preset.decay_duration_s;
      out.kind = RecordKind::kFreeDecay;
      out.slow = runner.freeDecaySlow(d, q0);
      noise.addTo(out.slow, q_std);
      md["noise_std"] = printfGText(q_std, 17);
      md["integrator"] = "averaged model (2.6), Dormand-Prince 5(4)";
      out.slow.metadata = md;
    }
    return out;
  }

  if (!options.raw && preset.eta > 0.0)
    throw InputError(
        "eta > 0 (the 2 omega0 parametric terms of (2.1)) exists only in the full equations: "
        "simulate the forced sweep with --raw, or set eta = 0");
  const SweepResult sweep = runner.forcedSweep();
  md["n_jumps"] = std::to_string(sweep.n_jumps);
  md["n_unsettled"] = std::to_string(sweep.n_unsettled);
  std::string jumps;
  for (const auto& s : sweep.steps)
    if (s.jump) jumps += (jumps.empty() ? "" : " ") + printfGText(s.lambda_rad_s, 17);
  if (!jumps.empty()) md["jump_lambdas_rad_s"] = jumps;
  if (sweep.has_hysteresis)
    md["hysteresis_lambda_range_rad_s"] = printfGText(sweep.hysteresis_lambda_min_rad_s, 17) + " " +
                                          printfGText(sweep.hysteresis_lambda_max_rad_s, 17);
  if (options.raw) {
    const double d = options.duration_s > 0 ? options.duration_s : preset.sweep_raw_duration_s;
    out.kind = RecordKind::kRaw;
    out.raw = runner.forcedSweepRaw(sweep, d);
    noise.addTo(out.raw, fg_std);
    md["noise_std"] = printfGText(fg_std, 17);
    md["integrator"] = "full equations (3.1), RK4 in osculating variables at omega0, " +
                       std::to_string(preset.steps_per_period) + " steps per period";
    md["layout"] =
        "one segment per settled sweep step; omega0 = the step's drive frequency; "
        "f ~ q1 cos(drive_phase_rad) + p1 sin(drive_phase_rad)";
    out.raw.metadata = md;
    return out;
  }
  out.kind = RecordKind::kForcedSweep;
  out.sweep = sweepRecordOf(sweep, preset.omega_rad_s);
  SweepRecord& rec = out.sweep;
  noise.addTo(rec, q_std);
  md["noise_std"] = printfGText(q_std, 17);
  md["integrator"] = "averaged model (3.3) settled per step, Newton-polished";
  rec.metadata = md;
  return out;
}

}  // namespace cvg_bench
