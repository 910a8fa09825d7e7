// identifier_node (see identifier_node.h).
#include "cvg_bench/ros/identifier_node.h"

#include <geometry_msgs/TransformStamped.h>
#include <tf2/LinearMath/Quaternion.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/DerivedQuantitiesStamped.h"
#include "cvg_bench/DriftRate.h"
#include "cvg_bench/ModelEstimate.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/diagnose/explanation.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/report/explain_json.h"
#include "cvg_bench/ros/bench_markers.h"
#include "cvg_bench/ros/conversions.h"
#include "cvg_bench/ros/estimate_sanity.h"

namespace cvg_bench {
namespace {

IdentifierNodeOptions loadIdentifierOptions(const ros::NodeHandle& pnh) {
  ParamReader reader(pnh);
  return loadOptions<IdentifierNodeOptions>(reader);
}

ParameterValues valuesOf(const Estimate& e) {
  ParameterValues v;
  for (size_t i = 0; i < e.names.size() && static_cast<Eigen::Index>(i) < e.values.size(); ++i)
    v[e.names[i]] = e.values[i];
  return v;
}

geometry_msgs::TransformStamped rotationAboutZ(const std::string& parent, const std::string& child,
                                               double angle_rad, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, angle_rad);
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

std::string summary(const Estimate& e, size_t samples) {
  std::ostringstream s;
  s << e.method << " " << e.model << " over " << samples << " samples: " << e.n_equations
    << " equations, rank " << e.rank << " of " << e.n_params << ", sigma = " << e.sigma;
  if (!e.unidentifiable.empty()) {
    s << "; NOT identifiable:";
    for (const auto& n : e.unidentifiable) s << " " << n;
    if (!e.identifiability_note.empty()) s << " (" << e.identifiability_note << ")";
  }
  return s.str();
}

}  // namespace

IdentifierNode::IdentifierNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), options_(loadIdentifierOptions(pnh)), mode_(parseExperimentMode(options_.mode)) {
  if (options_.identification.method == "rls")
    rls_.reset(new StreamingFreeDecayRls(options_.identification));
  estimate_pub_ = nh_.advertise<ModelEstimate>("estimate", 10, /*latch=*/true);
  derived_pub_ = nh_.advertise<DerivedQuantitiesStamped>("derived", 10, /*latch=*/true);
  drift_pub_ = nh_.advertise<DriftRate>("drift", 10);
  markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("markers", 2, /*latch=*/true);
  if (mode_ == ExperimentMode::kFreeDecay)
    data_sub_ = nh_.subscribe("slow", options_.queue_size, &IdentifierNode::onSlow, this);
  else
    data_sub_ = nh_.subscribe("sweep", options_.queue_size, &IdentifierNode::onSweep, this);
  truth_sub_ = nh_.subscribe("truth", 10, &IdentifierNode::onTruth, this);
  loss_sub_ = nh_.subscribe("input_loss", 100, &IdentifierNode::onInputLoss, this);
  // A whole-angle run arrives as a burst of states (thousands a second): its own deep queue, and
  // sequence gaps counted (WholeAngleRunBuffer::lost: the subscriber queue's overflow or the
  // network) rather than a silently shorter run.
  whole_angle_sub_ = nh_.subscribe("whole_angle", std::max(options_.queue_size, 100000),
                                   &IdentifierNode::onWholeAngle, this);
  drift_measured_pub_ = nh_.advertise<DriftMeasured>("drift_measured", 2, /*latch=*/true);
  // Services on their own thread: a solve they ask for does not hold up the data callbacks.
  ros::NodeHandle services(nh_);
  services.setCallbackQueue(&service_queue_);
  identify_srv_ = services.advertiseService("identify", &IdentifierNode::onIdentify, this);
  get_estimate_srv_ =
      services.advertiseService("get_estimate", &IdentifierNode::onGetEstimate, this);
  predict_drift_srv_ =
      services.advertiseService("predict_drift", &IdentifierNode::onPredictDrift, this);
  reset_srv_ = services.advertiseService("identifier/reset", &IdentifierNode::onReset, this);
  explain_srv_ = services.advertiseService("explain", &IdentifierNode::onExplain, this);
  measure_drift_srv_ =
      services.advertiseService("measure_drift", &IdentifierNode::onMeasureDrift, this);
  timer_ = nh_.createWallTimer(ros::WallDuration(0.05), &IdentifierNode::onTimer, this);
  reconfigure_.reset(new dynamic_reconfigure::Server<IdentifierConfig>(pnh));
  reconfigure_->setCallback(
      [this](IdentifierConfig& c, uint32_t level) { onReconfigure(c, level); });
  diagnostics_.setHardwareID("cvg_bench identifier");
  diagnostics_.add("identifier", this, &IdentifierNode::diagnose);
  last_diag_wall_ = ros::WallTime::now();
  diagnostics_timer_ = nh_.createWallTimer(
      ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) { diagnostics_.force_update(); });
  service_spinner_.reset(new ros::AsyncSpinner(1, &service_queue_));
  service_spinner_->start();
  ROS_INFO("identifier: %s, model %s, method %s", options_.mode.c_str(),
           options_.identification.model.c_str(), options_.identification.method.c_str());
}

IdentifierNode::~IdentifierNode() {
  if (service_spinner_) service_spinner_->stop();
  if (background_.valid()) background_.wait();
}

