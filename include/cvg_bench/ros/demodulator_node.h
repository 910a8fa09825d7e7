// demodulator_node: raw f, g batches (`raw`) -> slow variables of (2.4) (`slow`), with the core's
// streaming demodulator (demodulator.h). Bad samples are dropped and counted by the core; the node
// warns at most every warn_throttle_s and publishes the counters as diagnostics. The demodulator
// is rebuilt when the reference frequency or the sample rate of the data changes, and reset when
// the data jump back in time (a looping bag, a restarted experiment: new phase epoch); a /clock
// jumping back is logged (the data stamps decide: one loop, one reset). Service
// `demodulator/reset` clears it.
// Sample times enter the core relative to the phase epoch (conversions.h), exactly.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cvg_bench/RawSampleBatch.h"
#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/ros/demodulator_node_options.h"

namespace cvg_bench {

class DemodulatorNode {
 public:
  /// Reads the settings from pnh; throws InputError listing every problem.
  DemodulatorNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

 private:
  void onRaw(const RawSampleBatch::ConstPtr& msg);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void resetState(const std::string& why, bool expected);
  /// (Re)builds the core demodulator for reference W and rate; InputError when they do not suit
  /// the filter settings.
  void configure(double omega_rad_s, double sample_rate_hz);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void warnAboutDrops();
  /// Announces `batches` raw batches lost before `stamp` on input_loss (InputLoss.msg).
  void publishLoss(uint32_t batches, const ros::Time& stamp);

  ros::NodeHandle nh_;
  DemodulatorNodeOptions options_;
  ros::Subscriber raw_sub_;
  ros::Publisher slow_pub_;
  ros::Publisher loss_pub_;  ///< InputLoss events: raw batches missing (sequence gaps)
  ros::ServiceServer reset_srv_;
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_;

  std::unique_ptr<Demodulator> demodulator_;  ///< built once W and the rate are known
  double omega_rad_s_ = 0.0, sample_rate_hz_ = 0.0, natural_omega_rad_s_ = 0.0;
  bool have_epoch_ = false;
  ros::Time epoch_;     ///< phase epoch (t = 0 of the core's times)
  ros::Time last_end_;  ///< stamp of the last sample of the previous batch
  ros::Time last_now_;  ///< ROS time at the previous batch (detects /clock jumps back)
  std::vector<SlowSample> out_;
  std::map<std::string, uint64_t>
      counters_before_;  ///< counts of demodulators replaced by configure()
  uint64_t rejected_before_ = 0;
  uint64_t warned_rejected_ = 0;  ///< rejected count at the last warning
  uint64_t batches_ = 0, slow_published_ = 0, node_resets_ = 0, bad_batches_ = 0;
  std::string last_problem_;
  // Input accounting: batches lost before the callback (publisher sequence numbers skipped).
  bool have_seq_ = false;
  uint32_t last_seq_ = 0;
  uint64_t batches_lost_ = 0, samples_in_ = 0, samples_in_at_last_diag_ = 0;
  uint64_t end_markers_ = 0;  // empty batches: end-of-record markers of the simulator
  ros::WallTime last_diag_wall_;
};

}  // namespace cvg_bench
