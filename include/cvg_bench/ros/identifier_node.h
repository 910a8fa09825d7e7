// identifier_node: parameter identification on the bench. Buffers slow states (`slow`, free decay)
// or sweep points (`sweep`, forced) and runs the core's identification (identification.h) on the
// window: on request (service `identify`), periodically, or once when the data stop (end of a
// record or a bag); in `rls` mode additionally a block recursive estimate updated with every slow
// state. Publishes `estimate` (ModelEstimate, latched), `derived` (section 4 quantities with CIs)
// and `drift` ((5.9) at the latest slow state's orbit elements), and broadcasts tf frames rotated
// about z from `frame_id`: the stiffness axis (alpha), the damping axis (beta) and the wave pattern
// (theta of the latest slow state, orbitFromSlow). Services: identify, get_estimate, predict_drift,
// identifier/reset, explain. Each experiment (ExperimentTracker: new phase epoch, data jumping back
// in time, the simulator's start event on `truth`) starts a fresh buffer and estimate; the last
// history_size experiments' estimates stay retrievable (get_estimate by experiment_id). Every
// published estimate carries its experiment id and its sanity problems (estimate_sanity.h).
// Diagnostics (1 Hz): input rate, drops by reason, buffer depth, experiment, solver state.
//
// Threads (issue #27): the data callbacks only buffer (O(1) per message). The periodic and
// end-of-data solves run on a worker thread from a snapshot of the buffer, one at a time; the
// timer publishes the result when it is ready, unless the buffer changed meanwhile (new
// experiment, reset, refit settings, or a newer estimate), when it is discarded and counted. The
// services run on their own callback thread and solve (identify, explain) outside the state
// lock, so neither a solve nor a service call holds up the incoming data. Only the finishing
// estimate of an experiment, when the next one starts before it was solved, is solved on the
// data thread (once per experiment).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <ros/spinner.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_broadcaster.h>

#include <deque>
#include <future>
#include <memory>
#include <mutex>
#include <string>

#include "cvg_bench/DerivedQuantitiesStamped.h"
#include "cvg_bench/Explain.h"
#include "cvg_bench/GetEstimate.h"
#include "cvg_bench/IdentifierConfig.h"
#include "cvg_bench/Identify.h"
#include "cvg_bench/InputLoss.h"
#include "cvg_bench/MeasureDrift.h"
#include "cvg_bench/ModelEstimate.h"
#include "cvg_bench/PredictDrift.h"
#include "cvg_bench/SimulationTruth.h"
#include "cvg_bench/SlowState.h"
#include "cvg_bench/SweepPoint.h"
#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/estimate/identify_pipeline.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/ros/experiment_tracker.h"
#include "cvg_bench/ros/identifier_node_options.h"
#include "cvg_bench/ros/streaming_free_decay_rls.h"
#include "cvg_bench/ros/whole_angle_run_buffer.h"

namespace cvg_bench {

class IdentifierNode {
 public:
  /// Reads the settings from pnh; throws InputError listing every problem.
  IdentifierNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);
  /// Stops the service thread and waits for a solve in flight.
  ~IdentifierNode();

 private:
  /// What one solve needs, copied from the buffer under the lock.
  struct SolveInput {
    SlowRecord slow;
    SweepRecord sweep;
    PipelineOptions options;
    ros::Time start, end;
    uint32_t samples = 0;
    uint64_t generation = 0;              ///< generation_ at the snapshot
    uint64_t identifications_before = 0;  ///< identifications_ at the snapshot
  };
  /// Snapshot of the buffer for a solve; InputError below min_samples. Caller holds mutex_.
  SolveInput snapshot(const PipelineOptions& options) const;
  /// The core's identification of a snapshot (no node state: runs on any thread).
  Estimate solve(const SolveInput& in) const;
  /// Stores a solve's estimate as the current one and publishes it. Caller holds mutex_.
  void acceptEstimate(const Estimate& e, const SolveInput& in, double wall_s);
  /// Starts the periodic / end-of-data solve on the worker. Caller holds mutex_.
  void startBackgroundSolve();
  /// Publishes the worker's result when ready (or counts it stale). Caller holds mutex_.
  void collectBackgroundSolve();