double IdentifierNode::omegaForEstimate() const {
  return options_.identification.omega_rad_s > 0.0 ? options_.identification.omega_rad_s
                                                   : omega_from_data_rad_s_;
}

void IdentifierNode::clearData(const std::string& why) {
  clearBuffer();
  ROS_WARN("identifier: data cleared: %s", why.c_str());
}

void IdentifierNode::clearBuffer() {
  ++generation_;
  last_axes_stamp_ = ros::Time();  // a bag loop's experiment may start earlier in time
  stamps_.clear();
  slow_q_.clear();
  sweep_ = SweepRecord();
  have_latest_ = false;
  new_data_since_identify_ = false;
  lost_gaps_.clear();
  upstream_gaps_.clear();
  if (rls_) rls_->reset();
  rls_origin_ = ros::Time();
}

void IdentifierNode::onTruth(const SimulationTruth::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (msg->mode != options_.mode && truth_mode_warned_ != msg->mode) {
    truth_mode_warned_ = msg->mode;
    ROS_WARN(
        "identifier: the simulator runs a %s experiment but this identifier's mode is %s "
        "(it subscribes to %s): start both with the same mode (mode:=%s, autostart:=%s)",
        msg->mode.c_str(), options_.mode.c_str(),
        mode_ == ExperimentMode::kFreeDecay ? "slow" : "sweep",
        msg->mode == "forced" ? "forced" : "free_decay",
        msg->mode == "forced" ? "forced" : "free_decay");
  }
  tracker_.onStartEvent(msg->header.stamp);
}

void IdentifierNode::onReconfigure(IdentifierConfig& c, uint32_t) {
  std::lock_guard<std::mutex> lock(mutex_);
  IdentifierNodeOptions next = options_;
  next.identification.model = c.model;
  next.identification.method = c.method;
  next.identification.confidence = c.confidence;
  next.identification.rls_forgetting = c.rls_forgetting;
  next.window_s = c.window_s;
  next.identify_period_s = c.identify_period_s;
  const std::vector<std::string> problems = next.validate();
  if (!problems.empty()) {
    ROS_WARN(
        "%s",
        joinProblems("identifier: reconfiguration refused, settings unchanged", problems).c_str());
    c.model = options_.identification.model;
    c.method = options_.identification.method;
    c.confidence = options_.identification.confidence;
    c.rls_forgetting = options_.identification.rls_forgetting;
    c.window_s = options_.window_s;
    c.identify_period_s = options_.identify_period_s;
    return;
  }
  const bool refit = next.identification.model != options_.identification.model ||
                     next.identification.method != options_.identification.method ||
                     next.identification.confidence != options_.identification.confidence ||
                     next.identification.rls_forgetting != options_.identification.rls_forgetting ||
                     next.window_s != options_.window_s;
  options_ = next;
  if (!refit) return;
  ++generation_;  // a solve in flight used the old settings
  rls_.reset(options_.identification.method == "rls"
                 ? new StreamingFreeDecayRls(options_.identification)
                 : nullptr);
  rls_origin_ = ros::Time();
  // The buffered data are identified again with the new settings (at once when they stopped).
  if (!stamps_.empty()) new_data_since_identify_ = true;
  ROS_INFO(
      "identifier: reconfigured: model %s, method %s, window %.6g s, forgetting %.6g, "
      "confidence %.6g, identify_period %.6g s",
      options_.identification.model.c_str(), options_.identification.method.c_str(),
      options_.window_s, options_.identification.rls_forgetting, options_.identification.confidence,
      options_.identify_period_s);
}

uint64_t IdentifierNode::lostSince(const ros::Time& since) const {
  uint64_t n = 0;
  for (const auto& g : lost_gaps_)
    if (g.first > since) n += g.second;
  return n;
}

uint64_t IdentifierNode::upstreamLostSince(const ros::Time& since) const {
  uint64_t n = 0;
  for (const auto& g : upstream_gaps_)
    if (g.first > since) n += g.second;
  return n;
}

void IdentifierNode::onInputLoss(const InputLoss::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  upstream_batches_lost_ += msg->batches_lost;
  upstream_gaps_.emplace_back(msg->header.stamp, msg->batches_lost);
  ROS_WARN_THROTTLE(5.0,
                    "identifier: %s: %u lost before %.6f s; estimates over that data will be "
                    "marked suspect",
                    msg->source.c_str(), msg->batches_lost, msg->header.stamp.toSec());
}

std::vector<std::string> IdentifierNode::estimateProblems() {
  std::vector<std::string> problems = sanityProblems(estimate_);
  // Gaps before the window's first sample no longer touch its data (a sliding window).
  for (auto* gaps : {&lost_gaps_, &upstream_gaps_})
    while (!gaps->empty() && !stamps_.empty() && gaps->front().first <= stamps_.front())
      gaps->pop_front();
  const uint64_t lost = lostSince(window_start_);
  if (lost > 0)
    problems.push_back(std::to_string(lost) +
                       " input messages lost in transport (sequence gaps) within the data of "
                       "this estimate");
  const uint64_t upstream = upstreamLostSince(window_start_);
  if (upstream > 0)
    problems.push_back(std::to_string(upstream) +
                       " raw batches lost upstream (the demodulator's input, sequence gaps) "
                       "within the data of this estimate");
  return problems;
}

