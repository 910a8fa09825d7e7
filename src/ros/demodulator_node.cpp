// demodulator_node (see demodulator_node.h).
#include "cvg_bench/ros/demodulator_node.h"

#include "cvg_bench/InputLoss.h"
#include "cvg_bench/SlowState.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/ros/conversions.h"

namespace cvg_bench {
namespace {

DemodulatorNodeOptions loadDemodulatorOptions(const ros::NodeHandle& pnh) {
  ParamReader reader(pnh);
  return loadOptions<DemodulatorNodeOptions>(reader);
}

}  // namespace

DemodulatorNode::DemodulatorNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), options_(loadDemodulatorOptions(pnh)) {
  if (options_.omega_rad_s > 0.0 && options_.sample_rate_hz > 0.0)
    configure(options_.omega_rad_s, options_.sample_rate_hz);  // fail at start-up, not later
  slow_pub_ = nh_.advertise<SlowState>("slow", options_.queue_size);
  loss_pub_ = nh_.advertise<InputLoss>("input_loss", 100);
  raw_sub_ = nh_.subscribe("raw", options_.raw_queue_size, &DemodulatorNode::onRaw, this);
  reset_srv_ = nh_.advertiseService("demodulator/reset", &DemodulatorNode::onReset, this);
  diagnostics_.setHardwareID("cvg_bench demodulator");
  diagnostics_.add("demodulator", this, &DemodulatorNode::diagnose);
  diagnostics_timer_ = nh_.createWallTimer(
      ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) { diagnostics_.force_update(); });
}

void DemodulatorNode::configure(double omega_rad_s, double sample_rate_hz) {
  DemodulatorOptions o = options_.filter;
  o.omega_rad_s = omega_rad_s;
  o.sample_rate_hz = sample_rate_hz;
  Demodulator fresh(o);  // InputError listing every problem
  if (demodulator_) {
    for (const auto& kv : demodulator_->counters().asMap()) counters_before_[kv.first] += kv.second;
    rejected_before_ += demodulator_->counters().rejected();
  }
  demodulator_.reset(new Demodulator(std::move(fresh)));
  omega_rad_s_ = omega_rad_s;
  sample_rate_hz_ = sample_rate_hz;
  ROS_INFO(
      "demodulator: W = %.9g rad/s, input %.9g Hz, output %.6g Hz, passband %.4g Hz, latency %.4g "
      "s",
      omega_rad_s, sample_rate_hz, demodulator_->outputRateHz(), demodulator_->passbandHz(),
      demodulator_->latencyS());
}

void DemodulatorNode::resetState(const std::string& why, bool expected) {
  if (demodulator_) demodulator_->reset();
  have_epoch_ = false;
  last_end_ = ros::Time();
  ++node_resets_;
  last_problem_ = why;
  // A rerun or a requested reset is normal bench work (INFO); a jump back in time is not (issue
  // #27).
  if (expected)
    ROS_INFO("demodulator reset: %s", why.c_str());
  else
    ROS_WARN("demodulator reset: %s", why.c_str());
}

bool DemodulatorNode::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  resetState("reset requested", true);
  res.success = true;
  res.message = "demodulator reset";
  return true;
}

void DemodulatorNode::onRaw(const RawSampleBatch::ConstPtr& msg) {
  ++batches_;
  samples_in_ += msg->f.size();
  const uint32_t gap =
      have_seq_ && msg->header.seq > last_seq_ ? msg->header.seq - last_seq_ - 1 : 0;
  batches_lost_ += gap;
  have_seq_ = true;
  last_seq_ = msg->header.seq;
  // An empty batch marks the end of a record (its sequence number above counted any lost tail).
  if (msg->f.empty() && msg->g.empty() && msg->time_offsets_s.empty()) {
    ++end_markers_;
    if (gap > 0) publishLoss(gap, last_end_.isZero() ? msg->header.stamp : last_end_);
    return;
  }
  // Lost batches are announced at the data they precede (this batch's first sample), so that
  // the identifier marks the estimates whose data span them (InputLoss.msg).
  if (gap > 0) publishLoss(gap, msg->header.stamp);
  const ros::Time now = ros::Time::now();
  // A /clock that jumps back (replay restarted) is reported; the reset itself is decided by the
  // data's own stamps below, so a batch processed before the clock message is not reset twice.
  if (!last_now_.isZero() && now < last_now_)
    ROS_INFO("demodulator: ROS time jumped back by %.6g s", secondsSince(last_now_, now));
  last_now_ = now;

  const double w =
      options_.omega_rad_s > 0.0
          ? options_.omega_rad_s
          : (msg->drive_frequency_rad_s > 0.0 ? msg->drive_frequency_rad_s : msg->omega_rad_s);
  const double rate = options_.sample_rate_hz > 0.0 ? options_.sample_rate_hz : msg->sample_rate_hz;
  if (!(w > 0.0) || !(rate > 0.0) || !std::isfinite(w) || !std::isfinite(rate)) {
    ++bad_batches_;
    last_problem_ =
        "batch without a reference frequency or sample rate (set omega_rad_s / sample_rate_hz)";
    ROS_WARN_THROTTLE(options_.warn_throttle_s, "demodulator: %s", last_problem_.c_str());
    return;
  }
  const ros::Time epoch = msg->phase_epoch.isZero() ? msg->header.stamp : msg->phase_epoch;
  if (have_epoch_ && !msg->phase_epoch.isZero() && msg->phase_epoch != epoch_)
    resetState("new phase epoch (a new experiment started)", true);
  else if (have_epoch_ && secondsSince(msg->header.stamp, last_end_) < -options_.backward_jump_s)
    resetState("data jumped back in time (bag loop?)", false);
  if (!have_epoch_) {
    epoch_ = epoch;
    have_epoch_ = true;
  }
  if (!demodulator_ || w != omega_rad_s_ || rate != sample_rate_hz_) {
    try {
      configure(w, rate);
    } catch (const InputError& e) {
      ++bad_batches_;
      last_problem_ = e.what();
      ROS_ERROR_THROTTLE(options_.warn_throttle_s, "demodulator cannot take this batch: %s",
                         e.what());
      return;
    }
  }
  RawSamples samples;
  try {
    samples = rawSamplesFromMsg(*msg, epoch_);
  } catch (const InputError& e) {
    ++bad_batches_;
    last_problem_ = e.what();
    ROS_WARN_THROTTLE(options_.warn_throttle_s, "demodulator: malformed batch dropped: %s",
                      e.what());
    return;
  }
  out_.clear();
  demodulator_->push(samples.t_s, samples.f, samples.g, out_);
  if (msg->omega_rad_s > 0.0) natural_omega_rad_s_ = msg->omega_rad_s;
  const double detuning = natural_omega_rad_s_ > 0.0 ? w - natural_omega_rad_s_ : 0.0;
  for (const SlowSample& s : out_) {
    SlowState state = slowStateToMsg(s.q, timeAfter(epoch_, s.t_s), epoch_, w, detuning);
    state.header.frame_id = msg->header.frame_id;
    slow_pub_.publish(state);
    ++slow_published_;
  }
  if (!samples.t_s.empty()) last_end_ = timeAfter(epoch_, samples.t_s.back());
  warnAboutDrops();
}

