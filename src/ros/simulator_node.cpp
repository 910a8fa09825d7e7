// resonator_simulator_node (see simulator_node.h).
#include "cvg_bench/ros/simulator_node.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "cvg_bench/RawSampleBatch.h"
#include "cvg_bench/SimulationTruth.h"
#include "cvg_bench/SlowState.h"
#include "cvg_bench/SweepPoint.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/simulate/experiment_runner.h"
#include "cvg_bench/core/simulate/measurement_noise.h"
#include "cvg_bench/core/simulate/whole_angle_simulator.h"
#include "cvg_bench/ros/conversions.h"

namespace cvg_bench {
namespace {

ResonatorPreset loadPreset(const SimulatorNodeOptions& o) {
  ResonatorPreset p =
      o.config.empty() ? loadShippedPreset(o.preset) : loadResonatorPresetFile(o.config);
  p.noise_q_std *= o.noise_scale;
  p.noise_fg_std *= o.noise_scale;
  return p;
}

SimulatorNodeOptions loadSimulatorOptions(const ros::NodeHandle& pnh) {
  ParamReader reader(pnh);
  return loadOptions<SimulatorNodeOptions>(reader);
}

}  // namespace

SimulatorNode::SimulatorNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), options_(loadSimulatorOptions(pnh)), preset_(loadPreset(options_)) {
  raw_pub_ = nh_.advertise<RawSampleBatch>("raw", 100);
  slow_pub_ = nh_.advertise<SlowState>("sim/slow", 10000);
  slow_truth_pub_ = nh_.advertise<SlowState>("sim/slow_truth", 10000);
  sweep_pub_ = nh_.advertise<SweepPoint>("sweep", 1000);
  truth_pub_ = nh_.advertise<SimulationTruth>("truth", 1, /*latch=*/true);
  start_free_decay_srv_ =
      nh_.advertiseService("start_free_decay", &SimulatorNode::onStartFreeDecay, this);
  start_sweep_srv_ = nh_.advertiseService("start_sweep", &SimulatorNode::onStartSweep, this);
  whole_angle_pub_ = nh_.advertise<SlowState>("sim/whole_angle", 10000);
  start_whole_angle_srv_ =
      nh_.advertiseService("start_whole_angle", &SimulatorNode::onStartWholeAngle, this);
  timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / options_.publish_rate_hz),
                               &SimulatorNode::onTick, this);
  ROS_INFO("resonator simulator: preset '%s' (%s), omega = %.6g rad/s", preset_.name.c_str(),
           preset_.description.c_str(), preset_.omega_rad_s);
  diagnostics_.setHardwareID("cvg_bench resonator_simulator");
  diagnostics_.add("resonator_simulator", this, &SimulatorNode::diagnose);
  last_diag_wall_ = ros::WallTime::now();
  diagnostics_timer_ = nh_.createWallTimer(
      ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) { diagnostics_.force_update(); });
  if (options_.autostart != "none") {
    // Start once the first consumer is connected (nodes of a launch file come up in any order);
    // start_delay_s then leaves the rest of the chain time to connect.
    autostart_since_ = ros::WallTime::now();
    autostart_timer_ =
        nh_.createWallTimer(ros::WallDuration(0.05), &SimulatorNode::onAutostartTimer, this);
  }
}

