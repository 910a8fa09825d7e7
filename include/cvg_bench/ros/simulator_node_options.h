// Settings of resonator_simulator_node (config/simulator.yaml documents each key).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/ros/param_reader.h"

namespace cvg_bench {

struct SimulatorNodeOptions {
  /// Shipped resonator preset (config/resonators/NAME.yaml).
  std::string preset = "mems_ring";
  /// Preset YAML file; when set it replaces `preset`.
  std::string config;
  /// Experiment started at start-up: "free_decay", "forced" or "none" (wait for a service call).
  /// It starts when the first consumer (of `raw`, else `sim/slow`; `sweep` when forced) connects,
  /// start_delay_s later.
  std::string autostart = "none";
  /// Publish raw f, g batches on `raw` (free decay).
  bool publish_raw = true;
  /// Publish the averaged-model slow variables on `sim/slow` (noisy) and `sim/slow_truth`
  /// (noise-free) (free decay).
  bool publish_slow = true;
  /// Free-decay record length [s], >= 0; 0 = the preset's raw record length (when publishing raw)
  /// or its slow record length.
  double duration_s = 0.0;
  /// Simulated seconds per wall-clock second, in (0, 1000]. Stamps are always start + simulated t.
  double realtime_factor = 1.0;
  /// Publication ticks per wall-clock second [Hz], in [1, 1000]; a raw batch carries the samples
  /// due at a tick.
  double publish_rate_hz = 100.0;
  /// Wall-clock wait between a start request and the first sample [s], in [0, 60].
  double start_delay_s = 0.2;
  /// Wall-clock time between published sweep points [s], in [0, 10].
  double sweep_point_interval_s = 0.01;
  /// Seed of the measurement noise, >= 0 (a service request with seed 0 uses this).
  int seed = 1;
  /// Multiplies the preset's noise standard deviations, >= 0 (0 = noise-free).
  double noise_scale = 1.0;
  /// Longest free-decay record a start accepts [s], > 0 (memory: the raw record is produced
  /// piece by piece, the slow records at the slow rate are held whole).
  double max_duration_s = 600.0;
  /// Most raw samples in one RawSampleBatch, >= 1000: when the node falls behind real time it
  /// publishes at most this many per tick and reports the lag instead of sending huge messages.
  int max_batch_samples = 50000;
  /// frame_id of the published headers.
  std::string frame_id = "resonator";

  std::vector<std::string> validate() const;
  /// Reads every key (absent keys keep their defaults); problems go to the reader.
  void load(ParamReader& reader);
};

}  // namespace cvg_bench