void IdentifierNode::countSequence(uint32_t seq, const ros::Time& stamp) {
  ++received_;
  // Publishers number their messages; a skipped number is a message lost on the way (a full
  // subscriber queue). A number going back is a restarted publisher or a looped bag.
  if (have_seq_ && seq > last_seq_) {
    dropped_transport_ += seq - last_seq_ - 1;
    lost_gaps_.emplace_back(stamp, seq - last_seq_ - 1);
  }
  have_seq_ = true;
  last_seq_ = seq;
}

void IdentifierNode::trackExperiment(const ros::Time& epoch, const ros::Time& stamp) {
  const ExperimentTracker::Boundary b = tracker_.onSample(epoch, stamp);
  if (b == ExperimentTracker::Boundary::kNone) return;
  if (buffer_experiment_ > 0) {
    // Finish the old experiment's estimate from its own data before the buffer is cleared.
    if (new_data_since_identify_ && static_cast<int>(stamps_.size()) >= options_.min_samples) {
      try {
        identifyNow(options_.identification);
      } catch (const std::exception& e) {
        ROS_WARN("identifier: final identification of experiment %u failed: %s", buffer_experiment_,
                 e.what());
      }
    }
    clearBuffer();
  }
  buffer_experiment_ = tracker_.id();
  buffer_experiment_start_ = tracker_.start();
  marker_r_ref_ = 0.0;
  if (b == ExperimentTracker::Boundary::kJumpBack) {
    if (!loop_warned_)
      ROS_WARN(
          "identifier: %s: experiment %u starts afresh (further jumps are counted in the "
          "diagnostics, not logged)",
          ExperimentTracker::describe(b).c_str(), buffer_experiment_);
    else
      ROS_DEBUG("identifier: jump back in time, experiment %u", buffer_experiment_);
    loop_warned_ = true;
  } else {
    ROS_INFO("identifier: experiment %u: %s", buffer_experiment_,
             ExperimentTracker::describe(b).c_str());
  }
}

void IdentifierNode::onSlow(const SlowState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  countSequence(msg->header.seq, msg->header.stamp);
  Eigen::Vector4d q;
  try {
    q = slowFromMsg(*msg);
  } catch (const InputError& e) {
    ++dropped_;
    ++dropped_invalid_;
    ROS_WARN_THROTTLE(5.0, "identifier: slow state dropped (%llu so far): %s",
                      static_cast<unsigned long long>(dropped_), e.what());
    return;
  }
  const ros::Time stamp = msg->header.stamp;
  trackExperiment(msg->phase_epoch, stamp);
  if (have_latest_ && stamp == latest_stamp_) {
    ++dropped_;
    ++dropped_duplicate_;
    ROS_WARN_THROTTLE(5.0, "identifier: duplicate slow-state stamp dropped (%llu so far)",
                      static_cast<unsigned long long>(dropped_));
    return;
  }
  const double omega = msg->reference_frequency_rad_s - msg->detuning_rad_s;
  if (omega > 0.0 && std::isfinite(omega)) omega_from_data_rad_s_ = omega;
  stamps_.push_back(stamp);
  slow_q_.push_back(q);
  while (static_cast<int>(stamps_.size()) > options_.max_samples ||
         (options_.window_s > 0.0 &&
          secondsSince(stamps_.back(), stamps_.front()) > options_.window_s)) {
    stamps_.pop_front();
    slow_q_.pop_front();
    ++trimmed_;
  }
  latest_q_ = q;
  latest_stamp_ = stamp;
  have_latest_ = true;
  last_data_wall_ = ros::WallTime::now();
  finished_ = false;
  new_data_since_identify_ = true;

  if (rls_) {
    if (rls_origin_.isZero()) rls_origin_ = stamp;
    try {
      rls_->add(secondsSince(stamp, rls_origin_), q);
      const ros::WallTime now = ros::WallTime::now();
      if (rls_->initialized() &&
          (now - last_rls_publish_wall_).toSec() >= options_.rls_publish_period_s) {
        estimate_ = rls_->estimate(omegaForEstimate());
        window_start_ = rls_origin_;
        window_end_ = stamp;
        window_samples_ = static_cast<uint32_t>(rls_->numBlocks() + 2);
        have_estimate_ = true;
        axes_pending_ = true;
        last_rls_publish_wall_ = now;
        publishEstimate();
      }
    } catch (const std::exception& e) {
      ROS_WARN_THROTTLE(5.0, "identifier: recursive estimate restarted: %s", e.what());
      rls_->reset();
      rls_origin_ = ros::Time();
    }
  }
  publishFrames();
}