  void onSlow(const SlowState::ConstPtr& msg);
  void onSweep(const SweepPoint::ConstPtr& msg);
  void onTruth(const SimulationTruth::ConstPtr& msg);
  /// dynamic_reconfigure (cfg/Identifier.cfg): model, method, window, forgetting factor,
  /// confidence, streaming period; refused (previous settings kept) when invalid.
  void onReconfigure(IdentifierConfig& config, uint32_t level);
  void onTimer(const ros::WallTimerEvent&);
  /// Classifies a sample; on a new experiment finishes the old one's estimate and clears the
  /// buffer.
  void trackExperiment(const ros::Time& epoch, const ros::Time& stamp);
  /// Counts samples lost before reaching the callback (publisher sequence numbers skipped).
  void countSequence(uint32_t seq, const ros::Time& stamp);
  /// Messages lost in transport among the data an estimate from `since` on uses.
  uint64_t lostSince(const ros::Time& since) const;
  /// Raw batches the demodulator lost (InputLoss events) within the data from `since` on.
  uint64_t upstreamLostSince(const ros::Time& since) const;
  void onInputLoss(const InputLoss::ConstPtr& msg);
  /// Why the current estimate is suspect: its sanity checks and any input lost within its data
  /// (the published estimate and the services give the same list).
  std::vector<std::string> estimateProblems();
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);
  bool onIdentify(Identify::Request& req, Identify::Response& res);
  bool onGetEstimate(GetEstimate::Request& req, GetEstimate::Response& res);
  bool onPredictDrift(PredictDrift::Request& req, PredictDrift::Response& res);
  /// A whole-angle run's state (`whole_angle`): buffered apart from the identification window.
  void onWholeAngle(const SlowState::ConstPtr& msg);
  /// Measured against predicted drift of the buffered whole-angle run (core measureDrift, as
  /// `cvg_ident drift --measured`), also published on `drift_measured`.
  bool onMeasureDrift(MeasureDrift::Request& req, MeasureDrift::Response& res);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onExplain(Explain::Request& req, Explain::Response& res);

  /// Identification of the buffer by the pipeline (identify_pipeline.h, any method); stores and
  /// publishes the result. Throws InputError / AnalysisError (callers turn them into success =
  /// false).
  void identifyNow(const PipelineOptions& options);
  /// The same by batch LS (periodic and end-of-data runs; in `rls` mode the recursive estimate
  /// streams already).
  void identifyNow(const IdentificationOptions& options);
  /// Batch LS options of the periodic and end-of-data solves.
  PipelineOptions periodicOptions() const;
  void clearData(const std::string& why);
  void clearBuffer();
  /// The buffered window as a core record (t from the first buffered stamp).
  SlowRecord bufferedSlowRecord() const;
  void publishEstimate();
  void updateWindowDrift();
  void publishFrames();
  /// rviz markers (bench_markers.h): standing wave, axes, text panel.
  void publishMarkers();
  double omegaForEstimate() const;

  ros::NodeHandle nh_;
  IdentifierNodeOptions options_;
  ExperimentMode mode_;
  ros::Subscriber data_sub_, truth_sub_, whole_angle_sub_;
  ros::Publisher estimate_pub_, derived_pub_, drift_pub_, markers_pub_, drift_measured_pub_;
  ros::ServiceServer identify_srv_, get_estimate_srv_, predict_drift_srv_, reset_srv_, explain_srv_,
      measure_drift_srv_;
  WholeAngleRunBuffer whole_angle_;
  ros::WallTimer timer_;
  tf2_ros::TransformBroadcaster tf_;
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_;
  std::unique_ptr<dynamic_reconfigure::Server<IdentifierConfig>> reconfigure_;

  // Experiments: the buffer holds experiment buffer_experiment_ (0 = none yet).
  ExperimentTracker tracker_;
  uint32_t buffer_experiment_ = 0;
  ros::Time buffer_experiment_start_;
  bool loop_warned_ = false;
  std::string truth_mode_warned_;
  /// Last estimate of each of the last history_size experiments, oldest first.
  struct StoredEstimate {
    ModelEstimate estimate;
    DerivedQuantitiesStamped derived;
    std::string summary;
    bool full_rank = false;
  };
  std::deque<StoredEstimate> history_;

  // Counters (diagnostics).
  uint64_t received_ = 0, received_at_last_diag_ = 0;
  ros::WallTime last_diag_wall_;
  uint64_t dropped_invalid_ = 0, dropped_duplicate_ = 0, dropped_transport_ = 0, trimmed_ = 0;
  bool have_seq_ = false;
  // Messages lost in transport (sequence gaps): the stamp of the message after each gap and how
  // many were missing before it, since the buffer was last cleared; an estimate whose data reach
  // back over a gap is published suspect with the count (issue #27). Gaps older than the buffer
  // are dropped as the window slides.
  std::deque<std::pair<ros::Time, uint64_t>> lost_gaps_;
  // Raw batches lost upstream (the demodulator's InputLoss events), kept the same way.
  std::deque<std::pair<ros::Time, uint64_t>> upstream_gaps_;
  uint64_t upstream_batches_lost_ = 0;
  ros::Subscriber loss_sub_;
  uint32_t last_seq_ = 0;
  uint64_t identifications_ = 0, identification_failures_ = 0, suspect_estimates_ = 0;
  double last_identify_wall_s_ = 0.0;
  std::string last_solver_message_ = "no identification yet";
  std::vector<std::string> last_sanity_problems_;

  // rviz view.
  double marker_r_ref_ = 0.0;  ///< largest amplitude r of the experiment
  bool have_drift_ = false;
  ParameterEstimate last_drift_rad_s_;
  bool have_window_drift_ = false;
  bool finished_ = false;  ///< the estimate is the end-of-data one of the whole buffer
  ParameterEstimate window_drift_rad_s_;  ///< theta' averaged over the buffer (the headline)

  // Free decay buffer (stamps exact; q per stamp).
  std::deque<ros::Time> stamps_;
  std::deque<Eigen::Vector4d> slow_q_;
  // Forced buffer.
  SweepRecord sweep_;
  double omega_from_data_rad_s_ = 0.0;
  bool have_latest_ = false;
  Eigen::Vector4d latest_q_ = Eigen::Vector4d::Zero();
  ros::Time latest_stamp_;
  ros::Time last_tf_stamp_;
  ros::Time last_axes_stamp_;  // stiffness/damping axes: strictly increasing stamps

  std::unique_ptr<StreamingFreeDecayRls> rls_;
  ros::Time rls_origin_;
  ros::WallTime last_data_wall_, last_periodic_wall_, last_rls_publish_wall_, last_tf_wall_;
  bool new_data_since_identify_ = false;
  uint64_t dropped_ = 0;

  bool have_estimate_ = false;
  /// A new estimate whose axis frames have not been broadcast yet (sent even at a repeated stamp).
  bool axes_pending_ = false;
  Estimate estimate_;
  ros::Time window_start_, window_end_;
  uint32_t window_samples_ = 0;

  // Threads: every callback holds mutex_ while it touches the state above. generation_ changes
  // whenever a solve in flight would no longer describe the buffer (cleared, refit settings).
  std::mutex mutex_;
  uint64_t generation_ = 0;
  std::future<Estimate> background_;
  SolveInput background_input_;
  ros::WallTime background_started_;
  uint64_t stale_solves_ = 0;
  ros::CallbackQueue service_queue_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
};

}  // namespace cvg_bench