void SimulatorNode::onAutostartTimer(const ros::WallTimerEvent&) {
  const bool forced = options_.autostart == "forced";
  const ros::Publisher& first = forced ? sweep_pub_ : options_.publish_raw ? raw_pub_ : slow_pub_;
  if (first.getNumSubscribers() == 0) {
    const uint32_t others = forced ? raw_pub_.getNumSubscribers() + slow_pub_.getNumSubscribers()
                                   : sweep_pub_.getNumSubscribers();
    // Warned after 3 s of waiting, then every 5 s while the mismatch lasts.
    const ros::WallTime now = ros::WallTime::now();
    if (others > 0 && (now - autostart_since_).toSec() > 3.0 &&
        (last_autostart_warning_.isZero() || (now - last_autostart_warning_).toSec() > 5.0)) {
      last_autostart_warning_ = now;
      ROS_WARN(
          "autostart:=%s waits for a subscriber of %s, but only the %s experiment's topics "
          "have subscribers: is the identifier's mode %s? (start both with the same mode)",
          options_.autostart.c_str(), first.getTopic().c_str(), forced ? "free-decay" : "forced",
          forced ? "free_decay instead of forced" : "forced instead of free_decay");
    }
    return;
  }
  autostart_timer_.stop();
  try {
    if (options_.autostart == "free_decay") startFreeDecay(0.0, options_.seed);
    if (forced) startSweep(preset_, options_.seed);
  } catch (const std::exception& e) {
    ROS_ERROR("autostart failed: %s", e.what());
  }
}

bool SimulatorNode::onStartFreeDecay(StartFreeDecay::Request& req, StartFreeDecay::Response& res) {
  try {
    OrbitElements start;
    if (req.amplitude != 0.0) {
      start.r = req.amplitude;
      start.k = req.quadrature;
      start.theta = req.theta_rad;
    } else if (req.quadrature != 0.0 || req.theta_rad != 0.0) {
      throw InputError("quadrature/theta_rad given without amplitude (amplitude 0 = the drive)");
    }
    startFreeDecay(req.duration_s, req.seed > 0 ? static_cast<int>(req.seed) : options_.seed,
                   start);
    res.success = true;
    res.message = "free decay started: " + std::to_string(raw_stream_ ? raw_stream_->total() : 0) +
                  " raw samples, " + std::to_string(slow_.size()) + " slow states";
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    ROS_ERROR("start_free_decay refused: %s", e.what());
  }
  return true;
}

bool SimulatorNode::onStartSweep(StartSweep::Request& req, StartSweep::Response& res) {
  try {
    ResonatorPreset p = preset_;
    if (req.omega0_start_rad_s > 0.0)
      p.sweep_lambda_min_rad_s = req.omega0_start_rad_s - p.omega_rad_s;
    if (req.omega0_end_rad_s > 0.0) p.sweep_lambda_max_rad_s = req.omega0_end_rad_s - p.omega_rad_s;
    if (req.n_points > 0) p.sweep_points = static_cast<int>(req.n_points);
    p.sweep_down = p.sweep_down || req.up_and_down;
    throwIfProblems("sweep request", p.validate());
    startSweep(p, req.seed > 0 ? static_cast<int>(req.seed) : options_.seed);
    res.success = true;
    res.message = "sweep started: " + std::to_string(sweep_.size()) + " points";
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    ROS_ERROR("start_sweep refused: %s", e.what());
  }
  return true;
}

void SimulatorNode::startFreeDecay(double duration_s, int seed, const OrbitElements& start) {
  requireFinite(duration_s, "duration_s");
  if (duration_s < 0.0) throw InputError("duration_s must be >= 0");
  if (duration_s > options_.max_duration_s)
    throw InputError("duration_s = " + std::to_string(duration_s) + " s exceeds max_duration_s = " +
                     std::to_string(options_.max_duration_s) + " s");
  running_ = Running::kNone;
  const double duration = duration_s > 0.0 ? duration_s : options_.duration_s;
  SimulationOptions sim;
  sim.mode = ExperimentMode::kFreeDecay;
  sim.seed = static_cast<std::uint64_t>(seed);
  sim.free_decay_start = start;
  raw_stream_.reset();
  slow_ = SlowRecord();
  slow_truth_ = SlowRecord();
  sweep_ = SweepRecord();
  if (options_.publish_raw)
    raw_stream_.reset(new RawFreeDecayStream(
        preset_, duration > 0.0 ? duration : preset_.decay_raw_duration_s, sim.seed, start));
  if (options_.publish_slow) {
    sim.raw = false;
    // The slow record covers the raw record's span when both are published.
    sim.duration_s =
        duration > 0.0 ? duration : (options_.publish_raw ? preset_.decay_raw_duration_s : 0.0);
    slow_ = simulateExperiment(preset_, sim).slow;
    sim.noise_std = 0.0;
    slow_truth_ = simulateExperiment(preset_, sim).slow;
  }
  beginStreaming(Running::kFreeDecay, ExperimentMode::kFreeDecay, preset_);
  ROS_INFO("free decay started (seed %d): %zu raw samples, %zu slow states", seed,
           raw_stream_ ? raw_stream_->total() : size_t(0), slow_.size());
}

