// identifier_node: parameter identification on the bench. Buffers slow states (`slow`, free decay)
// or sweep points (`sweep`, forced) and runs the core's identification (identification.h) on the
// window: on request (service `identify`), periodically, or once when the data stop (end of a
// record or a bag); in `rls` mode additionally a block recursive estimate updated with every slow
// state. Publishes `estimate` (ModelEstimate, latched), `derived` (section 4 quantities with CIs)
// and `drift` ((5.9) at the latest slow state's orbit elements), and broadcasts tf frames rotated
// about z from `frame_id`: the stiffness axis (alpha), the damping axis (beta) and the wave pattern
// (theta of the latest slow state, orbitFromSlow). Services: identify, get_estimate, predict_drift,
// identifier/reset, explain. Data that jump back in time (bag loop) clear the buffer.
#pragma once

#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_broadcaster.h>

#include <deque>
#include <memory>
#include <string>

#include "cvg_bench/Explain.h"
#include "cvg_bench/GetEstimate.h"
#include "cvg_bench/Identify.h"
#include "cvg_bench/PredictDrift.h"
#include "cvg_bench/SlowState.h"
#include "cvg_bench/SweepPoint.h"
#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/estimate/identify_pipeline.h"
#include "cvg_bench/core/io/records.h"
#include "cvg_bench/ros/identifier_node_options.h"
#include "cvg_bench/ros/streaming_free_decay_rls.h"

namespace cvg_bench {

class IdentifierNode {
 public:
  /// Reads the settings from pnh; throws InputError listing every problem.
  IdentifierNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

 private:
  void onSlow(const SlowState::ConstPtr& msg);
  void onSweep(const SweepPoint::ConstPtr& msg);
  void onTimer(const ros::WallTimerEvent&);
  bool onIdentify(Identify::Request& req, Identify::Response& res);
  bool onGetEstimate(GetEstimate::Request& req, GetEstimate::Response& res);
  bool onPredictDrift(PredictDrift::Request& req, PredictDrift::Response& res);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onExplain(Explain::Request& req, Explain::Response& res);

  /// Identification of the buffer by the pipeline (identify_pipeline.h, any method); stores and
  /// publishes the result. Throws InputError / AnalysisError (callers turn them into success =
  /// false).
  void identifyNow(const PipelineOptions& options);
  /// The same by batch LS (periodic and end-of-data runs; in `rls` mode the recursive estimate
  /// streams already).
  void identifyNow(const IdentificationOptions& options);
  void clearData(const std::string& why);
  /// The buffered window as a core record (t from the first buffered stamp).
  SlowRecord bufferedSlowRecord() const;
  void publishEstimate();
  void publishFrames();
  double omegaForEstimate() const;

  ros::NodeHandle nh_;
  IdentifierNodeOptions options_;
  ExperimentMode mode_;
  ros::Subscriber data_sub_;
  ros::Publisher estimate_pub_, derived_pub_, drift_pub_;
  ros::ServiceServer identify_srv_, get_estimate_srv_, predict_drift_srv_, reset_srv_, explain_srv_;
  ros::WallTimer timer_;
  tf2_ros::TransformBroadcaster tf_;

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
};

}  // namespace cvg_bench
