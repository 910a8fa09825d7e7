// Settings of identifier_node (config/identifier.yaml documents each key).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/ros/param_reader.h"

namespace cvg_bench {

struct IdentifierNodeOptions {
  /// "free_decay" (subscribe to slow states) or "forced" (subscribe to sweep points).
  std::string mode = "free_decay";
  /// The core identification settings: model, method ("ls" batch; "rls" = block recursive least
  /// squares updated with every slow state, free decay only), confidence, omega_rad_s (0 = from the
  /// messages), angular_gain_k, mu, rank_tolerance, rls_forgetting.
  IdentificationOptions identification;
  /// Free decay: identify over the slow states of the last window_s seconds [s], >= 0; 0 = all
  /// since the last reset (bounded by max_samples).
  double window_s = 0.0;
  /// Largest number of buffered slow states or sweep points (oldest dropped), >= 10.
  int max_samples = 200000;
  /// Fewest samples (free decay) or sweep points (forced) before a batch identification, >= 4.
  int min_samples = 20;
  /// Batch identification every identify_period_s of wall-clock time while data arrive [s], >= 0;
  /// 0 = off.
  double identify_period_s = 0.0;
  /// Batch identification once when no data came for idle_identify_s after some did (end of a
  /// record, end of a bag) [s, wall clock], >= 0; 0 = off.
  double idle_identify_s = 0.5;
  /// Recursive mode: publish the running estimate at most this often [s, wall clock], >= 0.
  double rls_publish_period_s = 0.1;
  /// Frame of the resonator (tf parent of the stiffness axis, damping axis and wave pattern
  /// frames).
  std::string frame_id = "resonator";
  /// Prefix of the child frames: <prefix>stiffness_axis, <prefix>damping_axis,
  /// <prefix>wave_pattern.
  std::string child_frame_prefix = "";
  /// Experiments whose last estimate stays retrievable (get_estimate by experiment_id), >= 1.
  int history_size = 10;
  /// Queue length of the subscriptions, >= 1.
  int queue_size = 1000;

  std::vector<std::string> validate() const;
  void load(ParamReader& reader);
};

}  // namespace cvg_bench