bool SimulatorNode::onStartWholeAngle(StartWholeAngle::Request& req,
                                      StartWholeAngle::Response& res) {
  try {
    WholeAngleOptions o;
    for (double v :
         {req.duration_s, req.amplitude, req.quadrature, req.walk_rad_s, req.loop_rate_1_s})
      requireFinite(v, "start_whole_angle request");
    if (req.duration_s > options_.max_duration_s)
      throw InputError("duration_s = " + std::to_string(req.duration_s) +
                       " s exceeds max_duration_s = " + std::to_string(options_.max_duration_s) +
                       " s");
    o.duration_s = req.duration_s;
    if (req.amplitude != 0.0) o.r0 = req.amplitude;
    o.k0 = req.quadrature;
    o.walk_rad_s = req.walk_rad_s;
    o.loop_rate_1_s = req.loop_rate_1_s;
    o.seed = req.seed > 0 ? req.seed : static_cast<std::uint64_t>(options_.seed);
    running_ = Running::kNone;
    // The core's run (the one `cvg_ident simulate --mode whole_angle` writes), streamed like a
    // free decay's slow states but on its own topic.
    slow_ = simulateWholeAngle(preset_, o);
    slow_truth_ = SlowRecord();
    raw_stream_.reset();
    sweep_ = SweepRecord();
    beginStreaming(Running::kWholeAngle, ExperimentMode::kFreeDecay, preset_);
    res.walk_rad_s = std::strtod(slow_.metadata.at("whole_angle_walk_rad_s").c_str(), nullptr);
    res.n_slow_states = static_cast<uint32_t>(slow_.size());
    res.success = true;
    res.message = "whole-angle run started: " + std::to_string(slow_.size()) +
                  " slow states over " + std::to_string(slow_.t_s.back()) + " s on sim/whole_angle";
    ROS_INFO("%s", res.message.c_str());
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    ROS_ERROR("start_whole_angle refused: %s", e.what());
  }
  return true;
}

void SimulatorNode::startSweep(const ResonatorPreset& preset, int seed) {
  running_ = Running::kNone;
  const ExperimentRunner runner(preset);
  const SweepResult result = runner.forcedSweep();
  raw_stream_.reset();
  slow_ = SlowRecord();
  slow_truth_ = SlowRecord();
  sweep_ = sweepRecordOf(result, preset.omega_rad_s);
  settled_.clear();
  for (const SweepStep& s : result.steps) settled_.push_back(s.settled);
  MeasurementNoise noise(static_cast<std::uint64_t>(seed));
  noise.addTo(sweep_, preset.noise_q_std);
  beginStreaming(Running::kSweep, ExperimentMode::kForced, preset);
  ROS_INFO("forced sweep started (seed %d): %zu points, %d jumps, %d unsettled", seed,
           sweep_.size(), result.n_jumps, result.n_unsettled);
}