void IdentifierNode::onSweep(const SweepPoint::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const ros::Time stamp = msg->header.stamp;
  countSequence(msg->header.seq, msg->header.stamp);
  trackExperiment(ros::Time(), stamp);
  try {
    appendSweepPoint(*msg, &sweep_);
  } catch (const InputError& e) {
    ++dropped_;
    ++dropped_invalid_;
    ROS_WARN_THROTTLE(5.0, "identifier: sweep point dropped (%llu so far): %s",
                      static_cast<unsigned long long>(dropped_), e.what());
    return;
  }
  if (msg->omega_rad_s > 0.0) omega_from_data_rad_s_ = msg->omega_rad_s;
  stamps_.push_back(stamp);
  if (static_cast<int>(sweep_.size()) > options_.max_samples) {
    sweep_.omega0_rad_s.erase(sweep_.omega0_rad_s.begin());
    sweep_.q.erase(sweep_.q.begin());
    if (!sweep_.direction.empty()) sweep_.direction.erase(sweep_.direction.begin());
    if (!sweep_.jump.empty()) sweep_.jump.erase(sweep_.jump.begin());
    stamps_.pop_front();
    ++trimmed_;
  }
  latest_q_ = sweep_.q.back();
  latest_stamp_ = stamp;
  have_latest_ = true;
  last_data_wall_ = ros::WallTime::now();
  finished_ = false;
  new_data_since_identify_ = true;
  publishFrames();
}

SlowRecord IdentifierNode::bufferedSlowRecord() const {
  SlowRecord rec;
  rec.omega_rad_s = omega_from_data_rad_s_;
  rec.source = "identifier buffer";
  rec.t_s.reserve(stamps_.size());
  for (size_t i = 0; i < stamps_.size(); ++i) {
    rec.t_s.push_back(secondsSince(stamps_[i], stamps_.front()));
    rec.q.push_back(slow_q_[i]);
  }
  return rec;
}

PipelineOptions IdentifierNode::periodicOptions() const {
  // The window's batch estimate is the honest least-squares one (in `rls` mode the same z at
  // forgetting 1 as the streaming estimate, docs/paper.md item 9, with honest intervals).
  PipelineOptions batch;
  batch.method = Method::kLs;
  batch.identification = options_.identification;
  return batch;
}

void IdentifierNode::identifyNow(const IdentificationOptions& options) {
  PipelineOptions batch = periodicOptions();
  batch.identification = options;
  identifyNow(batch);
}

IdentifierNode::SolveInput IdentifierNode::snapshot(const PipelineOptions& options) const {
  const int have = static_cast<int>(stamps_.size());
  if (have < options_.min_samples)
    throw InputError("only " + std::to_string(have) +
                     (mode_ == ExperimentMode::kFreeDecay ? " slow states" : " sweep points") +
                     " buffered; min_samples is " + std::to_string(options_.min_samples));
  SolveInput in;
  if (mode_ == ExperimentMode::kFreeDecay)
    in.slow = bufferedSlowRecord();
  else
    in.sweep = sweep_;
  in.options = options;
  in.start = stamps_.front();
  in.end = stamps_.back();
  in.samples = static_cast<uint32_t>(have);
  in.generation = generation_;
  in.identifications_before = identifications_;
  return in;
}

Estimate IdentifierNode::solve(const SolveInput& in) const {
  return mode_ == ExperimentMode::kFreeDecay ? identify(in.slow, in.options)
                                             : identify(in.sweep, in.options);
}

void IdentifierNode::acceptEstimate(const Estimate& e, const SolveInput& in, double wall_s) {
  last_identify_wall_s_ = wall_s;
  ++identifications_;  // a solve still in flight is older than this estimate
  last_solver_message_ = summary(e, in.samples);
  estimate_ = e;
  window_start_ = in.start;
  window_end_ = in.end;
  window_samples_ = in.samples;
  have_estimate_ = true;
  axes_pending_ = true;
  // The end-of-data estimate of the whole buffer: the experiment is finished (panel, diagnostics).
  finished_ = options_.idle_identify_s > 0.0 && in.samples == stamps_.size() &&
              (ros::WallTime::now() - last_data_wall_).toSec() >= options_.idle_identify_s;
  if (e.rank < e.n_params)
    ROS_WARN("identifier: %s", summary(e, in.samples).c_str());
  else
    ROS_INFO("identifier: %s", summary(e, in.samples).c_str());
  publishEstimate();
}

void IdentifierNode::identifyNow(const PipelineOptions& options) {
  const SolveInput in = snapshot(options);
  const ros::WallTime t0 = ros::WallTime::now();
  Estimate e;
  try {
    e = solve(in);
  } catch (const std::exception& ex) {
    ++identification_failures_;
    last_solver_message_ = std::string("failed: ") + ex.what();
    throw;
  }
  new_data_since_identify_ = false;
  acceptEstimate(e, in, (ros::WallTime::now() - t0).toSec());
}

void IdentifierNode::startBackgroundSolve() {
  // Too few states yet (the start of a run or a rerun) is normal: the next period tries again.
  if (static_cast<int>(stamps_.size()) < options_.min_samples) return;
  try {
    background_input_ = snapshot(periodicOptions());
  } catch (const std::exception& e) {
    ROS_WARN("identifier: identification failed: %s", e.what());
    return;
  }
  background_started_ = ros::WallTime::now();
  const SolveInput* in = &background_input_;  // not touched again until the result is taken
  background_ = std::async(std::launch::async, [this, in] { return solve(*in); });
}

