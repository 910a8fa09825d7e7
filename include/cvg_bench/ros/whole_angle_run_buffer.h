// The whole-angle run an identifier measures drift from (issue #26): slow states received on
// `whole_angle`, kept apart from the identification buffer so the free-decay estimate stays. A
// new phase epoch starts a new run (the buffer is cleared); a state stamped at or before the
// previous one, or one over the limit, is dropped and counted, never inserted out of order; gaps in
// the publisher's sequence numbers count the states lost before the buffer (the subscriber queue's
// overflow or the network; said with the measurement). A sequence number that goes back (a new
// publisher, a wrap) restarts the count without a loss. Counts are per run.
#pragma once

#include <ros/time.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

class WholeAngleRunBuffer {
 public:
  explicit WholeAngleRunBuffer(size_t max_samples = 2000000) : max_samples_(max_samples) {}

  /// Adds one state; false (counted in dropped()) when it is out of order or the buffer is full.
  bool add(const ros::Time& phase_epoch, const ros::Time& stamp, uint32_t seq,
           const Eigen::Vector4d& q, double omega_rad_s);
  /// The run as a slow record, t from its first state [s]; the omega of its states.
  SlowRecord record() const;
  size_t size() const { return q_.size(); }
  uint64_t dropped() const { return dropped_; }
  uint64_t runs() const { return runs_; }
  /// Forgets the run (the identifier's reset).
  void clear();
  /// States of the current run missing between received ones (sequence-number gaps).
  uint64_t lost() const { return lost_; }

 private:
  size_t max_samples_;
  ros::Time epoch_;
  std::vector<ros::Time> stamps_;
  std::vector<Eigen::Vector4d> q_;
  double omega_rad_s_ = 0.0;
  uint32_t last_seq_ = 0;
  uint64_t dropped_ = 0, runs_ = 0, lost_ = 0;
};

}  // namespace cvg_bench
