// Experiment boundaries (see experiment_tracker.h).
#include "cvg_bench/ros/experiment_tracker.h"

namespace cvg_bench {

ExperimentTracker::Boundary ExperimentTracker::onSample(const ros::Time& epoch,
                                                        const ros::Time& stamp) {
  Boundary b = Boundary::kNone;
  if (id_ == 0)
    b = Boundary::kFirst;
  else if (!epoch.isZero() && epoch != epoch_)
    b = Boundary::kNewEpoch;
  else if (stamp < last_stamp_)
    b = Boundary::kJumpBack;
  else if (have_pending_ && stamp >= pending_start_)
    b = Boundary::kStartEvent;
  if (b == Boundary::kJumpBack) ++jumps_back_;
  if (b != Boundary::kNone) {
    ++id_;
    start_ = stamp;
    have_pending_ = false;
  }
  if (!epoch.isZero()) epoch_ = epoch;
  last_stamp_ = stamp;
  return b;
}

void ExperimentTracker::onStartEvent(const ros::Time& start) {
  // A start event at or before the current experiment's own start announced that experiment.
  if (id_ > 0 && start <= start_) return;
  pending_start_ = start;
  have_pending_ = true;
}

std::string ExperimentTracker::describe(Boundary b) {
  switch (b) {
    case Boundary::kNone:
      return "same experiment";
    case Boundary::kFirst:
      return "first data";
    case Boundary::kNewEpoch:
      return "new phase epoch (the experiment was restarted)";
    case Boundary::kJumpBack:
      return "data jumped back in time (looped bag or restarted replay)";
    case Boundary::kStartEvent:
      return "start event from the simulator";
  }
  return "?";
}

}  // namespace cvg_bench