void SimulatorNode::beginStreaming(Running what, ExperimentMode mode,
                                   const ResonatorPreset& preset) {
  slow_next_ = sweep_next_ = 0;
  lag_s_ = 0.0;
  ++experiments_;
  start_stamp_ = ros::Time::now() + ros::Duration(options_.start_delay_s);
  wall_start_ = ros::WallTime::now() + ros::WallDuration(options_.start_delay_s);
  running_ = what;
  const std::string spec = preset.truthModelSpec(mode);
  const ResonatorModel model(spec, mode);
  const Eigen::VectorXd z = preset.truthParameters(model);
  SimulationTruth truth =
      truthToMsg(options_.config.empty() ? preset.name : options_.config, experimentModeName(mode),
                 spec, preset.omega_rad_s, preset.mu, model.parameterNames(),
                 model.parameterValues(z), start_stamp_);
  truth.header.frame_id = options_.frame_id;
  truth.raw_noise_std = preset.noise_fg_std;
  truth.slow_noise_std = preset.noise_q_std;
  truth.raw_sample_rate_hz = preset.raw_sample_rate_hz;
  truth.n_raw_samples = static_cast<uint32_t>(raw_stream_ ? raw_stream_->total() : 0);
  truth.n_slow_states = static_cast<uint32_t>(slow_.size());
  truth.n_sweep_points = static_cast<uint32_t>(what == Running::kSweep ? sweep_.size() : 0);
  if (what == Running::kFreeDecay)
    truth.duration_s = std::max(raw_stream_ ? raw_stream_->timeOf(raw_stream_->total() - 1) : 0.0,
                                slow_.size() ? slow_.t_s.back() : 0.0);
  truth_pub_.publish(truth);
}

void SimulatorNode::onTick(const ros::WallTimerEvent&) {
  if (running_ == Running::kNone) return;
  const double wall_elapsed = (ros::WallTime::now() - wall_start_).toSec();
  if (wall_elapsed < 0.0) return;
  if (running_ == Running::kFreeDecay || running_ == Running::kWholeAngle)
    publishDueFreeDecay(wall_elapsed * options_.realtime_factor);
  if (running_ == Running::kSweep) publishDueSweep(wall_elapsed);
}

void SimulatorNode::publishDueFreeDecay(double due_s) {
  const bool raw_done = !raw_stream_ || raw_stream_->produced() >= raw_stream_->total();
  if (!raw_done) {
    // Samples with t <= due_s are due; at most max_batch_samples of them now.
    const double rate = raw_stream_->sampleRateHz();
    const size_t due = std::min(raw_stream_->total(),
                                static_cast<size_t>(std::floor(due_s * rate * (1 + 1e-12))) + 1);
    if (due > raw_stream_->produced()) {
      const size_t cap = static_cast<size_t>(options_.max_batch_samples);
      if (due - raw_stream_->produced() > cap) ++capped_ticks_;
      // What is due, no more (a full cap ran bursts up to a sixth of a second ahead of the clock).
      const RawRecord piece = raw_stream_->next(std::min(cap, due - raw_stream_->produced()));
      RawSampleBatch batch =
          rawBatchToMsg(piece, 0, piece.size(), start_stamp_, preset_.raw_sample_rate_hz);
      batch.header.frame_id = options_.frame_id;
      batch.omega_rad_s = preset_.omega_rad_s;
      raw_pub_.publish(batch);
      raw_published_ += piece.size();
      ++raw_batches_;
    }
    const double due_in_record_s = std::min(due_s, raw_stream_->timeOf(raw_stream_->total() - 1));
    lag_s_ = std::max(0.0, due_in_record_s - raw_stream_->timeOf(raw_stream_->produced() - 1));
    max_lag_s_ = std::max(max_lag_s_, lag_s_);
  }
  for (; slow_next_ < slow_.size() && slow_.t_s[slow_next_] <= due_s; ++slow_next_) {
    const ros::Time stamp = timeAfter(start_stamp_, slow_.t_s[slow_next_]);
    SlowState s = slowStateToMsg(slow_.q[slow_next_], stamp, start_stamp_, preset_.omega_rad_s);
    s.header.frame_id = options_.frame_id;
    (running_ == Running::kWholeAngle ? whole_angle_pub_ : slow_pub_).publish(s);
    if (slow_next_ < slow_truth_.size()) {
      SlowState t =
          slowStateToMsg(slow_truth_.q[slow_next_], stamp, start_stamp_, preset_.omega_rad_s);
      t.header.frame_id = options_.frame_id;
      slow_truth_pub_.publish(t);
    }
    ++slow_published_;
  }
  if ((!raw_stream_ || raw_stream_->produced() >= raw_stream_->total()) &&
      slow_next_ >= slow_.size()) {
    if (raw_stream_) publishEndOfRawRecord();
    ROS_INFO("%s finished (%.6g s simulated)",
             running_ == Running::kWholeAngle ? "whole-angle run" : "free decay", due_s);
    running_ = Running::kNone;
  }
}

