// resonator_simulator_node: a simulated resonator on the bench. Runs the core's experiments
// (experiment_runner.h) on a preset and streams them in (scaled) real time:
//   raw             RawSampleBatch  raw f, g of the full equations, with noise (free decay)
//   sim/slow        SlowState       averaged-model slow variables, with noise (free decay)
//   sim/slow_truth  SlowState       the same without noise
//   sweep           SweepPoint      settled points of a forced sweep, with noise
//   truth           SimulationTruth latched: preset, true parameters, noise levels
//   sim/whole_angle SlowState       a whole-angle run (loops hold r and k, theta free), with noise
// Services start_free_decay, start_sweep and start_whole_angle start an experiment (the previous
// one stops).
// Stamps are start + simulated time; the start is the phase epoch of (2.4). The raw record is
// produced piece by piece as it becomes due (RawFreeDecayStream), at most max_batch_samples a
// tick: a node that cannot keep up lags (reported in the diagnostics) instead of growing.
// Diagnostics (1 Hz): state, published rates, lag behind the requested real-time factor.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <memory>

#include "cvg_bench/StartFreeDecay.h"
#include "cvg_bench/StartSweep.h"
#include "cvg_bench/StartWholeAngle.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/ros/raw_free_decay_stream.h"
#include "cvg_bench/ros/simulator_node_options.h"

namespace cvg_bench {

class SimulatorNode {
 public:
  /// Reads the settings from pnh and the preset; throws InputError listing every problem.
  SimulatorNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

 private:
  enum class Running { kNone, kFreeDecay, kSweep, kWholeAngle };

  bool onStartFreeDecay(StartFreeDecay::Request& req, StartFreeDecay::Response& res);
  bool onStartSweep(StartSweep::Request& req, StartSweep::Response& res);
  bool onStartWholeAngle(StartWholeAngle::Request& req, StartWholeAngle::Response& res);
  /// Simulates the whole record now (InputError / AnalysisError from the core pass through).
  /// start.r = 0: from the drive's stationary state; else from these orbit elements.
  void startFreeDecay(double duration_s, int seed, const OrbitElements& start = OrbitElements());
  void startSweep(const ResonatorPreset& preset, int seed);
  void beginStreaming(Running what, ExperimentMode mode, const ResonatorPreset& preset);
  void onTick(const ros::WallTimerEvent&);
  void publishDueFreeDecay(double due_s);
  void publishEndOfRawRecord();
  void publishDueSweep(double wall_elapsed_s);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);
  /// Autostart: starts once the experiment's first consumer is connected; warns once when only
  /// consumers of the other experiment's topic are (mode / autostart mismatch), every 5 s.
  void onAutostartTimer(const ros::WallTimerEvent&);

  ros::NodeHandle nh_;
  SimulatorNodeOptions options_;
  ResonatorPreset preset_;  ///< as loaded, noise scaled by options_.noise_scale

  ros::Publisher raw_pub_, slow_pub_, slow_truth_pub_, sweep_pub_, truth_pub_, whole_angle_pub_;
  ros::ServiceServer start_free_decay_srv_, start_sweep_srv_, start_whole_angle_srv_;
  ros::WallTimer timer_, autostart_timer_;

  Running running_ = Running::kNone;
  std::unique_ptr<RawFreeDecayStream> raw_stream_;
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_;
  ros::WallTime autostart_since_;
  ros::WallTime last_autostart_warning_;
  uint64_t raw_published_ = 0, raw_at_last_diag_ = 0, raw_batches_ = 0, capped_ticks_ = 0;
  uint64_t slow_published_ = 0, sweep_published_ = 0, experiments_ = 0;
  double lag_s_ = 0.0, max_lag_s_ = 0.0;
  ros::WallTime last_diag_wall_;
  SlowRecord slow_, slow_truth_;
  SweepRecord sweep_;
  std::vector<bool> settled_;
  size_t slow_next_ = 0, sweep_next_ = 0;
  ros::Time start_stamp_;
  ros::WallTime wall_start_;
};

}  // namespace cvg_bench