void IdentifierNode::collectBackgroundSolve() {
  if (!background_.valid() ||
      background_.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
    return;
  const double wall_s = (ros::WallTime::now() - background_started_).toSec();
  Estimate e;
  try {
    e = background_.get();
  } catch (const std::exception& ex) {
    ++identification_failures_;
    last_solver_message_ = std::string("failed: ") + ex.what();
    ROS_WARN("identifier: identification failed: %s", ex.what());
    return;
  }
  if (background_input_.generation != generation_ ||
      background_input_.identifications_before != identifications_) {
    ++stale_solves_;  // the buffer changed, or a newer estimate came, while it ran
    ROS_DEBUG("identifier: a solve of a buffer that has changed since was discarded");
    return;
  }
  acceptEstimate(e, background_input_, wall_s);
}

void IdentifierNode::onTimer(const ros::WallTimerEvent&) {
  std::lock_guard<std::mutex> lock(mutex_);
  collectBackgroundSolve();
  if (background_.valid()) return;  // one solve at a time; data that came meanwhile go next
  const ros::WallTime now = ros::WallTime::now();
  bool run = false;
  if (options_.identify_period_s > 0.0 && new_data_since_identify_ &&
      (now - last_periodic_wall_).toSec() >= options_.identify_period_s) {
    run = true;
    last_periodic_wall_ = now;
  }
  if (options_.idle_identify_s > 0.0 && new_data_since_identify_ &&
      (now - last_data_wall_).toSec() >= options_.idle_identify_s)
    run = true;
  if (!run) return;
  new_data_since_identify_ = false;  // one attempt per batch of new data
  startBackgroundSolve();
}

void IdentifierNode::publishEstimate() {
  ModelEstimate msg = estimateToMsg(estimate_, window_start_, window_end_, window_samples_);
  msg.header.frame_id = options_.frame_id;
  msg.experiment_id = buffer_experiment_;
  msg.experiment_start = buffer_experiment_start_;
  msg.sanity_problems = estimateProblems();
  msg.suspect = !msg.sanity_problems.empty();
  if (msg.suspect) {
    ++suspect_estimates_;
    std::string all;
    for (const auto& p : msg.sanity_problems) all += "; " + p;
    ROS_WARN_THROTTLE(5.0, "identifier: estimate of experiment %u is suspect%s", buffer_experiment_,
                      all.c_str());
  }
  last_sanity_problems_ = msg.sanity_problems;
  estimate_pub_.publish(msg);
  DerivedQuantitiesStamped d = derivedToMsg(estimate_.derived, window_end_, estimate_.confidence,
                                            options_.identification.angular_gain_k);
  d.header.frame_id = options_.frame_id;
  if (!estimate_.derived.empty()) derived_pub_.publish(d);
  if (history_.empty() || history_.back().estimate.experiment_id != msg.experiment_id)
    history_.emplace_back();
  history_.back() = {msg, d, summary(estimate_, window_samples_),
                     estimate_.rank == estimate_.n_params};
  while (static_cast<int>(history_.size()) > options_.history_size) history_.pop_front();
  if (have_latest_) {
    const OrbitElements o = orbitFromSlow(latest_q_);
    if (std::fabs(o.r * o.r - o.k * o.k) > 1e-12 * (o.r * o.r + 1e-300)) {
      try {
        const ParameterEstimate rate =
            driftRateWithInterval(o.r, o.k, o.theta, uncertainParameters(estimate_));
        last_drift_rad_s_ = rate;
        have_drift_ = true;
        DriftRate d = driftRateToMsg(o.r, o.k, o.theta, rate, estimate_.confidence, latest_stamp_);
        d.header.frame_id = options_.frame_id;
        drift_pub_.publish(d);
      } catch (const std::exception& e) {
        ROS_WARN_THROTTLE(5.0, "identifier: no drift rate: %s", e.what());
      }
    }
  }
  updateWindowDrift();
  publishFrames();
}

void IdentifierNode::updateWindowDrift() {
  // The rviz headline (issue #27): theta' of the estimate averaged over the buffered states whose
  // amplitude is above 10 % of the largest (near r = k the instantaneous (5.9) swings widely); at
  // most 200 evenly spaced states keep the delta method cheap.
  have_window_drift_ = false;
  if (mode_ != ExperimentMode::kFreeDecay || slow_q_.empty()) return;
  std::vector<OrbitElements> all;
  all.reserve(slow_q_.size());
  double r_max = 0.0;
  for (const Eigen::Vector4d& q : slow_q_) {
    all.push_back(orbitFromSlow(q));
    r_max = std::max(r_max, std::fabs(all.back().r));
  }
  std::vector<OrbitElements> kept;
  for (const OrbitElements& o : all)
    if (std::fabs(o.r) > 0.1 * r_max && std::fabs(o.r * o.r - o.k * o.k) > 1e-12 * o.r * o.r)
      kept.push_back(o);
  if (kept.empty()) return;
  std::vector<OrbitElements> used;
  const std::size_t step = (kept.size() + 199) / 200;
  for (std::size_t i = 0; i < kept.size(); i += step) used.push_back(kept[i]);
  try {
    window_drift_rad_s_ = meanDriftRateWithInterval(used, uncertainParameters(estimate_));
    have_window_drift_ = true;
  } catch (const std::exception& e) {
    ROS_DEBUG("identifier: no window drift: %s", e.what());
  }
}

void IdentifierNode::publishFrames() {
  if (!have_estimate_ && !have_latest_) return;
  const ros::Time stamp = have_latest_ ? latest_stamp_ : window_end_;
  const ros::WallTime now = ros::WallTime::now();
  // tf2 rejects a repeated stamp per child frame; 20 Hz is plenty for rviz. A new estimate's axis
  // frames are sent at once, even at the stamp the wave pattern was last sent with.
  const bool repeated = stamp == last_tf_stamp_;
  const bool throttled = (now - last_tf_wall_).toSec() < 0.05;
  if (!(have_estimate_ && axes_pending_) && (repeated || throttled)) return;
  std::vector<geometry_msgs::TransformStamped> frames;
  const std::string& parent = options_.frame_id;
  const std::string& prefix = options_.child_frame_prefix;
  if (have_estimate_) {
    // Two estimates at one data stamp (the last periodic one and the end-of-data one) would repeat
    // the axes' stamp (TF_REPEATED_DATA in every listener): the second goes 1 ns later.
    const ros::Time axes_stamp =
        stamp > last_axes_stamp_ ? stamp : last_axes_stamp_ + ros::Duration(0, 1);
    last_axes_stamp_ = axes_stamp;
    const DefectAxes axes = defectAxes(valuesOf(estimate_));
    frames.push_back(rotationAboutZ(parent, prefix + "stiffness_axis", axes.alpha, axes_stamp));
    frames.push_back(rotationAboutZ(parent, prefix + "damping_axis", axes.beta, axes_stamp));
    axes_pending_ = false;
  }
  last_tf_wall_ = now;
  publishMarkers();
  if (repeated) {
    tf_.sendTransform(frames);
    return;
  }
  last_tf_stamp_ = stamp;
  if (have_latest_)
    frames.push_back(
        rotationAboutZ(parent, prefix + "wave_pattern", orbitFromSlow(latest_q_).theta, stamp));
  tf_.sendTransform(frames);
}

void IdentifierNode::publishMarkers() {
  BenchView v;
  v.frame_id = options_.frame_id;
  v.stamp = latest_stamp_;
  if (have_latest_) {
    const OrbitElements o = orbitFromSlow(latest_q_);
    v.have_state = true;
    v.r = o.r;
    v.theta_rad = o.theta;
    marker_r_ref_ = std::max(marker_r_ref_, std::fabs(o.r));
    v.r_ref = marker_r_ref_;
  }
  if (have_estimate_) {
    const DefectAxes axes = defectAxes(valuesOf(estimate_));
    v.have_axes = true;
    v.alpha_rad = axes.alpha;
    v.beta_rad = axes.beta;
    std::ostringstream t;
    t.precision(4);
    const auto line = [&](const char* label, const char* key, double scale, const char* unit) {
      const auto it = estimate_.derived.find(key);
      if (it == estimate_.derived.end()) return;
      t << label << " = " << it->second.value * scale << " [" << it->second.ci_low * scale << ", "
        << it->second.ci_high * scale << "]" << unit << "\n";
    };
    t << nh_.getNamespace() << ": experiment " << buffer_experiment_
      << (finished_ ? " finished: final estimate, " : ", ") << window_samples_ << " samples, "
      << estimate_.method << " " << estimate_.model << "\n";
    line("Q", "Q", 1.0, "");
    line("split", "frequency_split_hz", 1.0, " Hz");
    constexpr double kDegPerHour = 180.0 / M_PI * 3600.0;  // from rad/s
    if (have_window_drift_)
      t << "drift (window mean) = " << window_drift_rad_s_.value * kDegPerHour << " ["
        << window_drift_rad_s_.ci_low * kDegPerHour << ", "
        << window_drift_rad_s_.ci_high * kDegPerHour << "] deg/h\n";
    if (have_drift_)
      t << "  now: " << last_drift_rad_s_.value * kDegPerHour << " ["
        << last_drift_rad_s_.ci_low * kDegPerHour << ", " << last_drift_rad_s_.ci_high * kDegPerHour
        << "] deg/h\n";
    if (v.have_state)
      t << "r = " << v.r << " (" << 100.0 * std::fabs(v.r) / std::max(v.r_ref, 1e-300)
        << " % of the start), theta = " << v.theta_rad * 180 / M_PI << " deg\n";
    t << estimate_.confidence * 100 << " % intervals";
    if (!last_sanity_problems_.empty()) t << "\nSUSPECT: " << last_sanity_problems_.front();
    v.panel = t.str();
  }
  markers_pub_.publish(benchMarkers(v));
}

bool IdentifierNode::onIdentify(Identify::Request& req, Identify::Response& res) {
  // Every method of the pipeline: ls, rls (batch recursive (2.12)) and ceres (output error).
  // Solved on the service thread outside the lock; the buffer goes on filling meanwhile.
  try {
    SolveInput in;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      PipelineOptions o;
      o.identification = options_.identification;
      if (!req.model.empty()) o.identification.model = req.model;
      if (req.confidence != 0.0) o.identification.confidence = req.confidence;
      o.method = parseMethod(req.method.empty() ? options_.identification.method : req.method);
      throwIfProblems("identify request", o.validate());
      in = snapshot(o);
    }
    const ros::WallTime t0 = ros::WallTime::now();
    Estimate e;
    try {
      e = solve(in);
    } catch (const std::exception& ex) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++identification_failures_;
      last_solver_message_ = std::string("failed: ") + ex.what();
      throw;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (in.generation != generation_)
      throw InputError(
          "the buffer was cleared or the settings changed while identifying (a new experiment, a "
          "reset or a reconfiguration): call identify again");
    acceptEstimate(e, in, (ros::WallTime::now() - t0).toSec());
    res.success = estimate_.rank == estimate_.n_params;
    res.message = summary(estimate_, window_samples_);
    res.estimate = estimateToMsg(estimate_, window_start_, window_end_, window_samples_);
    res.estimate.header.frame_id = options_.frame_id;
    res.estimate.experiment_id = buffer_experiment_;
    res.estimate.experiment_start = buffer_experiment_start_;
    res.estimate.sanity_problems = estimateProblems();
    res.estimate.suspect = !res.estimate.sanity_problems.empty();
    res.derived = derivedToMsg(estimate_.derived, window_end_, estimate_.confidence,
                               in.options.identification.angular_gain_k);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool IdentifierNode::onGetEstimate(GetEstimate::Request& req, GetEstimate::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (req.experiment_id != 0) {
    for (const StoredEstimate& h : history_)
      if (h.estimate.experiment_id == req.experiment_id) {
        res.success = h.full_rank;
        res.message = "experiment " + std::to_string(req.experiment_id) + ": " + h.summary;
        res.estimate = h.estimate;
        res.derived = h.derived;
        return true;
      }
    res.success = false;
    std::string kept;
    for (const StoredEstimate& h : history_)
      kept += (kept.empty() ? "" : ", ") + std::to_string(h.estimate.experiment_id);
    res.message = "no estimate of experiment " + std::to_string(req.experiment_id) +
                  " (kept: " + (kept.empty() ? "none" : kept) + ")";
    return true;
  }
  if (!have_estimate_) {
    res.success = false;
    res.message = "no estimate yet (" + std::to_string(stamps_.size()) + " samples buffered)";
    return true;
  }
  res.success = estimate_.rank == estimate_.n_params;
  res.message = summary(estimate_, window_samples_);
  res.estimate = estimateToMsg(estimate_, window_start_, window_end_, window_samples_);
  res.estimate.header.frame_id = options_.frame_id;
  if (!history_.empty()) {
    res.estimate.experiment_id = history_.back().estimate.experiment_id;
    res.estimate.experiment_start = history_.back().estimate.experiment_start;
  }
  res.estimate.sanity_problems = estimateProblems();
  res.estimate.suspect = !res.estimate.sanity_problems.empty();
  res.derived = derivedToMsg(estimate_.derived, window_end_, estimate_.confidence,
                             options_.identification.angular_gain_k);
  return true;
}

void IdentifierNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const ros::WallTime now = ros::WallTime::now();
  const double dt = (now - last_diag_wall_).toSec();
  const double rate = dt > 0.0 ? (received_ - received_at_last_diag_) / dt : 0.0;
  last_diag_wall_ = now;
  received_at_last_diag_ = received_;
  const uint64_t drops = dropped_invalid_ + dropped_duplicate_ + dropped_transport_;
  if (!last_sanity_problems_.empty())
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "estimate of experiment %u suspect: %s",
                  buffer_experiment_, last_sanity_problems_.front().c_str());
  else if (drops > 0)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%llu inputs dropped",
                  static_cast<unsigned long long>(drops));
  else if (received_ == 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "waiting for data");
  else if (finished_)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::OK,
                  "finished: final estimate of experiment %u", buffer_experiment_);
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "ok");
  stat.add("input_rate_hz", rate);
  stat.add("received", received_);
  stat.add("dropped_invalid", dropped_invalid_);
  stat.add("dropped_duplicate_stamp", dropped_duplicate_);
  stat.add("dropped_in_transport", dropped_transport_);
  stat.add("upstream_batches_lost", upstream_batches_lost_);
  stat.add("trimmed_oldest", trimmed_);
  stat.add("buffer_depth", stamps_.size());
  stat.add("buffer_capacity", options_.max_samples);
  stat.add("experiment_id", buffer_experiment_);
  stat.add("jumps_back_in_time", tracker_.jumpsBack());
  stat.add("identifications", identifications_);
  stat.add("identification_failures", identification_failures_);
  stat.add("last_identification_wall_s", last_identify_wall_s_);
  stat.add("solving", background_.valid());
  stat.add("stale_solves_discarded", stale_solves_);
  stat.add("solver", last_solver_message_);
  stat.add("suspect_estimates", suspect_estimates_);
  stat.add("whole_angle_states", whole_angle_.size());
  stat.add("whole_angle_dropped", whole_angle_.dropped());
  stat.add("whole_angle_lost", whole_angle_.lost());
  for (size_t i = 0; i < last_sanity_problems_.size(); ++i)
    stat.add("sanity_problem_" + std::to_string(i + 1), last_sanity_problems_[i]);
}