// An empty batch after the record's last samples: its sequence number shows a subscriber the
// batches lost at the very end (a gap is otherwise only seen by the next message).
void SimulatorNode::publishEndOfRawRecord() {
  RawSampleBatch end;
  end.header.stamp = timeAfter(start_stamp_, raw_stream_->timeOf(raw_stream_->total() - 1));
  end.header.frame_id = options_.frame_id;
  end.sample_rate_hz = preset_.raw_sample_rate_hz;
  end.phase_epoch = start_stamp_;
  end.omega_rad_s = preset_.omega_rad_s;
  raw_pub_.publish(end);
}

void SimulatorNode::publishDueSweep(double wall_elapsed_s) {
  const double interval = std::max(options_.sweep_point_interval_s, 1e-9);
  for (; sweep_next_ < sweep_.size() && sweep_next_ * interval <= wall_elapsed_s; ++sweep_next_) {
    SweepPoint p = sweepPointToMsg(sweep_, sweep_next_, ros::Time::now());
    p.settled = settled_[sweep_next_];
    p.header.frame_id = options_.frame_id;
    sweep_pub_.publish(p);
    ++sweep_published_;
  }
  if (sweep_next_ >= sweep_.size()) {
    running_ = Running::kNone;
    ROS_INFO("forced sweep finished (%zu points)", sweep_.size());
  }
}

void SimulatorNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const ros::WallTime now = ros::WallTime::now();
  const double dt = (now - last_diag_wall_).toSec();
  const double raw_rate = dt > 0.0 ? (raw_published_ - raw_at_last_diag_) / dt : 0.0;
  last_diag_wall_ = now;
  raw_at_last_diag_ = raw_published_;
  const char* state = running_ == Running::kFreeDecay    ? "free decay"
                      : running_ == Running::kSweep      ? "forced sweep"
                      : running_ == Running::kWholeAngle ? "whole-angle run"
                      : experiments_ > 0                 ? "finished"
                                                         : "idle";
  // Behind by more than two ticks of simulated time: the requested real-time factor is not met.
  const double tick_s = options_.realtime_factor / options_.publish_rate_hz;
  if (running_ == Running::kFreeDecay && lag_s_ > 2.0 * tick_s)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                  "%s: %.3g s of simulated time behind realtime_factor %.3g", state, lag_s_,
                  options_.realtime_factor);
  else
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "%s", state);
  stat.add("experiments_started", experiments_);
  stat.add("raw_output_rate_hz", raw_rate);
  stat.add("raw_samples_published", raw_published_);
  stat.add("raw_batches_published", raw_batches_);
  stat.add("raw_samples_of_record", raw_stream_ ? raw_stream_->total() : 0);
  stat.add("ticks_capped_at_max_batch_samples", capped_ticks_);
  stat.add("lag_s", lag_s_);
  stat.add("max_lag_s", max_lag_s_);
  stat.add("slow_states_published", slow_published_);
  stat.add("sweep_points_published", sweep_published_);
  stat.add("raw_subscribers", raw_pub_.getNumSubscribers());
  stat.add("realtime_factor", options_.realtime_factor);
}

}  // namespace cvg_bench
