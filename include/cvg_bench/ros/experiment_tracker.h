// Which experiment a sample belongs to. An experiment begins at the first sample, and again when
//  - the sample's phase epoch (t = 0 of (2.4), set by the simulator at each start) changes,
//  - the samples jump back in time (a looped bag, a restarted replay),
//  - a start event was announced (the simulator's latched `truth` at each start_free_decay /
//    start_sweep) and a sample stamped at or after that start arrives.
// Ids count from 1 and never repeat within a node's life, so a rerun never mixes with the old run.
#pragma once

#include <ros/time.h>

#include <cstdint>
#include <string>

namespace cvg_bench {

class ExperimentTracker {
 public:
  /// Why a sample starts a new experiment (kNone: it continues the current one).
  enum class Boundary { kNone, kFirst, kNewEpoch, kJumpBack, kStartEvent };

  /// Classifies a sample (epoch zero = unknown, e.g. sweep points) and advances the id on a
  /// boundary.
  Boundary onSample(const ros::Time& epoch, const ros::Time& stamp);
  /// A start event: the next sample stamped at or after `start` begins a new experiment.
  void onStartEvent(const ros::Time& start);

  uint32_t id() const { return id_; }                ///< 0 before the first sample
  const ros::Time& start() const { return start_; }  ///< stamp of the experiment's first sample
  uint64_t jumpsBack() const { return jumps_back_; }
  static std::string describe(Boundary b);

 private:
  uint32_t id_ = 0;
  ros::Time start_, epoch_, last_stamp_, pending_start_;
  bool have_pending_ = false;
  uint64_t jumps_back_ = 0;
};

}  // namespace cvg_bench