bool IdentifierNode::onPredictDrift(PredictDrift::Request& req, PredictDrift::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    if (!have_estimate_) throw InputError("no estimate yet: call identify first");
    double r = req.r, k = req.k, theta = req.theta_rad;
    if (r == 0.0) {
      if (!have_latest_)
        throw InputError("r = 0 asks for the latest slow state, and there is none");
      const OrbitElements o = orbitFromSlow(latest_q_);
      r = o.r;
      k = o.k;
      if (req.theta_grid == 0) theta = o.theta;
    }
    requireFinite(r, "r");
    requireFinite(k, "k");
    requireFinite(theta, "theta_rad");
    if (!(std::fabs(r) > std::fabs(k)))
      throw InputError("need |r| > |k| (a standing-wave component): (5.9) is singular at r = |k|");
    if (req.theta_grid > 100000) throw InputError("theta_grid: at most 100000 angles");
    std::vector<double> thetas;
    if (req.theta_grid == 0)
      thetas.push_back(theta);
    else
      for (uint32_t i = 0; i < req.theta_grid; ++i) thetas.push_back(M_PI / 2 * i / req.theta_grid);
    const UncertainParameters p = uncertainParameters(estimate_);
    const ros::Time stamp = ros::Time::now();
    for (double th : thetas)
      res.rates.push_back(driftRateToMsg(r, k, th, driftRateWithInterval(r, k, th, p),
                                         estimate_.confidence, stamp));
    res.success = true;
    res.message = std::to_string(res.rates.size()) + " drift rate(s) by (5.9) from the " +
                  estimate_.method + " estimate of " + estimate_.model;
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    res.rates.clear();
  }
  return true;
}

