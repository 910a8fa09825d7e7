// The one place where ROS messages meet core types (style.md "Boundaries"). Nodes, the bag reader
// and the tests call these; nothing else touches a message field.
//
// Time: the core works in double seconds. Absolute ros::Time stamps (~1.7e9 s) lose ~0.2 us in a
// double, a phase error of ~0.02 rad at 85 kHz; so sample times always enter the core RELATIVE to
// an origin (ros::Time arithmetic is exact), e.g. the phase epoch of the demodulation reference.
// Message names: the core already has structs ParameterEstimate and DerivedQuantities in namespace
// cvg_bench, so the messages are ModelEstimate and DerivedQuantitiesStamped.
#pragma once

#include <ros/time.h>

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "cvg_bench/DerivedQuantitiesStamped.h"
#include "cvg_bench/DriftMeasured.h"
#include "cvg_bench/DriftRate.h"
#include "cvg_bench/ModelEstimate.h"
#include "cvg_bench/RawSampleBatch.h"
#include "cvg_bench/SimulationTruth.h"
#include "cvg_bench/SlowState.h"
#include "cvg_bench/SweepPoint.h"
#include "cvg_bench/core/diagnose/drift_measurement.h"
#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

/// Seconds from origin to t, exact in ros::Time arithmetic before the conversion to double.
double secondsSince(const ros::Time& t, const ros::Time& origin);
/// origin + seconds; InputError when seconds is not finite or the result is outside ros::Time.
ros::Time timeAfter(const ros::Time& origin, double seconds);

// ---------------------------------------------------------------- raw samples

/// Samples of one batch with times relative to an origin.
struct RawSamples {
  std::vector<double> t_s;  ///< sample times [s] from the origin (as in the message: unsorted kept)
  std::vector<double> f, g;
};

/// Validates the batch's layout (f, g and time_offsets_s lengths, a positive finite sample rate
/// or offsets) and returns its samples with times from origin. InputError names the problem.
/// Sample values are NOT screened here (NaN, duplicates...): that is the demodulator's counted job.
RawSamples rawSamplesFromMsg(const RawSampleBatch& msg, const ros::Time& origin);

/// Samples [begin, end) of a raw record as one batch: stamp = origin + t_s[begin]; uniform
/// (sample_rate_hz, no offsets) when sample_rate_hz > 0, else per-sample offsets.
RawSampleBatch rawBatchToMsg(const RawRecord& record, size_t begin, size_t end,
                             const ros::Time& origin, double sample_rate_hz);

// ---------------------------------------------------------------- slow variables

/// q = (q1, p1, q2, p2) of a SlowState; InputError when any is not finite.
Eigen::Vector4d slowFromMsg(const SlowState& msg);
/// A SlowState at time stamp with reference frequency w [rad/s] and detuning [rad/s] (controls 0).
SlowState slowStateToMsg(const Eigen::Vector4d& q, const ros::Time& stamp,
                         const ros::Time& phase_epoch, double reference_frequency_rad_s,
                         double detuning_rad_s = 0.0);

// ---------------------------------------------------------------- sweep points

/// Point i of a sweep record (direction/jump from the record when present; settled = true).
SweepPoint sweepPointToMsg(const SweepRecord& record, size_t i, const ros::Time& stamp);
/// Appends a point to a sweep record (omega_rad_s set from the point when the record has none).
/// InputError for non-finite values or omega0 <= 0.
void appendSweepPoint(const SweepPoint& msg, SweepRecord* record);

// ---------------------------------------------------------------- estimates

/// The message form of an estimate; stamps and sample count describe the window it came from.
ModelEstimate estimateToMsg(const Estimate& e, const ros::Time& window_start,
                            const ros::Time& window_end, uint32_t n_samples);
/// Back to the core struct (values, intervals, covariance, provenance). InputError when the
/// parallel arrays or the covariance size do not match names.
Estimate estimateFromMsg(const ModelEstimate& msg);

/// Section 4's quantities with intervals (the keys of DerivedQuantities::asMap(), as in
/// Estimate::derived); missing keys are left 0.
DerivedQuantitiesStamped derivedToMsg(const std::map<std::string, ParameterEstimate>& derived,
                                      const ros::Time& stamp, double confidence,
                                      double angular_gain);

/// A drift rate (5.9) with its interval at (r, k, theta).
DriftRate driftRateToMsg(double r, double k, double theta_rad, const ParameterEstimate& rate,
                         double confidence, const ros::Time& stamp);

/// Measured against predicted drift of a whole-angle run (core measureDrift), in deg/h.
DriftMeasured driftComparisonToMsg(const DriftComparison& c, double confidence,
                                   const ros::Time& stamp);

// ---------------------------------------------------------------- simulator truth

/// The truth message from named parameter values (sorted by the model's order when names given).
SimulationTruth truthToMsg(const std::string& preset, const std::string& mode,
                           const std::string& model, double omega_rad_s, double mu,
                           const std::vector<std::string>& names,
                           const std::map<std::string, double>& values, const ros::Time& stamp);
/// Named true values of a truth message; InputError when names and values differ in length.
std::map<std::string, double> truthValuesFromMsg(const SimulationTruth& msg);

}  // namespace cvg_bench
