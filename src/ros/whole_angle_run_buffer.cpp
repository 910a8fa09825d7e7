// The whole-angle run buffer (see whole_angle_run_buffer.h).
#include "cvg_bench/ros/whole_angle_run_buffer.h"

namespace cvg_bench {

bool WholeAngleRunBuffer::add(const ros::Time& phase_epoch, const ros::Time& stamp, uint32_t seq,
                              const Eigen::Vector4d& q, double omega_rad_s) {
  if (q_.empty() || phase_epoch != epoch_) {
    stamps_.clear();
    q_.clear();
    epoch_ = phase_epoch;
    lost_ = dropped_ = 0;
    last_seq_ = seq;
    ++runs_;
  } else {
    // A state that arrived counts as received even when it is dropped below (not lost).
    if (seq > last_seq_ && seq - last_seq_ > 1) lost_ += seq - last_seq_ - 1;
    last_seq_ = seq;
    if (stamp <= stamps_.back() || q_.size() >= max_samples_) {
      ++dropped_;
      return false;
    }
  }
  stamps_.push_back(stamp);
  q_.push_back(q);
  if (omega_rad_s > 0.0) omega_rad_s_ = omega_rad_s;
  return true;
}

void WholeAngleRunBuffer::clear() {
  stamps_.clear();
  q_.clear();
  lost_ = dropped_ = 0;
}

SlowRecord WholeAngleRunBuffer::record() const {
  SlowRecord rec;
  rec.omega_rad_s = omega_rad_s_;
  rec.source = "whole_angle topic";
  rec.metadata["experiment"] = "whole_angle";
  rec.t_s.reserve(q_.size());
  rec.q.reserve(q_.size());
  for (size_t i = 0; i < q_.size(); ++i) {
    rec.t_s.push_back((stamps_[i] - stamps_.front()).toSec());
    rec.q.push_back(q_[i]);
  }
  return rec;
}

}  // namespace cvg_bench