void IdentifierNode::onWholeAngle(const SlowState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    const Eigen::Vector4d q = slowFromMsg(*msg);
    if (!whole_angle_.add(msg->phase_epoch, msg->header.stamp, msg->header.seq, q,
                          msg->reference_frequency_rad_s - msg->detuning_rad_s))
      ROS_WARN_THROTTLE(5.0,
                        "identifier: whole-angle state out of order or over the limit "
                        "dropped (%llu so far)",
                        static_cast<unsigned long long>(whole_angle_.dropped()));
  } catch (const InputError& e) {
    ROS_WARN_THROTTLE(5.0, "identifier: whole-angle state dropped: %s", e.what());
  }
}

bool IdentifierNode::onMeasureDrift(MeasureDrift::Request& req, MeasureDrift::Response& res) {
  try {
    requireFinite(req.walk_rad_s, "walk_rad_s");
    if (req.bins != 0 && (req.bins < 4 || req.bins > 3600))
      throw InputError("bins: need 4..3600 theta bins (0 = 24)");
    SlowRecord run;
    UncertainParameters params;
    uint64_t lost = 0, dropped = 0;
    std::string frame_id;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!have_estimate_) throw InputError("no estimate yet: identify a free decay first");
      // As `cvg_ident drift`: a rank-deficient estimate predicts nothing (#25).
      if (estimate_.rank < estimate_.n_params)
        throw InputError("the latest estimate is rank-deficient (rank " +
                         std::to_string(estimate_.rank) + " of " +
                         std::to_string(estimate_.n_params) +
                         "): it predicts no drift; identify a longer record or several decays");
      if (whole_angle_.size() == 0)
        throw InputError("no whole-angle run received on " + whole_angle_sub_.getTopic());
      run = whole_angle_.record();
      lost = whole_angle_.lost();
      dropped = whole_angle_.dropped();
      params = uncertainParameters(estimate_);
      frame_id = options_.frame_id;
    }
    // Measured outside the lock: the data callbacks go on meanwhile.
    const DriftComparison c = measureDrift(
        run, req.walk_rad_s, params, req.bins ? static_cast<int>(req.bins) : 24, params.confidence);
    res.comparison = driftComparisonToMsg(c, params.confidence, ros::Time::now());
    res.comparison.header.frame_id = frame_id;
    drift_measured_pub_.publish(res.comparison);
    res.success = true;
    res.message =
        c.summary + " (" + std::to_string(run.size()) + " states of the run" +
        (lost ? ", " + std::to_string(lost) + " lost before the buffer" : "") +
        (dropped ? ", " + std::to_string(dropped) + " dropped (out of order or buffer full)" : "") +
        ")";
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    std::lock_guard<std::mutex> lock(mutex_);
    if (whole_angle_.lost())
      res.message += " (" + std::to_string(whole_angle_.lost()) + " states lost before the buffer)";
  }
  return true;
}

