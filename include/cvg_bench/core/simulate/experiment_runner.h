// The paper's two experiments, simulated on a ResonatorPreset:
//  - FREE DECAY (section 2): the resonator is driven into the stationary forced oscillation at the
//    preset's drive u~ and detuning (stationary averaged equations (3.3), settled then solved by
//    Newton), the controls are switched off at t = 0 and the decay is recorded: slow variables by
//    the averaged model (AveragedModelSimulator), or raw f, g by the full equations
//    (FullEquationSimulator).
//  - FORCED SWEEP (section 3): the detuning lambda = omega0 - omega is stepped over the preset's
//    range; each step starts from the previous step's state and is settled by integrating the
//    averaged model (3.3) until stationary, then polished by Newton. A nonlinear resonator is
//    bistable near a fold: a step whose settled state is not the continuation of the previous
//    step's branch (Newton continuation in adaptive sub-steps fails or ends elsewhere) is flagged
//    as a jump. A step that does not become stationary within settle_time_s (e.g. a limit cycle of
//    the averaged equations of two coupled nonlinear modes) is reported as unsettled, not a jump.
//    With sweep_down the sweep runs back down, and the detunings where the two branches differ are
//    reported (hysteresis).
// simulateExperiment() adds seeded noise and `# truth_<name>: value` metadata for tests.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "cvg_bench/core/io/record_io.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/resonator_preset.h"

namespace cvg_bench {

/// One settled step of a forced sweep.
struct SweepStep {
  double lambda_rad_s = 0.0;                    ///< detuning omega0 - omega [rad/s]
  double omega0_rad_s = 0.0;                    ///< drive frequency [rad/s]
  Eigen::Vector4d q = Eigen::Vector4d::Zero();  ///< stationary (q1, p1, q2, p2), noise-free
  int direction = 1;                            ///< +1 up-sweep, -1 down-sweep
  bool jump = false;    ///< reached by a jump off the previous step's branch (both steps settled)
  bool settled = true;  ///< stationary within settle_time_s (else the last state)
  double settle_time_s = 0.0;  ///< time the averaged model ran for this step [s]
};

struct SweepResult {
  std::vector<SweepStep> steps;  ///< up-sweep first, then the down-sweep if requested
  int n_jumps = 0;
  int n_unsettled = 0;
  /// Detuning range where the up- and down-sweep states differ by more than 1e-3 of the largest
  /// amplitude [rad/s]; has_hysteresis false when they agree everywhere (or no down-sweep).
  bool has_hysteresis = false;
  double hysteresis_lambda_min_rad_s = 0.0;
  double hysteresis_lambda_max_rad_s = 0.0;
};

/// The noise-free sweep as a record: omega0, q, direction, jump per step and the extra column
/// `stationary` (1 settled, 0 still moving after the settle time).
SweepRecord sweepRecordOf(const SweepResult& sweep, double omega_rad_s);

class ExperimentRunner {
 public:
  /// InputError if the preset does not validate.
  explicit ExperimentRunner(const ResonatorPreset& preset);
  const ResonatorPreset& preset() const { return preset_; }

  /// Stationary forced oscillation at detuning lambda (drive u~ of the preset): the averaged model
  /// (3.3) integrated from `start` until stationary, then Newton. AnalysisError when it does not
  /// settle within 50 settle times.
  Eigen::Vector4d stationaryForcedState(
      double lambda_rad_s, const Eigen::Vector4d& start = Eigen::Vector4d::Zero()) const;
  /// Initial osculating state of the free decay at t = 0, van der Pol variables at W = omega.
  Eigen::Vector4d freeDecayInitialState() const;

  /// Free decay, slow variables by the averaged model, sampled at the preset's rate (noise-free),
  /// from freeDecayInitialState() or from q0 (van der Pol variables at W = omega).
  SlowRecord freeDecaySlow(double duration_s) const;
  SlowRecord freeDecaySlow(double duration_s, const Eigen::Vector4d& q0) const;
  /// Free decay, raw f, g by the full equations at the preset's raw rate (noise-free), from
  /// freeDecayInitialState() or from q0.
  RawRecord freeDecayRaw(double duration_s) const;
  RawRecord freeDecayRaw(double duration_s, const Eigen::Vector4d& q0) const;
  /// Forced sweep (noise-free stationary states).
  SweepResult forcedSweep() const;
  /// Raw f, g of each settled sweep step by the full equations at W = omega0: segments of
  /// segment_s each, back to back in t, after sweep_raw_settle_s of discarded settling, with extra
  /// columns omega0 (the step's drive frequency [rad/s]) and drive_phase_rad (omega0 times the
  /// time since the segment's start, modulo 2 pi), so f ~ q1 cos(drive_phase) + p1
  /// sin(drive_phase).
  RawRecord forcedSweepRaw(const SweepResult& sweep, double segment_s) const;

 private:
  ResonatorPreset preset_;
};

struct SimulationOptions {
  ExperimentMode mode = ExperimentMode::kFreeDecay;
  /// Raw f, g (full equations) instead of slow variables.
  bool raw = false;
  /// Seed of the measurement noise (std::mt19937_64).
  std::uint64_t seed = 1;
  /// Noise std overriding the preset's (q for slow/sweep, f, g for raw); < 0 = the preset's.
  double noise_std = -1.0;
  /// Record length overriding the preset's [s] (free decay: the record; forced raw: each
  /// segment); <= 0 = the preset's.
  double duration_s = 0.0;
  /// Free decay only: start from these orbit elements (5.2) at t = 0 instead of the stationary
  /// state of the preset's drive: r > 0 the wave amplitude [amplitude units], |k| <= r the
  /// quadrature, theta the pattern angle [rad], chi the temporal phase [rad]. r = 0 = the drive.
  OrbitElements free_decay_start;
};

/// Runs the experiment, adds the noise and fills the metadata (omega, mode, preset, truth_model,
/// truth_<parameter> for every parameter of the truth model, truth_mu, truth_eta, seed, noise_std,
/// and for sweeps n_jumps, jump_lambdas_rad_s, hysteresis range). The kind of the result is
/// kFreeDecay, kForcedSweep or kRaw. Sweep records carry an extra column `stationary` (1 settled,
/// 0 still moving after settle_time_s: the q written is the last state).
AnyRecord simulateExperiment(const ResonatorPreset& preset, const SimulationOptions& options);

}  // namespace cvg_bench