void DemodulatorNode::publishLoss(uint32_t batches, const ros::Time& stamp) {
  InputLoss loss;
  loss.header.stamp = stamp;
  loss.batches_lost = batches;
  loss.source = "demodulator: raw batches";
  loss_pub_.publish(loss);
  ROS_WARN_THROTTLE(options_.warn_throttle_s,
                    "demodulator: %u raw batches lost in transport before %.6f s (sequence gap); "
                    "%llu so far",
                    batches, stamp.toSec(), static_cast<unsigned long long>(batches_lost_));
}

void DemodulatorNode::warnAboutDrops() {
  const uint64_t rejected = rejected_before_ + demodulator_->counters().rejected();
  if (rejected == warned_rejected_) return;
  const SampleCounters& c = demodulator_->counters();
  ROS_WARN_THROTTLE(
      options_.warn_throttle_s,
      "demodulator dropped %llu samples so far (non-finite %llu, duplicate %llu, "
      "out of order %llu, off grid %llu, rate mismatch %llu); see diagnostics",
      static_cast<unsigned long long>(rejected), static_cast<unsigned long long>(c.non_finite),
      static_cast<unsigned long long>(c.duplicate_timestamp),
      static_cast<unsigned long long>(c.non_monotonic), static_cast<unsigned long long>(c.off_grid),
      static_cast<unsigned long long>(c.rate_mismatch_samples));
  warned_rejected_ = rejected;
}

void DemodulatorNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::map<std::string, uint64_t> counts = counters_before_;
  uint64_t rejected = rejected_before_;
  if (demodulator_) {
    for (const auto& kv : demodulator_->counters().asMap()) counts[kv.first] += kv.second;
    rejected += demodulator_->counters().rejected();
  }
  if (!demodulator_)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "waiting for raw batches");
  else if (rejected > 0 || bad_batches_ > 0 || batches_lost_ > 0)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                  "%llu samples dropped, %llu bad batches, %llu batches lost in transport",
                  static_cast<unsigned long long>(rejected),
                  static_cast<unsigned long long>(bad_batches_),
                  static_cast<unsigned long long>(batches_lost_));
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "ok");
  for (const auto& kv : counts) stat.add(kv.first, kv.second);
  const ros::WallTime now = ros::WallTime::now();
  const double dt = last_diag_wall_.isZero() ? 0.0 : (now - last_diag_wall_).toSec();
  stat.add("input_rate_samples_per_s",
           dt > 0.0 ? (samples_in_ - samples_in_at_last_diag_) / dt : 0.0);
  last_diag_wall_ = now;
  samples_in_at_last_diag_ = samples_in_;
  stat.add("raw_samples_received", samples_in_);
  stat.add("batches_lost_in_transport", batches_lost_);
  stat.add("end_of_record_markers", end_markers_);
  stat.add("raw_queue_size", options_.raw_queue_size);
  stat.add("rejected_total", rejected);
  stat.add("batches", batches_);
  stat.add("bad_batches", bad_batches_);
  stat.add("slow_states_published", slow_published_);
  stat.add("node_resets", node_resets_);
  stat.add("reference_frequency_rad_s", omega_rad_s_);
  stat.add("sample_rate_hz", sample_rate_hz_);
  if (demodulator_) {
    stat.add("output_rate_hz", demodulator_->outputRateHz());
    stat.add("latency_s", demodulator_->latencyS());
    stat.add("segment", demodulator_->segment());
    stat.add("last_event", demodulator_->lastEvent());
  }
  stat.add("last_problem", last_problem_);
}

}  // namespace cvg_bench