bool IdentifierNode::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  clearData("reset requested");
  whole_angle_.clear();
  have_estimate_ = false;
  estimate_ = Estimate();
  res.success = true;
  res.message = "identifier reset: buffer and estimates cleared";
  return true;
}

bool IdentifierNode::onExplain(Explain::Request& req, Explain::Response& res) {
  try {
    const ExperimentMode mode = req.mode.empty() ? mode_ : parseExperimentMode(req.mode);
    if (mode != mode_)
      throw InputError("this identifier buffers " + experimentModeName(mode_) + " data, not " +
                       experimentModeName(mode));
    ExplainOptions eo;
    SolveInput in;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      eo.fitting.identification = options_.identification;
      if (eo.fitting.identification.method == "rls") eo.fitting.identification.method = "ls";
      in = snapshot(PipelineOptions());
    }
    // Explained on the service thread outside the lock: the data callbacks go on meanwhile.
    const Explanation ex = mode_ == ExperimentMode::kFreeDecay ? explainFreeDecay(in.slow, eo)
                                                               : explainForced(in.sweep, eo);
    std::string selected;
    for (const auto& s : ex.selection.selected) selected += (selected.empty() ? "" : "+") + s;
    res.success = ex.determined;  // a model the buffer does not determine is no answer (#25)
    res.message = ex.cause + " [selected: " + (selected.empty() ? "none" : selected) +
                  (ex.unexplained ? "; structure remains unexplained" : "") + "]";
    res.report_json = report::explanationToJson(ex).dump();  // as `cvg_ident explain` writes
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

}  // namespace cvg_bench
